"""Constrained dynamics: accelerations and constraint forces of a tree with contacts, welds,
closed loops, rods and coupled joints, from the KKT system solved by a Schur complement.

    [[M, J_c^T], [J_c, 0]] [a; -lambda] = [tau - h; gamma]

    gamma = -Jdot_c v - 2 alpha J_c v - beta^2 phi       (Baumgarte stabilisation)

``M = crba(q)``, ``h = rnea(q, v, 0) = C v + g (+ friction)``, ``J_c`` (m, nv) the stacked
constraint Jacobians, ``phi`` (m,) the position errors of the constraints and ``lambda`` the
constraint forces, so that ``M a = tau - h + J_c^T lambda``. With ``alpha = beta = 0`` the
constraint holds at acceleration level (``J_c a + Jdot_c v = 0``); positive values make
position and velocity errors decay as ``phi'' + 2 alpha phi' + beta^2 phi = 0``.

Solution (Schur complement on ``M``, Featherstone RBDA chapter 8; Baumgarte 1972):
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
from ..lie import skew
from ..coupling import expand_q, is_coupled, reduce_columns
from ._lazy import any_lazy, deferred
from . import _inputs
from .crba import crba
from .jacobian import jacobian_pass, moving_frame
from .rnea import rnea

# Eigenvalues of the Schur complement below this fraction of the largest are dropped.
RCOND = 1e-10


def _vector3(name: str, x) -> np.ndarray:
    a = np.array(x, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected 3 finite numbers, got {np.asarray(x).tolist()!r}")
    a.flags.writeable = False
    return a


def _body_name(name: str, body, world: bool = False):
    if world and body is None:
        return None
    if not isinstance(body, (str, int, np.integer)) or isinstance(body, bool):
        raise ValueError(f"{name}: expected a link or frame name or a body index, got {body!r}")
    return body if isinstance(body, str) else int(body)


class FrameKinematics(NamedTuple):
    """A frame or point fixed on a body, flat batch of B states, world axes: orientation
    ``R`` (B, 3, 3) and position ``p`` (B, 3); Jacobians ``J_lin`` (B, 3, nv) of the velocity
    of the point and ``J_ang`` (B, 3, nv) of the angular velocity; ``acc_lin`` (B, 3) and
    ``acc_ang`` (B, 3) the point's classical and the angular acceleration at ``qdd = 0``
    (``Jdot v``)."""
    R: np.ndarray
    p: np.ndarray
    J_lin: np.ndarray
    J_ang: np.ndarray
    acc_lin: np.ndarray
    acc_ang: np.ndarray


def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    return (A @ x[..., None])[..., 0]


def frame_kinematics(model, q, v, body, point=(0.0, 0.0, 0.0)) -> FrameKinematics:
    """Kinematics of the point ``point`` (3,) given in the coordinates of the link/frame
    ``body`` (name or body index; ``None``: a fixed world point), for one state ``q`` (nq,),
    ``v`` (nv,) (then B = 1) or flat batches ``q`` (B, nq), ``v`` (B, nv).

    From one pass of the Jacobian kernel (world-frame Jacobian ``oJ``, body pose ``(oR, op)``,
    body-frame velocity ``[v_o; w]`` and acceleration ``[a_o; alpha]`` at ``qdd = 0``), with
    ``r`` the point in body coordinates and ``x = op + oR r``:
    ``J_lin = oJ_lin - [x]x oJ_ang``, ``J_ang = oJ_ang``,
    ``acc_lin = oR (a_o + alpha x r + w x (v_o + w x r))``, ``acc_ang = oR alpha``
    (spatial to classical acceleration, RBDA section 2.11).
    """
    point = np.asarray(point, dtype=float)
    B = _inputs.as_batch(q).shape[0]
    if body is None:
        zeros = np.zeros((B, 3, model.nv))
        return FrameKinematics(np.broadcast_to(np.eye(3), (B, 3, 3)), np.broadcast_to(point, (B, 3)), zeros, zeros,
                               np.zeros((B, 3)), np.zeros((B, 3)))
    b, R_bf, p_bf = moving_frame(model, body)
    r = p_bf + R_bf @ point
    oJ, oR, op, acc, vel = jacobian_pass(model, {"q": q, "v": v}, b, False, "constrained_dynamics")
    x = op + oR @ r
    w, alpha = vel[:, 3:], acc[:, 3:]
    a_body = acc[:, :3] + np.cross(alpha, r) + np.cross(w, vel[:, :3] + np.cross(w, r))
    return FrameKinematics(oR @ R_bf, x, oJ[:, :3] - skew(x) @ oJ[:, 3:], oJ[:, 3:], _mv(oR, a_body), _mv(oR, alpha))


@dataclass(frozen=True, eq=False)
class PointConstraint:
    """A point of a body held at a fixed world position (3 constraints): a pin, a contact
    without slip.

    ``body``: link/frame name or body index; ``point`` (3,): the point in the coordinates of
    that link/frame (m); ``target`` (3,): the world position where it is held (m), used by
    the Baumgarte position term. Force: ``[fx, fy, fz]`` (N) applied to the body at the point, world axes.
    """
    body: str | int
    point: np.ndarray
    target: np.ndarray

    dim = 3

    def __post_init__(self):
        object.__setattr__(self, "body", _body_name("PointConstraint.body", self.body))
        object.__setattr__(self, "point", _vector3("PointConstraint.point", self.point))
        object.__setattr__(self, "target", _vector3("PointConstraint.target", self.target))

    def rows(self, model, q, v):
        k = frame_kinematics(model, q, v, self.body, self.point)
        return k.J_lin, k.acc_lin, k.p - self.target


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
        k = frame_kinematics(model, q, v, self.body)
        return (np.concatenate([k.J_lin, k.J_ang], axis=1), np.concatenate([k.acc_lin, k.acc_ang], axis=1),
                np.concatenate([k.p - self.target[:3, 3], _log_rotation(k.R @ self.target[:3, :3].T)], axis=1))


@dataclass(frozen=True, eq=False)
class LoopConstraint:
    """Two bodies joined at a point (3 constraints): closes a kinematic loop (four-bar
    linkage, parallel mechanism) with a spherical joint, or with a revolute joint in a planar
    mechanism (its out-of-plane rows are then redundant).

    ``point_a`` in the coordinates of ``body_a`` and ``point_b`` in those of ``body_b`` must
    coincide (``body_b=None``: ``point_b`` is a fixed world point). Force: ``[fx, fy, fz]``
    (N) applied to ``body_a`` at the point, world axes; ``body_b`` receives the opposite force.
    """
    body_a: str | int
    point_a: np.ndarray
    body_b: str | int | None
    point_b: np.ndarray

    dim = 3

    def __post_init__(self):
        _two_points(self)

    def rows(self, model, q, v):
        a = frame_kinematics(model, q, v, self.body_a, self.point_a)
        b = frame_kinematics(model, q, v, self.body_b, self.point_b)
        return a.J_lin - b.J_lin, a.acc_lin - b.acc_lin, a.p - b.p


@dataclass(frozen=True, eq=False)
class DistanceConstraint:
    """A rigid massless rod of length ``length`` (m) between two body points (1 constraint):
    ``|p_a - p_b| = length``; ``body_b=None`` anchors the rod at the world point ``point_b``.

    Position error ``phi = (|d|^2 - length^2) / (2 length)`` with ``d = p_a - p_b`` (equal to
    ``|d| - length`` to first order), Jacobian ``d^T (J_a - J_b) / length``. Force: the rod
    force (N) along ``d / length``, applied to ``body_a`` at ``point_a`` (positive pushes the
    points apart, negative is tension); ``body_b`` receives the opposite force.
    """
    body_a: str | int
    point_a: np.ndarray
    body_b: str | int | None
    point_b: np.ndarray
    length: float

    dim = 1

    def __post_init__(self):
        _two_points(self)
        L = self.length
        number = isinstance(L, (int, float, np.integer, np.floating)) and not isinstance(L, bool)
        if not (number and np.isfinite(L) and L > 0):
            raise ValueError(f"DistanceConstraint.length: expected a finite number > 0, got {L!r}")
        object.__setattr__(self, "length", float(L))

    def rows(self, model, q, v):
        a = frame_kinematics(model, q, v, self.body_a, self.point_a)
        b = frame_kinematics(model, q, v, self.body_b, self.point_b)
        d, dJ = a.p - b.p, a.J_lin - b.J_lin
        dv = _mv(dJ, _inputs.as_batch(v))
        L = self.length
        J = (d[:, None, :] @ dJ) / L
        Jdv = (np.sum(d * (a.acc_lin - b.acc_lin), axis=1) + np.sum(dv * dv, axis=1)) / L
        phi = (np.sum(d * d, axis=1) - L * L) / (2.0 * L)
        return J, Jdv[:, None], phi[:, None]


def _two_points(c) -> None:
    """Check and freeze ``body_a``, ``point_a``, ``body_b`` (or None), ``point_b`` of ``c``."""
    kind = type(c).__name__
    for side in ("a", "b"):
        object.__setattr__(c, f"body_{side}", _body_name(f"{kind}.body_{side}", getattr(c, f"body_{side}"),
                                                         world=side == "b"))
        object.__setattr__(c, f"point_{side}", _vector3(f"{kind}.point_{side}", getattr(c, f"point_{side}")))
    if c.body_a == c.body_b and isinstance(c.body_a, str):
        raise ValueError(f"{kind}: body_a and body_b are the same body {c.body_a!r}")


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
        if is_coupled(model):  # the full tree's row at E(q) (either joint may be a mimic joint), columns by G
            J, dJv, phi = self.rows(model.full, expand_q(model, q), None)
            return reduce_columns(model, J), dJv, phi
        (qa, va), (qb, vb) = self._indices(model, self.joint_a), self._indices(model, self.joint_b)
        q = _inputs.as_batch(q)
        J = np.zeros((q.shape[0], 1, model.nv))
        J[:, 0, vb] = 1.0
        J[:, 0, va] -= self.ratio
        phi = q[:, qb] - self.ratio * q[:, qa] - self.offset
        return J, np.zeros((q.shape[0], 1)), phi[:, None]


CONSTRAINT_TYPES = (PointConstraint, WeldConstraint, LoopConstraint, DistanceConstraint, CouplingConstraint)


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
    """Stacked ``(J_c, Jdot_c v, phi)`` of ``constraints`` for one state ``q`` (nq,), ``v``
    (nv,) (then B = 1) or flat batches ``q`` (B, nq), ``v`` (B, nv): (B, m, nv), (B, m),
    (B, m) with ``m`` the sum of their dimensions."""
    if any_lazy(q, v):
        return deferred(constraint_jacobian, locals())
    B = _inputs.as_batch(q).shape[0]
    if not constraints:
        return np.zeros((B, 0, model.nv)), np.zeros((B, 0)), np.zeros((B, 0))
    parts = [c.rows(model, q, v) for c in constraints]
    return tuple(np.concatenate([p[k] for p in parts], axis=1) for k in range(3))


def check_constraints(constraints) -> list:
    """``constraints`` (one constraint or a sequence) as a list, each one of
    ``CONSTRAINT_TYPES``, or a ValueError naming the first that is not."""
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


def check_baumgarte(baumgarte) -> tuple[float, float]:
    """``(alpha, beta)`` as finite floats >= 0, or a ValueError."""
    try:
        alpha, beta = (float(x) for x in baumgarte)
    except (TypeError, ValueError):
        raise ValueError(f"baumgarte: expected two numbers (alpha, beta), got {baumgarte!r}") from None
    if not (np.isfinite(alpha) and np.isfinite(beta) and alpha >= 0 and beta >= 0):
        raise ValueError(f"baumgarte: expected finite alpha >= 0 and beta >= 0, got {baumgarte!r}")
    return alpha, beta


def cholesky(M: np.ndarray, what: str) -> np.ndarray:
    """Lower Cholesky factors of the mass matrices (B, nv, nv); ValueError if one is not
    positive definite."""
    try:
        return np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ValueError(f"{what}: the mass matrix is not positive definite at this configuration (a body "
                         "without mass or inertia about its joint?); the dynamics is undefined") from None


def symmetric_pinv(S: np.ndarray, rcond: float) -> tuple[np.ndarray, np.ndarray]:
    """Pseudo-inverses (B, m, m) of symmetric positive semi-definite matrices and their ranks
    (B,): eigenvalues at most ``rcond`` times the largest count as zero. A matrix with NaN or
    Inf (inputs that ``check_finite=False`` let through) gives NaN and rank 0."""
    finite = np.isfinite(S).all(axis=(1, 2))
    if not finite.all():
        P, rank = np.full_like(S, np.nan), np.zeros(S.shape[0], dtype=np.int64)
        P[finite], rank[finite] = symmetric_pinv(S[finite], rcond)
        return P, rank
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
            :class:`LoopConstraint`, :class:`DistanceConstraint`, :class:`CouplingConstraint`
            (or a single one).
        baumgarte: ``(alpha, beta)`` >= 0 in 1/s; ``(0, 0)`` enforces the constraints at
            acceleration level only.
        rcond: relative threshold below which eigenvalues of the Schur complement count as
            zero (redundant constraints).
        friction, armature, check_finite: as in :func:`robodyn.aba`.

    Returns:
        :class:`ConstrainedDynamics` ``(a, forces, rank)``. Without constraints ``a`` equals
        ``aba(q, v, tau)``. With ``check_finite=False`` a state with NaN or Inf gets NaN
        (rank 0 when its ``q`` is not finite), the others their own results.

    Raises ValueError for bad shapes or values, unknown bodies or joints, and a mass matrix
    that is not positive definite. Reference: Featherstone, RBDA (2008), chapter 8;
    J. Baumgarte, "Stabilization of constraints and integrals of motion in dynamical
    systems", Comput. Methods Appl. Mech. Eng. 1 (1972).
    """
    if any_lazy(q, v, tau):
        return deferred(constrained_dynamics, locals())
    constraints = check_constraints(constraints)
    alpha, beta = check_baumgarte(baumgarte)
    if not (np.isfinite(rcond) and 0 <= rcond < 1):
        raise ValueError(f"rcond: expected a number in [0, 1), got {rcond!r}")
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    if check_finite:
        for name, arr in x.items():
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"constrained_dynamics: {name} contains NaN or Inf")
    nv = model.nv
    M = crba(model, x["q"], armature=armature, check_finite=False).reshape(-1, nv, nv)
    h = rnea(model, x["q"], x["v"], np.zeros_like(x["v"]), friction=friction, armature=armature,
             check_finite=False).reshape(-1, nv)
    Jc, Jdv, phi = constraint_jacobian(model, x["q"], x["v"], constraints)
    V, TAU = _inputs.as_batch(x["v"]), _inputs.as_batch(x["tau"])
    L = cholesky(M, "constrained_dynamics")
    LT = np.swapaxes(L, 1, 2)
    a0 = np.linalg.solve(LT, np.linalg.solve(L, (TAU - h)[..., None]))[..., 0]
    Y = np.linalg.solve(L, np.swapaxes(Jc, 1, 2))                    # L^-1 J_c^T (B, nv, m)
    S = np.swapaxes(Y, 1, 2) @ Y                                     # J_c M^-1 J_c^T
    gamma = -Jdv - 2.0 * alpha * _mv(Jc, V) - beta * beta * phi
    Sinv, rank = symmetric_pinv(S, rcond)
    lam = _mv(Sinv, gamma - _mv(Jc, a0))
    a = a0 + np.linalg.solve(LT, Y @ lam[..., None])[..., 0]
    bounds = np.cumsum([0] + [c.dim for c in constraints])
    forces = tuple(_inputs.unflatten(lam[:, lo:hi], batch) if batch else lam[0, lo:hi]
                   for lo, hi in zip(bounds[:-1], bounds[1:]))
    if batch == ():
        return ConstrainedDynamics(a[0], forces, int(rank[0]))
    return ConstrainedDynamics(_inputs.unflatten(a, batch), forces, rank.reshape(batch))
