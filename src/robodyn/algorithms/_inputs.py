"""Input checks and batch handling shared by the public algorithm functions.

Every public function accepts states with leading batch dimensions: ``q`` of shape
``(..., nq)``, ``v``/``a``/``tau`` of shape ``(..., nv)``; the leading shapes broadcast
against each other. Shapes are checked here and raise ``ValueError`` naming the argument, the
expected shape and the received one.

The value checks run inside the compiled kernels (see ``status``).
"""

from __future__ import annotations

import numpy as np
from numba import int64

from .._jit import inline, splice
from ..layout import BODY_COLUMNS, DOF_COLUMNS, IV, NDOF, PARAMS_SIZE
from ._lazy import is_lazy
from ._workspace import row, view
from .status import NO_WRENCH, OK, raise_for_coupled


@inline
def unpack(ints, packed):
    """Views ``(body, dofs, params, zero_wrench)`` of a model's ``packed`` kernel array (see
    ``layout``): (nb, BODY_COLUMNS), (nv, DOF_COLUMNS), (PARAMS_SIZE,) and (nb, 6), owning no
    memory (see ``_jit``)."""
    nb = ints.shape[0]
    nv = 0 if nb == 0 else ints[nb - 1, IV] + ints[nb - 1, NDOF]
    o1 = nb * BODY_COLUMNS
    o2 = o1 + DOF_COLUMNS * nv
    return (view(packed, 0, (nb, BODY_COLUMNS)), view(packed, o1, (nv, DOF_COLUMNS)),
            view(packed, o2, (PARAMS_SIZE,)), view(packed, o2 + PARAMS_SIZE, (nb, 6)))


def _as_float(name: str, x) -> np.ndarray:
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    if is_lazy(x):  # never computed behind the caller's back
        raise TypeError(f"{name}: a Dask array, which this function does not take: pass the states as Dask "
                        f"arrays (the batched functions then return Dask arrays) or call .compute() first")
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None


_F8 = np.dtype(np.float64)


def states(model, **arrays):
    """Check shapes and bring the state arrays to the kernels' layout.

    ``arrays`` maps argument names (``q`` has length nq, every other one nv) to array-likes.
    Returns ``(batch_shape, out)``: for a single state (``batch_shape == ()``) ``out[name]``
    is a contiguous 1-D array, otherwise C-contiguous of shape ``(B, n)``,
    ``B = prod(batch_shape)``; always writeable (read-only inputs are copied).
    """
    nq, nv = model.nq, model.nv
    for name, x in arrays.items():  # fast path: contiguous float64 vectors of the right size
        if not (type(x) is np.ndarray and x.dtype is _F8 and x.shape == ((nq,) if name == "q" else (nv,))
                and x.strides == (8,) and x.flags.writeable):
            break
    else:
        return (), arrays
    out = {}
    single = True
    for name, x in arrays.items():
        a = _as_float(name, x)
        n = nq if name == "q" else nv
        if a.ndim == 0 or a.shape[-1] != n:
            raise ValueError(f"{name}: expected shape (..., {n}), got {a.shape}")
        single = single and a.ndim == 1
        out[name] = a
    if single:
        return (), {name: _kernel_layout(a) for name, a in out.items()}
    try:
        batch = np.broadcast_shapes(*(a.shape[:-1] for a in out.values()))
    except ValueError:
        shapes = {k: a.shape for k, a in out.items()}
        raise ValueError(f"leading (batch) dimensions do not broadcast: {shapes}") from None
    B = int(np.prod(batch))
    for name, a in out.items():
        if a.shape[:-1] != batch:
            a = np.broadcast_to(a, batch + a.shape[-1:])
        out[name] = _kernel_layout(a.reshape(B, a.shape[-1]))
    return batch, out


def _kernel_layout(a: np.ndarray) -> np.ndarray:
    """``a`` C-contiguous and writeable (a copy if needed): the one array type the kernels are
    compiled for, so that read-only or strided inputs do not compile new specialisations."""
    a = np.ascontiguousarray(a)
    return a if a.flags.writeable else a.copy()


WRENCH_FRAMES = {"local": 0, "world": 1, "local_world_aligned": 2}


def body_wrenches(model, f_ext, batch: tuple, frame: str) -> tuple[np.ndarray, int]:
    """External wrenches ``(..., nbodies, 6)`` ``[force, torque]`` for the kernels.

    Returns ``(F, code)``: ``F`` is (nb, 6) for a single state, else (B or 1, nb, 6);
    ``code`` is -1 without wrenches, else the frame they are expressed in: 0 ``"local"``
    (body frame, torque about the body origin), 1 ``"world"`` (world axes, torque about the
    world origin), 2 ``"local_world_aligned"`` (world axes, torque about the body origin).
    """
    if f_ext is None and frame in WRENCH_FRAMES:
        zero = model.kernel.zero_wrench
        return (zero if batch == () else zero[None]), -1
    codes = WRENCH_FRAMES
    if frame not in codes:
        raise ValueError(f"frame must be one of {sorted(codes)}, got {frame!r}")
    nb = model.nbodies
    f = _as_float("f_ext", f_ext)
    if f.ndim < 2 or f.shape[-2:] != (nb, 6):
        raise ValueError(f"f_ext: expected shape (..., {nb}, 6), got {f.shape}")
    if not np.isfinite(f).all():
        raise ValueError("f_ext: contains NaN or Inf")
    if f.shape[:-2] != batch:
        try:
            full = np.broadcast_shapes(batch, f.shape[:-2])
        except ValueError:
            full = None
        if full != batch:
            raise ValueError(f"f_ext: batch shape {f.shape[:-2]} does not match the states' {batch}")
        f = np.broadcast_to(f, batch + (nb, 6))
    f = np.ascontiguousarray(f if batch == () else f.reshape(-1, nb, 6)).view()
    f.flags.writeable = False  # the caller's array without a copy: the kernels only read it
    return f, codes[frame]


def batched(batch: tuple, *arrays) -> tuple:
    """The kernel arrays of a call as a batch: unchanged for a batch, each with a leading axis
    of one (a view) for a single state (``batch == ()``), which runs the batch's compiled code
    (``driver.BatchKernel.serial``)."""
    return arrays if batch != () else tuple(a[None] for a in arrays)


def fast_out(out, shape: tuple):
    """The output array of a single-state fast path: ``out`` itself, or a new
    ``np.empty(shape)`` when it is None. The fast kernels are compiled for a C-contiguous,
    writeable float64 ``out`` only (anything else raises ``TypeError`` in the dispatcher) and
    check its shape and that it overlaps no input (:func:`fits`) before they write; when it
    does not fit, the caller takes its general path, where :func:`output` raises the error
    that says why."""
    return np.empty(shape) if out is None else out


@inline
def apart(out, x):
    """True when the arrays ``out`` and ``x`` occupy disjoint memory (the bounds test of
    ``np.may_share_memory``): the kernels read their inputs while they write ``out``."""
    o, b = out.ctypes.data, x.ctypes.data
    return o + out.nbytes <= b or b + x.nbytes <= o


@inline
def fits(out, n, x, y, z):
    """The single-state output check of a fast path: ``out`` is (n,) or (n, n) and shares no
    memory with the inputs ``x, y, z`` (pass an input again where there are fewer)."""
    return out.shape[0] == n and out.size == n ** out.ndim and apart(out, x) and apart(out, y) and apart(out, z)


# The arguments of a fast path's single state for its batch code, a batch of one
# (``driver.BatchKernel.call_one``): ``(fits, args)``, ``fits`` as :func:`fits` for the output.

@splice
def one_state(ints, packed, q, v, x, check, out):
    """``(q, v, x) -> out`` (nv,) without external wrenches: ``args = (ints, body, dofs, params,
    Q, V, X, F, NO_WRENCH, check, OUT)`` (``aba``; the RNEA's fast path keeps its own code)."""
    body, dofs, params, zero = unpack(ints, packed)
    return (fits(out, dofs.shape[0], q, v, x),
            (ints, body, dofs, params, row(q), row(v), row(x), row(zero), int64(NO_WRENCH), check, row(out)))


@splice
def coupled_one_state(ints, packed, cints, cfloats, q, v, x, check, out):
    """:func:`one_state` of a model with mimic couplings (``cints, cfloats``: its
    ``CouplingTables``): ``args = (ints, body, dofs, params, cints, cfloats, Q, V, X, F,
    NO_WRENCH, check, OUT)``."""
    body, dofs, params, zero = unpack(ints, packed)
    return (fits(out, cints[1], q, v, x), (ints, body, dofs, params, cints, cfloats, row(q), row(v), row(x),
                                           row(zero), int64(NO_WRENCH), check, row(out)))


@splice
def matrix_one_state(ints, packed, q, check, M):
    """``q -> M`` (nv, nv): ``args = (ints, body, dofs, Q, check, MM)`` (``crba``,
    ``inverse_mass_matrix``)."""
    body, dofs, _, _ = unpack(ints, packed)
    return fits(M, dofs.shape[0], q, q, q), (ints, body, dofs, row(q), check, row(M))


def output(out, batch: tuple, tail: tuple, inputs: dict) -> tuple[np.ndarray, np.ndarray]:
    """The result array of a kernel and the array to return.

    Without ``out``: a new array ``(B,) + tail`` (``tail`` alone for a single state) and its
    reshape to ``batch + tail``. With ``out``: it must be a writeable C-contiguous float64
    ndarray of shape ``batch + tail`` that shares no memory with the ``inputs`` (the kernels
    read their inputs while they write); the kernel writes into it and ``out`` is returned.
    """
    shape = batch + tail
    flat = tail if batch == () else (int(np.prod(batch)),) + tail
    if out is None:
        res = np.empty(flat)
        return res, unflatten(res, batch)
    if not isinstance(out, np.ndarray) or out.dtype != np.float64:
        raise ValueError(f"out: expected a float64 ndarray, got {type(out).__name__}"
                         + (f" of {out.dtype}" if isinstance(out, np.ndarray) else ""))
    if out.shape != shape:
        raise ValueError(f"out: expected shape {shape}, got {out.shape}")
    if not (out.flags.c_contiguous and out.flags.writeable):
        raise ValueError("out: must be C-contiguous and writeable")
    for name, a in inputs.items():
        if np.may_share_memory(out, a):
            raise ValueError(f"out: shares memory with the input {name}")
    return out.reshape(flat), out


def as_batch(a: np.ndarray) -> np.ndarray:
    """A single state (n,) as a batch of one (1, n); a batch (B, n) as it is."""
    return a[None] if a.ndim == 1 else a


def unflatten(out: np.ndarray, batch: tuple) -> np.ndarray:
    return out if batch == () else out.reshape(batch + out.shape[1:])


def coupled_call(model, one, batch, sizes, third: str, q, v, x, f_ext, frame: str, friction: bool,
                 armature: bool, check: bool, out, what: str) -> np.ndarray:
    """A per-state algorithm ``(q, v, x) -> (nv,)`` of a :class:`~robodyn.coupling.CoupledModel`
    (``x`` named ``third``: ``a`` or ``tau``) by its batch kernel ``batch`` (workspace
    ``sizes``; a single state as a batch of one), the full tree's tables and the coupling's; a
    contiguous float64 state without wrenches goes straight to the compiled single-state
    kernel ``one(address, ints, packed, cints, cfloats, q, v, x, check, out)``, which runs the
    batch's code at ``batch.one_address``; errors name the caller's arrays (``what``)."""
    full, tables, k = model.full, model.tables, model.full.kernel
    if f_ext is None and frame in WRENCH_FRAMES:
        res = fast_out(out, (model.nv,))
        try:  # one state of contiguous float64 vectors (the dispatcher raises TypeError otherwise)
            if one(batch.one_address, k.ints, k.packed[bool(friction), bool(armature)], tables.ints, tables.floats,
                   q, v, x, check, res) == OK:
                return res
        except TypeError:
            pass
    shape, xs = states(model, q=q, v=v, **{third: x})
    F, fcode = body_wrenches(full, f_ext, shape, frame)
    res, result = output(out, shape, (model.nv,), xs)
    Q, V, X, F, R = batched(shape, xs["q"], xs["v"], xs[third], F, res)
    status = np.empty(Q.shape[0], dtype=np.int64)
    batch.run((k.ints, k.body, k.dofs[(bool(friction), bool(armature))], k.params[True], tables.ints, tables.floats,
               Q, V, X, F, fcode, check, R), sizes, status, shape)
    raise_for_coupled(model, status, xs, what)
    return result
