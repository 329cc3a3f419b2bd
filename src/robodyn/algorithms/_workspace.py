"""Workspaces of the compiled kernels: many small arrays carved from one allocation.

A kernel's per-call scratch arrays (placements, spatial vectors, articulated inertias) come
from one ``np.empty`` buffer, cut into C-contiguous views with :func:`take`. One allocation
instead of one per array matters for single calls from Python: Numba allocates an array in
about 50 ns, and a kernel needs 9 to 23 of them, while a view costs a few nanoseconds.

The views do not own their memory: the workspace tuple keeps the buffer as its first entry,
so the memory lives as long as the tuple.
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .._jit import inline, splice


@intrinsic
def view(typingctx, buf, offset, shape):
    """The C-contiguous array of ``shape`` (a tuple of ints) starting at the flat index
    ``offset`` of the C-contiguous array ``buf``, sharing ``buf``'s memory and owning none
    (like ``carray``, and usable in the kernels compiled without reference counting)."""
    if not (isinstance(buf, types.Array) and buf.layout == "C"):
        return None
    ndim = len(shape)
    arrty = types.Array(buf.dtype, ndim, "C")
    sig = arrty(buf, offset, shape)

    def codegen(context, builder, signature, args):
        src = context.make_array(signature.args[0])(context, builder, args[0])
        data = builder.gep(src.data, [args[1]])
        dims = [context.cast(builder, v, ty, types.intp)
                for v, ty in zip(cgutils.unpack_tuple(builder, args[2], ndim), signature.args[2])]
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(context.get_data_type(buf.dtype)))
        strides = [itemsize] * ndim
        for k in range(ndim - 2, -1, -1):
            strides[k] = builder.mul(strides[k + 1], dims[k + 1])
        out = context.make_array(arrty)(context, builder)
        context.populate_array(out, data=data, shape=cgutils.pack_array(builder, dims),
                               strides=cgutils.pack_array(builder, strides), itemsize=itemsize, meminfo=None)
        return out._getvalue()

    return sig, codegen


@splice
def take(buf, o, shape):
    """The view of ``buf[o:o + prod(shape)]`` with ``shape`` (a tuple of ints), and the
    offset after it."""
    n = 1
    for s in shape:
        n *= s
    if o + n > buf.shape[0]:  # a layout error in the caller: fail loudly, never overrun
        raise IndexError("workspace buffer too small")
    return view(buf, o, shape), o + n


@splice
def row(x):
    """``x`` as a batch of one state: the view of shape ``(1,) + x.shape`` (owning no memory),
    for a single-state kernel that runs its algorithm's batch code (``driver.BatchKernel``)."""
    return view(x, 0, (1,) + x.shape)


POSES_SIZE_NB, POSES_SIZE = 24, 12  # entries of :func:`poses`: 24 nb + 12


@inline
def poses(buf, o, nb):
    """The placements every kernel starts with: ``(liR, lip, oR, op, Rj, pj)`` (local and world
    placements of the ``nb`` bodies, a joint's rotation and position), and the next offset."""
    liR, o = take(buf, o, (nb, 3, 3))
    lip, o = take(buf, o, (nb, 3))
    oR, o = take(buf, o, (nb, 3, 3))
    op, o = take(buf, o, (nb, 3))
    Rj, o = take(buf, o, (3, 3))
    pj, o = take(buf, o, (3,))
    return (liR, lip, oR, op, Rj, pj), o
