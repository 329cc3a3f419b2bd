"""Task-space (operational-space) dynamics of a body frame.

With ``x' = J v`` the velocity of a frame (``J`` from :func:`robodyn.jacobian`), the joint
dynamics ``M a + C v + g = tau`` seen from the frame, for ``tau = J^T F``, is

    Lambda x'' + mu + p = F

    Lambda = (J M^-1 J^T)^-1                    task-space inertia
    Jbar   = M^-1 J^T Lambda                    dynamically consistent generalised inverse of J
    mu     = Jbar^T C v - Lambda Jdot v         Coriolis and centrifugal forces
    p      = Jbar^T g                           gravity forces

``Jbar`` is the right inverse of ``J`` (``J Jbar = 1``) that is consistent with the dynamics:
joint forces ``(1 - J^T Jbar^T) tau_0`` in its null space produce no frame acceleration.
``M^-1`` comes from :func:`robodyn.inverse_mass_matrix`, ``J`` and ``Jdot v`` are those of
:func:`robodyn.jacobian` and :func:`robodyn.jacobian_dot_times_v` in the chosen ``frame``;
``rows`` selects the linear part, the angular part, both, or any rows by index (``[0, 2]``:
the x and z of a planar arm's point). Works for fixed and floating
bases (``M`` and ``J`` then include the base's six dofs).

Reference: O. Khatib, "A unified approach for motion and force control of robot
manipulators: the operational space formulation", IEEE J. Robotics and Automation 3(1), 1987;
Siciliano, Sciavicco, Villani and Oriolo, *Robotics: Modelling, Planning and Control*,
Springer 2009, section 7.8.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._lazy import any_lazy, deferred
from . import _inputs
from .jacobian import FRAMES, jacobian, jacobian_dot_times_v
from .minv import inverse_mass_matrix
from .terms import gravity, nonlinear_effects

ROWS = {"all": slice(0, 6), "linear": slice(0, 3), "angular": slice(3, 6)}
ROW_NAMES = ("vx", "vy", "vz", "wx", "wy", "wz")


def task_rows(rows) -> tuple[np.ndarray, str]:
    """``(indices, label)`` of the task rows: ``"all"``, ``"linear"``, ``"angular"``, or a
    sequence of distinct row indices 0-5 (``[linear; angular]``: vx, vy, vz, wx, wy, wz)."""
    if isinstance(rows, str):
        if rows not in ROWS:
            raise ValueError(f"rows must be one of {tuple(ROWS)} or a list of row indices 0-5, got {rows!r}")
        return np.arange(6)[ROWS[rows]], f"{rows} rows"
    try:
        idx = np.asarray(rows)
        ok = idx.ndim == 1 and idx.size > 0 and np.issubdtype(idx.dtype, np.integer)
    except (TypeError, ValueError):
        ok = False
    if not ok or np.any((idx < 0) | (idx > 5)) or len(set(idx.tolist())) != idx.size:
        raise ValueError(f"rows must be one of {tuple(ROWS)} or a list of distinct row indices 0-5 "
                         f"({', '.join(f'{k} {n}' for k, n in enumerate(ROW_NAMES))}), got {rows!r}")
    return idx.astype(np.int64), f"rows {[ROW_NAMES[k] for k in idx.tolist()]}"

# J M^-1 J^T is singular when its smallest eigenvalue is below this fraction of the largest.
SINGULAR_RCOND = 1e-12


class TaskSpaceDynamics(NamedTuple):
    """Terms of ``Lambda x'' + mu + p = F`` (module docstring), ``m`` task rows:
    ``Lambda`` (..., m, m), ``mu`` (..., m), ``p`` (..., m), ``Jbar`` (..., nv, m) and the
    task Jacobian ``J`` (..., m, nv)."""
    Lambda: np.ndarray
    mu: np.ndarray
    p: np.ndarray
    Jbar: np.ndarray
    J: np.ndarray


def _task(model, q, body, frame, rows, armature, check_finite, what):
    """Flat-batch ``(batch, x, Minv, J, Lambda)`` with the checks of every task-space function."""
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    idx, label = task_rows(rows)
    batch, x = _inputs.states(model, q=q)
    nv = model.nv
    J = jacobian(model, x["q"], body, frame, check_finite=check_finite).reshape(-1, 6, nv)[:, idx]
    Minv = inverse_mass_matrix(model, x["q"], armature=armature, check_finite=False).reshape(-1, nv, nv)
    A = J @ Minv @ np.swapaxes(J, 1, 2)
    A = 0.5 * (A + np.swapaxes(A, 1, 2))
    w, V = np.linalg.eigh(A)
    bad = ~(w[:, 0] > SINGULAR_RCOND * w[:, -1])
    if np.any(bad):
        s = int(np.flatnonzero(bad)[0])
        where = "" if batch == () else f" (batch element {tuple(int(i) for i in np.unravel_index(s, batch))})"
        raise ValueError(
            f"{what}: J M^-1 J^T of {body!r} ({label}, frame {frame!r}) is singular{where}: eigenvalues "
            f"{w[s].tolist()}; the frame cannot move in every task direction at this configuration (a kinematic "
            f"singularity, or fewer joints than task rows: {J.shape[1]} rows, {nv} dofs); choose fewer rows (a list "
            "of indices, e.g. rows=[0, 1] for the x and y of a planar arm) or another configuration")
    Lam = (V / w[:, None, :]) @ np.swapaxes(V, 1, 2)
    return batch, x, Minv, J, Lam


def task_space_inertia(model, q, body, frame: str = "local_world_aligned", rows="all", *,
                       armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Task-space inertia ``Lambda = (J M^-1 J^T)^-1`` of a body or frame: (..., m, m).

    ``body``: body index or link/frame name; ``frame``: coordinates of ``J`` as in
    :func:`robodyn.jacobian`; ``rows``: ``"all"`` (m = 6, ``[linear; angular]``),
    ``"linear"`` or ``"angular"`` (m = 3), or a list of row indices 0-5 (``[0, 2]``: vx and
    vz; m = its length). Raises ValueError where ``J M^-1 J^T`` is singular.
    Reference: Khatib 1987.
    """
    if any_lazy(q):
        return deferred(task_space_inertia, locals())
    batch, _, _, _, Lam = _task(model, q, body, frame, rows, armature, check_finite, "task_space_inertia")
    return Lam[0] if batch == () else Lam.reshape(batch + Lam.shape[1:])


def dynamically_consistent_inverse(model, q, body, frame: str = "local_world_aligned", rows="all", *,
                                   armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Dynamically consistent generalised inverse ``Jbar = M^-1 J^T Lambda`` (..., nv, m) of
    the task Jacobian (arguments as in :func:`task_space_inertia`): ``J Jbar = 1``.
    Reference: Khatib 1987."""
    if any_lazy(q):
        return deferred(dynamically_consistent_inverse, locals())
    batch, _, Minv, J, Lam = _task(model, q, body, frame, rows, armature, check_finite,
                                   "dynamically_consistent_inverse")
    Jbar = Minv @ np.swapaxes(J, 1, 2) @ Lam
    return Jbar[0] if batch == () else Jbar.reshape(batch + Jbar.shape[1:])


def task_space_dynamics(model, q, v, body, frame: str = "local_world_aligned", rows="all", *,
                        armature: bool = True, check_finite: bool = True) -> TaskSpaceDynamics:
    """All terms of the task-space equation ``Lambda x'' + mu + p = F`` of a body or frame.

    q: (..., nq), v: (..., nv); ``body``, ``frame``, ``rows`` as in :func:`task_space_inertia`.
    Returns :class:`TaskSpaceDynamics` ``(Lambda, mu, p, Jbar, J)`` with
    ``mu = Jbar^T C v - Lambda Jdot v`` and ``p = Jbar^T g`` (rigid-body terms, no friction).
    Joint forces ``tau = J^T F`` then give the frame the acceleration ``x'' = J a + Jdot v``
    with ``Lambda x'' + mu + p = F``. Reference: Khatib 1987; Siciliano et
    al. 2009, section 7.8.
    """
    if any_lazy(q, v):
        return deferred(task_space_dynamics, locals())
    batch, x = _inputs.states(model, q=q, v=v)
    if check_finite and not np.all(np.isfinite(x["v"])):
        raise ValueError("task_space_dynamics: v contains NaN or Inf")
    _, _, Minv, J, Lam = _task(model, x["q"], body, frame, rows, armature, check_finite, "task_space_dynamics")
    Q, V, nv = x["q"], x["v"], model.nv
    Jbar = Minv @ np.swapaxes(J, 1, 2) @ Lam
    g = gravity(model, Q, check_finite=False).reshape(-1, nv)
    Cv = nonlinear_effects(model, Q, V, check_finite=False).reshape(-1, nv) - g
    Jdv = jacobian_dot_times_v(model, Q, V, body, frame, check_finite=False).reshape(-1, 6)[:, task_rows(rows)[0]]
    JbarT = np.swapaxes(Jbar, 1, 2)
    mu = np.einsum("bij,bj->bi", JbarT, Cv) - np.einsum("bij,bj->bi", Lam, Jdv)
    p = np.einsum("bij,bj->bi", JbarT, g)
    out = TaskSpaceDynamics(Lam, mu, p, Jbar, J)
    if batch == ():
        return TaskSpaceDynamics(*(t[0] for t in out))
    return TaskSpaceDynamics(*(t.reshape(batch + t.shape[1:]) for t in out))
