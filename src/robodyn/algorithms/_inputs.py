"""Input checks and batch handling shared by the public algorithm functions.

Every public function accepts states with leading batch dimensions: ``q`` of shape
``(..., nq)``, ``v``/``a``/``tau`` of shape ``(..., nv)``; the leading shapes broadcast
against each other. The checks raise ``ValueError`` naming the argument, the expected shape
and the received one; NaN/Inf raise unless ``check_finite=False`` (for hot loops that
guarantee finite inputs). Free-joint quaternions within ``QUAT_TOL`` of unit norm are
normalised, others are an error.
"""

from __future__ import annotations

import numba
import numpy as np

from .. import joints as J

QUAT_TOL = 1e-3


def _as_float(name: str, x) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None
    return a


def states(model, check_finite: bool = True, **arrays):
    """Validate and flatten state arrays.

    ``arrays`` maps argument names (``q`` has length nq, every other one nv) to array-likes.
    Returns ``(batch_shape, flat)`` where ``flat[name]`` is C-contiguous of shape
    ``(B, n)`` with ``B = prod(batch_shape)``.
    """
    checked = {}
    for name, x in arrays.items():
        a = _as_float(name, x)
        n = model.nq if name == "q" else model.nv
        if a.ndim == 0 or a.shape[-1] != n:
            raise ValueError(f"{name}: expected shape (..., {n}), got {a.shape}")
        if check_finite and not np.isfinite(a).all():
            bad = np.argwhere(~np.isfinite(a))[0].tolist()
            raise ValueError(f"{name}: contains NaN or Inf (first at index {tuple(bad)}); "
                             "pass check_finite=False to skip this check")
        checked[name] = a
    try:
        batch = np.broadcast_shapes(*(a.shape[:-1] for a in checked.values()))
    except ValueError:
        shapes = {k: a.shape for k, a in checked.items()}
        raise ValueError(f"leading (batch) dimensions do not broadcast: {shapes}") from None
    B = int(np.prod(batch)) if batch else 1
    flat = {}
    for name, a in checked.items():
        if a.shape[:-1] != batch:
            a = np.broadcast_to(a, batch + a.shape[-1:])
        flat[name] = np.ascontiguousarray(a.reshape(B, a.shape[-1]))
    if "q" in flat and model.floating_base:
        flat["q"] = _normalized_quaternions(model, flat["q"])
    return batch, flat


def _normalized_quaternions(model, q: np.ndarray) -> np.ndarray:
    copied = False
    for i in np.flatnonzero(model.joint_type == J.FREE):
        k = model.idx_q[i] + 3
        n = np.sqrt(np.einsum("bi,bi->b", q[:, k:k + 4], q[:, k:k + 4]))
        if np.any(np.abs(n - 1.0) > QUAT_TOL):
            worst = float(n[np.argmax(np.abs(n - 1.0))])
            raise ValueError(
                f"q: quaternion of free joint {model.body_joint_names[i]!r} (q[{k}:{k + 4}]) has norm "
                f"{worst:.6g}, not 1 (tolerance {QUAT_TOL}); normalise it"
            )
        if np.any(n != 1.0):
            if not copied:
                q, copied = q.copy(), True
            q[:, k:k + 4] /= n[:, None]
    return q


def body_wrenches(model, f_ext, batch: tuple, frame: str) -> tuple[np.ndarray, int]:
    """External wrenches ``(..., nbodies, 6)`` ``[force, torque]`` -> ``(B or 1, nb, 6)``.

    ``frame`` is where they are expressed: ``"local"`` (body frame, torque about the body
    origin), ``"world"`` (world axes, torque about the world origin) or
    ``"local_world_aligned"`` (world axes, torque about the body origin).
    """
    codes = {"local": 0, "world": 1, "local_world_aligned": 2}
    if frame not in codes:
        raise ValueError(f"f_ext_frame must be one of {sorted(codes)}, got {frame!r}")
    nb = model.nbodies
    if f_ext is None:
        return np.zeros((1, nb, 6)), -1
    f = _as_float("f_ext", f_ext)
    if f.ndim < 2 or f.shape[-2:] != (nb, 6):
        raise ValueError(f"f_ext: expected shape (..., {nb}, 6), got {f.shape}")
    if not np.isfinite(f).all():
        raise ValueError("f_ext: contains NaN or Inf")
    try:
        full = np.broadcast_shapes(batch, f.shape[:-2])
    except ValueError:
        raise ValueError(f"f_ext: batch shape {f.shape[:-2]} does not broadcast with {batch}") from None
    if full != batch:
        raise ValueError(f"f_ext: batch shape {f.shape[:-2]} would enlarge the state batch {batch}")
    if f.shape[:-2] != batch:
        f = np.broadcast_to(f, batch + (nb, 6))
    B = int(np.prod(batch)) if batch else 1
    return np.ascontiguousarray(f.reshape(B, nb, 6)), codes[frame]


def chunks(B: int) -> int:
    """Number of parallel chunks for a batch of ``B`` states (0 selects the serial path)."""
    return 0 if B <= 1 else min(B, numba.get_num_threads())


def unflatten(out: np.ndarray, batch: tuple) -> np.ndarray:
    return out.reshape(batch + out.shape[1:])
