"""Constrained dynamics: accelerations and constraint forces of a tree with contacts, welds,
closed loops and coupled joints, from the KKT system solved by a Schur complement.

    [[M, J_c^T], [J_c, 0]] [a; -lambda] = [tau - h; gamma]

    gamma = -Jdot_c v - 2 alpha J_c v - beta^2 phi       (Baumgarte stabilisation)

``M = crba(q)``, ``h = rnea(q, v, 0) = C v + g (+ friction)``, ``J_c`` (m, nv) the stacked
constraint Jacobians, ``phi`` (m,) the position errors of the constraints and ``lambda`` the
constraint forces, so that ``M a = tau - h + J_c^T lambda``. With ``alpha = beta = 0`` the
constraint holds at acceleration level (``J_c a + Jdot_c v = 0``); positive values make
position and velocity errors decay as ``phi'' + 2 alpha phi' + beta^2 phi = 0``.

Solution (Schur complement on ``M``, Featherstone RBDA section 8.3; Baumgarte 1972):
``M = L L^T`` (Cholesky), ``a_0 = M^-1 (tau - h)`` (the unconstrained acceleration),
``S = J_c M^-1 J_c^T = Y^T Y`` with ``Y = L^-1 J_c^T``, ``S lambda = gamma - J_c a_0``,
``a = a_0 + M^-1 J_c^T lambda``.

Redundant constraints (rows of ``J_c`` that depend on the others, e.g. a planar four-bar
linkage closed by a 3D point constraint) make ``S`` singular. ``lambda`` is then the
minimum-norm least-squares solution, by the pseudo-inverse of ``S`` computed from its
eigen-decomposition with eigenvalues below ``rcond`` times the largest dropped; the
accelerations are unique and the constraint forces the smallest that produce them. The
result reports the rank kept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple, Sequence

import numpy as np

from .. import joints as Jt
from . import _inputs
from .crba import crba
from .jacobian import jacobian, jacobian_dot_times_v
from .kinematics import frame_pose
from .rnea import rnea

# Eigenvalues of the Schur complement below this fraction of the largest are dropped.
RCOND = 1e-10


def _vector3(name: str, x) -> np.ndarray:
    a = np.array(x, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected 3 finite numbers, got {np.asarray(x).tolist()!r}")
    a.flags.writeable = False
    return a


def _body_name(name: str, body):
    if not isinstance(body, (str, int, np.integer)) or isinstance(body, bool):
        raise ValueError(f"{name}: expected a link or frame name or a body index, got {body!r}")
    return body if isinstance(body, str) else int(body)


class _PointKinematics(NamedTuple):
    """A point fixed on a body, world axes, flat batch: position (B, 3), Jacobian (B, 3, nv)
    of its velocity and ``Jdot v`` (B, 3), its acceleration at ``qdd = 0``."""
    p: np.ndarray
    J: np.ndarray
    Jdv: np.ndarray


def frame_kinematics(model, q, v, body):
    """World pose (B, 4, 4), Jacobian (B, 6, nv) and ``Jdot v`` (B, 6) of a link/frame name or
    body index, ``"local_world_aligned"`` coordinates, for flat batches ``q``, ``v``."""
    name = model.link_names[model.body_index(body)] if not isinstance(body, str) else body
    T = frame_pose(model, q, name, check_finite=False)
    J = jacobian(model, q, name, "local_world_aligned", check_finite=False)
    Jdv = jacobian_dot_times_v(model, q, v, name, "local_world_aligned", check_finite=False)
    return T, J, Jdv


def point_kinematics(model, q, v, body, point) -> _PointKinematics:
    """Position, velocity Jacobian and ``Jdot v`` of the point ``point`` (3,), given in the
    coordinates of the link/frame ``body``, for flat batches ``q`` (B, nq), ``v`` (B, nv).

    ``p = p_f + r`` with ``r = R_f point``; ``v_p = v_f + omega x r``, so
    ``J_p = J_lin - [r]x J_ang``; ``a_p = a_f + alpha x r + omega x (omega x r)``, with ``J``
    and ``Jdot v`` of the frame in ``"local_world_aligned"`` coordinates.
    """
    T, J, Jdv = frame_kinematics(model, q, v, body)
    r = T[:, :3, :3] @ point
    omega = np.einsum("bij,bj->bi", J[:, 3:], v)
    Jp = J[:, :3] - np.cross(r[:, :, None], J[:, 3:], axis=1)
    acc = Jdv[:, :3] + np.cross(Jdv[:, 3:], r) + np.cross(omega, np.cross(omega, r))
    return _PointKinematics(T[:, :3, 3] + r, Jp, acc)


@dataclass(frozen=True, eq=False)
class PointConstraint:
    """A point of a body held at a fixed world position (3 constraints): a pin, a contact
    without slip.

    ``body``: link/frame name or body index; ``point`` (3,): the point in the coordinates of
    that link/frame (m); ``target`` (3,): its world position (m), used by the Baumgarte
    position term. Force: ``[fx, fy, fz]`` (N) applied to the body at the point, world axes.
    """
    body: str | int
    point: np.ndarray = (0.0, 0.0, 0.0)
    target: np.ndarray = (0.0, 0.0, 0.0)

    dim = 3

    def __post_init__(self):
        object.__setattr__(self, "body", _body_name("PointConstraint.body", self.body))
        object.__setattr__(self, "point", _vector3("PointConstraint.point", self.point))
        object.__setattr__(self, "target", _vector3("PointConstraint.target", self.target))

    def rows(self, model, q, v):
        pk = point_kinematics(model, q, v, self.body, self.point)
        return pk.J, pk.Jdv, pk.p - self.target


@dataclass(frozen=True, eq=False)
class WeldConstraint:
    """A body frame welded to a fixed world pose (6 constraints).

    ``body``: link/frame name or body index; ``target`` (4, 4): the frame's world pose.
    Position error ``[p - p_target; log(R R_target^T)]`` (world axes, m and rad). Force:
    wrench ``[force (N); torque (N m)]`` applied to the body, world axes, torque about the
    frame origin.
    """
    body: str | int
    target: np.ndarray

    dim = 6

    def __post_init__(self):
        object.__setattr__(self, "body", _body_name("WeldConstraint.body", self.body))
        T = np.array(self.target, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError(f"WeldConstraint.target: expected a finite 4 x 4 pose, got shape {T.shape}")
        R = T[:3, :3]
        if np.abs(R @ R.T - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0 or np.any(T[3] != (0, 0, 0, 1)):
            raise ValueError("WeldConstraint.target: not a homogeneous transform (rotation block and last row "
                             "[0, 0, 0, 1])")
        T.flags.writeable = False
        object.__setattr__(self, "target", T)

    def rows(self, model, q, v):
        T, J, Jdv = frame_kinematics(model, q, v, self.body)
        return J, Jdv, np.concatenate([T[:, :3, 3] - self.target[:3, 3],
                                       _log_rotation(T[:, :3, :3] @ self.target[:3, :3].T)], axis=1)


@dataclass(frozen=True, eq=False)
class LoopConstraint:
    """Two bodies joined at a point (3 constraints): closes a kinematic loop (four-bar
    linkage, parallel mechanism) with a spherical joint, or with a revolute joint in a planar
    mechanism (its out-of-plane rows are then redundant).

    ``point_a`` in the coordinates of ``body_a`` and ``point_b`` in those of ``body_b`` must
    coincide. Force: ``[fx, fy, fz]`` (N) applied to ``body_a`` at the point, world axes;
    ``body_b`` receives the opposite force.
    """
    body_a: str | int
    point_a: np.ndarray
    body_b: str | int
    point_b: np.ndarray

    dim = 3

    def __post_init__(self):
        for side in ("a", "b"):
            object.__setattr__(self, f"body_{side}", _body_name(f"LoopConstraint.body_{side}",
                                                               getattr(self, f"body_{side}")))
            object.__setattr__(self, f"point_{side}", _vector3(f"LoopConstraint.point_{side}",
                                                               getattr(self, f"point_{side}")))

    def rows(self, model, q, v):
        a = point_kinematics(model, q, v, self.body_a, self.point_a)
        b = point_kinematics(model, q, v, self.body_b, self.point_b)
        return a.J - b.J, a.Jdv - b.Jdv, a.p - b.p


@dataclass(frozen=True, eq=False)
class CouplingConstraint:
    """Two 1-dof joints coupled by a gear or a mimic joint (1 constraint):
    ``q_b = ratio q_a + offset``, so ``v_b = ratio v_a``.

    ``joint_a``, ``joint_b``: names of 1-dof joints (``model.joint_names``). Force: the joint
    force (N m or N) applied at ``joint_b``; ``joint_a`` receives ``-ratio`` times it.
    """
    joint_a: str
    joint_b: str
    ratio: float = 1.0
    offset: float = 0.0

    dim = 1

    def __post_init__(self):
        for name in ("joint_a", "joint_b"):
            if not isinstance(getattr(self, name), str):
                raise ValueError(f"CouplingConstraint.{name}: expected a joint name, got {getattr(self, name)!r}")
        if self.joint_a == self.joint_b:
            raise ValueError(f"CouplingConstraint: joint_a and joint_b are the same joint {self.joint_a!r}")
        for name in ("ratio", "offset"):
            x = getattr(self, name)
            if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)) or not np.isfinite(x):
                raise ValueError(f"CouplingConstraint.{name}: expected a finite number, got {x!r}")
            object.__setattr__(self, name, float(x))

    def _indices(self, model, name):
        for i, jn in enumerate(model.body_joint_names):
            if jn == name and Jt.NV[model.joint_type[i]] == 1:
                return int(model.idx_q[i]), int(model.idx_v[i])
        raise ValueError(f"CouplingConstraint: unknown 1-dof joint {name!r}; known: {list(model.joint_names)}")

    def rows(self, model, q, v):
        (qa, va), (qb, vb) = self._indices(model, self.joint_a), self._indices(model, self.joint_b)
        J = np.zeros((q.shape[0], 1, model.nv))
        J[:, 0, vb] = 1.0
        J[:, 0, va] -= self.ratio
        phi = q[:, qb] - self.ratio * q[:, qa] - self.offset
        return J, np.zeros((q.shape[0], 1)), phi[:, None]


CONSTRAINT_TYPES = (PointConstraint, WeldConstraint, LoopConstraint, CouplingConstraint)


def _log_rotation(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (B, 3) of rotation matrices (B, 3, 3)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_rotvec()


class ConstrainedDynamics(NamedTuple):
    """Result of :func:`constrained_dynamics`: ``a`` (..., nv); ``forces``, one array
    (..., dim) per constraint, in the order given (frames and units in each constraint
    class); ``rank`` (int, or (...,) ints for a batch): the number of independent constraint
    directions, less than the total dimension when constraints are redundant."""
    a: np.ndarray
    forces: tuple
    rank: object


def constraint_jacobian(model, q, v, constraints: Sequence) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stacked ``(J_c, Jdot_c v, phi)`` of ``constraints`` for flat batches ``q`` (B, nq),
    ``v`` (B, nv): (B, m, nv), (B, m), (B, m) with ``m`` the sum of their dimensions."""
    B = q.shape[0]
    if not constraints:
        return np.zeros((B, 0, model.nv)), np.zeros((B, 0)), np.zeros((B, 0))
    parts = [c.rows(model, q, v) for c in constraints]
    return tuple(np.concatenate([p[k] for p in parts], axis=1) for k in range(3))


def _check_constraints(constraints) -> list:
    if isinstance(constraints, CONSTRAINT_TYPES):
        constraints = [constraints]
    try:
        out = list(constraints)
    except TypeError:
        raise ValueError(f"constraints: expected a sequence of constraints, got {type(constraints).__name__}") from None
    for k, c in enumerate(out):
        if not isinstance(c, CONSTRAINT_TYPES):
            raise ValueError(f"constraints[{k}]: expected one of {[t.__name__ for t in CONSTRAINT_TYPES]}, "
                             f"got {type(c).__name__}")
    return out


def _check_baumgarte(baumgarte) -> tuple[float, float]:
    try:
        alpha, beta = (float(x) for x in baumgarte)
    except (TypeError, ValueError):
        raise ValueError(f"baumgarte: expected two numbers (alpha, beta), got {baumgarte!r}") from None
    if not (np.isfinite(alpha) and np.isfinite(beta) and alpha >= 0 and beta >= 0):
        raise ValueError(f"baumgarte: expected finite alpha >= 0 and beta >= 0, got {baumgarte!r}")
    return alpha, beta


def cholesky(model, M: np.ndarray, what: str) -> np.ndarray:
    """Lower Cholesky factors of the mass matrices (B, nv, nv); ValueError if one is not
    positive definite."""
    try:
        return np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ValueError(f"{what}: the mass matrix is not positive definite at this configuration (a body "
                         "without mass or inertia about its joint?); the dynamics is undefined") from None


def symmetric_pinv(S: np.ndarray, rcond: float) -> tuple[np.ndarray, np.ndarray]:
    """Pseudo-inverses (B, m, m) of symmetric positive semi-definite matrices and their ranks
    (B,): eigenvalues at most ``rcond`` times the largest count as zero."""
    w, V = np.linalg.eigh(S)
    if w.shape[-1] == 0:
        return S.copy(), np.zeros(S.shape[0], dtype=np.int64)
    keep = w > rcond * np.maximum(w[:, -1:], 0.0)
    keep &= w > 0
    winv = np.where(keep, 1.0 / np.where(keep, w, 1.0), 0.0)
    return (V * winv[:, None, :]) @ np.swapaxes(V, 1, 2), keep.sum(axis=1)


def constrained_dynamics(model, q, v, tau, constraints, baumgarte=(0.0, 0.0), *, rcond: float = RCOND,
                         friction: bool = True, armature: bool = True,
                         check_finite: bool = True) -> ConstrainedDynamics:
    """Forward dynamics under constraints: accelerations and constraint forces.

    Solves ``M a = tau - h + J_c^T lambda`` with ``J_c a = -Jdot_c v - 2 alpha J_c v -
    beta^2 phi`` by the Schur complement ``J_c M^-1 J_c^T`` (module docstring).

    Args:
        q: (..., nq). v, tau: (..., nv).
        constraints: a sequence of :class:`PointConstraint`, :class:`WeldConstraint`,
            :class:`LoopConstraint`, :class:`CouplingConstraint` (or a single one).
        baumgarte: ``(alpha, beta)`` >= 0 in 1/s; ``(0, 0)`` enforces the constraints at
            acceleration level only.
        rcond: relative threshold below which eigenvalues of the Schur complement count as
            zero (redundant constraints).
        friction, armature, check_finite: as in :func:`robodyn.aba`.

    Returns:
        :class:`ConstrainedDynamics` ``(a, forces, rank)``. Without constraints ``a`` equals
        ``aba(q, v, tau)``.

    Raises ValueError for bad shapes or values, unknown bodies or joints, and a mass matrix
    that is not positive definite. Reference: Featherstone, RBDA (2008), section 8.3;
    J. Baumgarte, "Stabilization of constraints and integrals of motion in dynamical
    systems", Comput. Methods Appl. Mech. Eng. 1 (1972).
    """
    constraints = _check_constraints(constraints)
    alpha, beta = _check_baumgarte(baumgarte)
    if not (np.isfinite(rcond) and 0 <= rcond < 1):
        raise ValueError(f"rcond: expected a number in [0, 1), got {rcond!r}")
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    if check_finite:
        for name, arr in x.items():
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"constrained_dynamics: {name} contains NaN or Inf")
    Q, V, TAU = (_inputs.as_batch(x[k]) for k in ("q", "v", "tau"))
    M = crba(model, Q, armature=armature, check_finite=False)
    h = rnea(model, Q, V, np.zeros_like(V), friction=friction, armature=armature, check_finite=False)
    Jc, Jdv, phi = constraint_jacobian(model, Q, V, constraints)
    L = cholesky(model, M, "constrained_dynamics")
    LT = np.swapaxes(L, 1, 2)
    a0 = np.linalg.solve(LT, np.linalg.solve(L, (TAU - h)[..., None]))[..., 0]
    Y = np.linalg.solve(L, np.swapaxes(Jc, 1, 2))                    # L^-1 J_c^T (B, nv, m)
    S = np.swapaxes(Y, 1, 2) @ Y                                     # J_c M^-1 J_c^T
    gamma = -Jdv - 2.0 * alpha * np.einsum("bij,bj->bi", Jc, V) - beta * beta * phi
    Sinv, rank = symmetric_pinv(S, rcond)
    lam = np.einsum("bij,bj->bi", Sinv, gamma - np.einsum("bij,bj->bi", Jc, a0))
    a = a0 + np.linalg.solve(LT, Y @ lam[..., None])[..., 0]
    bounds = np.cumsum([0] + [c.dim for c in constraints])
    forces = tuple(_inputs.unflatten(lam[:, lo:hi], batch) if batch else lam[0, lo:hi]
                   for lo, hi in zip(bounds[:-1], bounds[1:]))
    if batch == ():
        return ConstrainedDynamics(a[0], forces, int(rank[0]))
    return ConstrainedDynamics(_inputs.unflatten(a, batch), forces, rank.reshape(batch))
