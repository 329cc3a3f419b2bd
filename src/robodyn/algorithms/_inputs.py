"""Input checks and batch handling shared by the public algorithm functions.

Every public function accepts states with leading batch dimensions: ``q`` of shape
``(..., nq)``, ``v``/``a``/``tau`` of shape ``(..., nv)``; the leading shapes broadcast
against each other. Shapes are checked here and raise ``ValueError`` naming the argument, the
expected shape and the received one.

The value checks run inside the compiled kernels, where they cost nanoseconds: each kernel
returns a status per state (``OK``, ``NONFINITE`` for NaN/Inf in an input, ``BAD_QUATERNION``
for a free joint's quaternion farther than ``joints.QUAT_TOL`` from unit norm — near-unit
ones are normalised —, ``NONFINITE_RESULT`` when the inputs are finite but the result
overflowed, or ``i + 1`` for a failure at body ``i``), and :func:`raise_for_status`
turns a failure into a ``ValueError`` that says what and where. ``check_finite=False`` skips
the NaN/Inf checks of inputs and results (for hot loops with trusted input). No public function
returns NaN or Inf from finite inputs: it raises instead.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline
from .. import joints as J
from ..joints import NQ, ROW_SIZE
from ._workspace import view

OK = 0
NONFINITE = -1
BAD_QUATERNION = -2
WRONG_SIZE = -3
NONFINITE_RESULT = -4

# Constant arguments of the compiled per-state functions, as NumPy scalars: a Python literal
# (``-1``, ``True``) in a call from compiled code makes Numba compile a separate copy of the
# callee for that constant (minutes for the ABA); these are typed int64/bool like the runtime
# values of the other callers, which then share one compiled copy.
NO_WRENCH = np.int64(-1)  # ``fcode`` without external wrenches
CHECKED = np.bool_(True)  # ``check``: the NaN/Inf checks on


@inline
def nq_of(ints):
    """Length of the configuration vector of the model whose kernel table is ``ints``."""
    nb = ints.shape[0]
    return 0 if nb == 0 else ints[nb - 1, 2] + NQ[ints[nb - 1, 1]]


@inline
def unpack(ints, packed):
    """Views ``(body, dofs, params, zero_wrench)`` of a model's ``packed`` kernel array (see
    ``Model._pack``): (nb, ROW_SIZE), (nv, 9), (4,) and (nb, 6), owning no memory (see
    ``_jit``)."""
    nb = ints.shape[0]
    nv = 0 if nb == 0 else ints[nb - 1, 3] + ints[nb - 1, 4]
    o1 = nb * ROW_SIZE
    o2 = o1 + 9 * nv
    return (view(packed, 0, (nb, ROW_SIZE)), view(packed, o1, (nv, 9)), view(packed, o2, (4,)),
            view(packed, o2 + 4, (nb, 6)))


@inline
def finite(x):
    """True when every entry of the 1-D array ``x`` is finite: ``sum(x * 0) == 0``, since
    ``inf * 0`` and ``nan * 0`` are NaN (a branch-free loop the compiler vectorises; the
    kernels' fast-math flags keep NaN/Inf semantics, so the product is never folded to 0)."""
    return zero_sum(x) == 0.0


@inline
def zero_sum(x):
    """``sum(x * 0)`` of a 1-D array: 0 when every entry is finite, NaN otherwise."""
    s = 0.0
    for k in range(x.shape[0]):
        s += x[k] * 0.0
    return s


@inline
def finite2(x):
    """True when every entry of the 2-D array ``x`` is finite (see :func:`finite`)."""
    s = 0.0
    for r in range(x.shape[0]):
        s += zero_sum(x[r])
    return s == 0.0


@inline
def result_status(check, ok):
    """The status of a computed result: ``OK``, or ``NONFINITE_RESULT`` when the value checks
    are on and ``ok`` (the result's finiteness) is False."""
    return NONFINITE_RESULT if check and not ok else OK


def _as_float(name: str, x) -> np.ndarray:
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None


_F8 = np.dtype(np.float64)


def vectors(*xs) -> bool:
    """True when every argument is a writeable C-contiguous 1-D float64 ndarray: the
    single-state fast path, where the kernel itself checks the sizes (status ``WRONG_SIZE``)
    and values. (The one array type the kernels are compiled for: see :func:`states`.)"""
    for x in xs:
        if not (type(x) is np.ndarray and x.ndim == 1 and x.dtype is _F8 and x.flags.c_contiguous
                and x.flags.writeable):
            return False
    return True


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
        zero = model._kernel["zero_wrench"]
        return (zero if batch == () else zero[None]), -1
    codes = WRENCH_FRAMES
    if frame not in codes:
        raise ValueError(f"f_ext_frame must be one of {sorted(codes)}, got {frame!r}")
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
    f.flags.writeable = False  # read-only as the model's zero wrenches: one compiled specialisation
    return f, codes[frame]


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


def raise_nonfinite_result(what: str, arrays: dict):
    """Raise the ``ValueError`` of a result that is not finite although its inputs are."""
    big = max((float(np.abs(a).max()) for a in arrays.values() if np.size(a)), default=0.0)
    raise ValueError(
        f"{what}: the result is not finite although every input is (largest input magnitude {big:.3g}): "
        "the computation overflowed or divided by zero; check the scale of the inputs and the model's "
        "masses and inertias")


def require_finite_result(what: str, out: np.ndarray, check: bool, arrays: dict) -> np.ndarray:
    """``out``, after checking (when ``check``) that it is finite (for results computed in NumPy)."""
    if check and not np.isfinite(out).all():
        raise_nonfinite_result(what, arrays)
    return out


def raise_for_status(model, status, arrays: dict, what: str) -> int:
    """Raise the ``ValueError`` a kernel status stands for; return the failing body + 1 (or 0).

    ``status`` is an int (single state) or an int array (batch); ``arrays`` are the inputs as
    given to the kernel, used to say where the problem is.
    """
    if type(status) is int:
        if status == OK:
            return 0
        code = status
    else:
        bad = np.flatnonzero(status)
        if bad.size == 0:
            return 0
        code = int(status[bad[0]])
    if code == OK:
        return 0
    if code == WRONG_SIZE:
        raise AssertionError("sizes are checked before the kernels run")
    if code == NONFINITE:
        for name, a in arrays.items():
            idx = np.argwhere(~np.isfinite(a))
            if idx.size:
                raise ValueError(f"{what}: {name} contains NaN or Inf (first at index {tuple(idx[0].tolist())}); "
                                 "pass check_finite=False to skip this check")
        raise AssertionError("kernel reported a non-finite input that is not there")
    if code == NONFINITE_RESULT:
        raise_nonfinite_result(what, arrays)
    if code == BAD_QUATERNION:
        q = arrays["q"]
        for i in np.flatnonzero(model.joint_type == J.FREE):
            k = model.idx_q[i] + 3
            n = np.linalg.norm(q[..., k:k + 4], axis=-1)
            if np.any(~(np.abs(n - 1.0) <= J.QUAT_TOL)):
                worst = float(np.ravel(n)[np.argmax(np.ravel(np.abs(n - 1.0)))])
                raise ValueError(
                    f"{what}: q: quaternion of free joint {model.body_joint_names[i]!r} (q[{k}:{k + 4}]) has norm "
                    f"{worst:.6g}, not 1 (tolerance {J.QUAT_TOL}); normalise it"
                )
        raise AssertionError("kernel reported a bad quaternion that is not there")
    return code
