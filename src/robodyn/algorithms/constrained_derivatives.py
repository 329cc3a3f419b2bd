"""Derivatives of the constrained forward dynamics: ``d(a, lambda) / d(q, v, tau)``.

:func:`robodyn.constrained_dynamics` solves, for the accelerations ``a`` and the constraint
forces ``lambda`` (``constrained.py``)::

    ID(q, v, a, lambda) = M a + h - J_c^T lambda = tau                             (1)
    c(q, v, a) = J_c a + Jdot_c v + 2 alpha J_c v + beta^2 phi = 0                 (2)

Differentiating (1) and (2) at the solution, with the partial derivatives ``dID``, ``dc`` taken
at fixed ``(a, lambda)`` (Carpentier and Mansard, 2018; Pinocchio's
``computeConstraintDynamicsDerivatives``)::

    [[M, J_c^T], [J_c, 0]] [da/dx; -dlambda/dx] = [dtau/dx - dID/dx; -dc/dx],   x = q, v, tau

solved by the Schur complement ``S = J_c M^-1 J_c^T`` (full rank: the forces are unique):
``dlambda = S^-1 (r_2 - J_c M^-1 r_1)``, ``da = M^-1 (r_1 + J_c^T dlambda)``.

``dID``: ``ID`` is the inverse dynamics with the constraint forces as external wrenches, so
``dID/dq``, ``dID/dv`` are :func:`robodyn.rnea_derivatives` at ``(q, v, a)`` with the wrenches
``W_i = sum [f; n + x x f]`` (world axes, about the world origin) of the forces ``f`` (and
torques ``n``) acting at the points ``x`` of body ``i``. That derivative holds ``W_i`` fixed;
the forces keep their world axes but act at points that move with their body
(``dx/dq = J_x``, the point's linear Jacobian), which adds ``J_w,i^T [f]x J_x`` (``J_w,i``
the body's angular Jacobian in world axes). A rod's force ``lambda d / L`` also turns with
``d = x_a - x_b``: ``-lambda / L J_d^T J_d`` (``J_d = J_xa - J_xb``).

``dc``: the rows ``J_c a + Jdot_c v`` are classical accelerations of body points (``a_x =
A_lin + alpha x x + w x v_x``, ``v_x = V_lin + w x x``, from the world spatial velocity ``V``
and acceleration ``A`` of the body) and angular accelerations ``alpha``; their derivatives
follow from :func:`robodyn.frame_velocity_derivatives` and
:func:`robodyn.frame_acceleration_derivatives` in world coordinates, with ``dx/dq = J_x``::

    d v_x/dq = dV_lin/dq + dw/dq x x + w x J_x,   d v_x/dv = J_x
    d a_x/dq = dA_lin/dq + dalpha/dq x x + alpha x J_x + dw/dq x v_x + w x d v_x/dq
    d a_x/dv = dA_lin/dv + dalpha/dv x x + J_w x v_x + w x J_x

The Baumgarte terms add ``2 alpha d(J_c v)`` and ``beta^2 dphi/dq`` (``J_x`` for a point; for a
weld's rotation error ``e = log(R R_target^T)``, ``J_l(e)^-1 J_w`` with ``J_l`` the left
Jacobian of SO(3)). Derivatives with respect to ``q`` are in the tangent space of
:func:`robodyn.integrate`, as :func:`robodyn.aba_derivatives`.

Reference: J. Carpentier and N. Mansard, "Analytical derivatives of rigid body dynamics
algorithms", Robotics: Science and Systems, 2018; Pinocchio,
``include/pinocchio/algorithm/constrained-dynamics-derivatives.hxx``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from ._lazy import any_lazy, deferred
from . import _inputs
from .constrained import (RCOND, CouplingConstraint, LoopConstraint, PointConstraint,
                          WeldConstraint, check_baumgarte, check_constraints, cholesky, constrained_dynamics,
                          frame_kinematics)
from .frame_derivatives import frame_acceleration_derivatives, frame_velocity_derivatives
from .jacobian import moving_frame
from .rnea_derivatives import rnea_derivatives


class ConstrainedDynamicsDerivatives(NamedTuple):
    """Result of :func:`constrained_dynamics_derivatives`: ``da_dq``, ``da_dv``, ``da_dtau``
    (..., nv, nv) and ``dlambda_dq``, ``dlambda_dv``, ``dlambda_dtau`` (..., m, nv), the rows of
    ``lambda`` those of the constraint forces concatenated in the order of the constraints."""
    da_dq: np.ndarray
    da_dv: np.ndarray
    da_dtau: np.ndarray
    dlambda_dq: np.ndarray
    dlambda_dv: np.ndarray
    dlambda_dtau: np.ndarray


class _Point(NamedTuple):
    """A point fixed on body ``body`` (-1: the world), flat batch of B states, world axes:
    position ``x`` (B, 3) and orientation ``R`` (B, 3, 3) of its frame; Jacobians ``Jx`` of its
    velocity and ``Jw`` of the body's angular velocity (B, 3, nv); velocity ``vx``, angular
    velocity ``w``, classical acceleration ``ax`` and angular acceleration ``alpha`` at ``a``
    (B, 3); their derivatives (B, 3, nv)."""
    body: int
    x: np.ndarray
    R: np.ndarray
    Jx: np.ndarray
    Jw: np.ndarray
    vx: np.ndarray
    w: np.ndarray
    ax: np.ndarray
    alpha: np.ndarray
    dvx_dq: np.ndarray
    dw_dq: np.ndarray
    dax_dq: np.ndarray
    dax_dv: np.ndarray
    dalpha_dq: np.ndarray
    dalpha_dv: np.ndarray


def _mv(A, x):
    return (A @ x[..., None])[..., 0]


def _xc(a, M):
    """``a x`` each column of ``M``: a (B, 3), M (B, 3, n) -> (B, 3, n)."""
    return np.cross(a[:, :, None], M, axis=1)


def _point(model, q, v, a, body, point) -> _Point:
    """Kinematics and derivatives of the point ``point`` of ``body`` (``None``: a world point)
    for one state (``q`` (nq,), ...) or a flat batch (``q`` (B, nq), ...), as a batch."""
    (B, _), nv = _inputs.as_batch(q).shape, model.nv
    if body is None:
        z, zJ = np.zeros((B, 3)), np.zeros((B, 3, nv))
        return _Point(-1, np.broadcast_to(point, (B, 3)), np.broadcast_to(np.eye(3), (B, 3, 3)), zJ, zJ,
                      z, z, z, z, zJ, zJ, zJ, zJ, zJ, zJ)
    b = int(moving_frame(model, body)[0])
    k = frame_kinematics(model, q, v, body, point)
    dV = frame_velocity_derivatives(model, q, v, b, "world", check_finite=False)[0].reshape(B, 6, nv)
    dAq, dAv = (d.reshape(B, 6, nv) for d in
                frame_acceleration_derivatives(model, q, v, a, b, "world", check_finite=False)[:2])
    x, Jx, Jw, v, a = k.p, k.J_lin, k.J_ang, _inputs.as_batch(v), _inputs.as_batch(a)
    vx, w = _mv(Jx, v), _mv(Jw, v)
    ax, alpha = k.acc_lin + _mv(Jx, a), k.acc_ang + _mv(Jw, a)
    dw_dq = dV[:, 3:]
    dvx_dq = dV[:, :3] - _xc(x, dw_dq) + _xc(w, Jx)
    dax_dq = dAq[:, :3] - _xc(x, dAq[:, 3:]) + _xc(alpha, Jx) - _xc(vx, dw_dq) + _xc(w, dvx_dq)
    dax_dv = dAv[:, :3] - _xc(x, dAv[:, 3:]) - _xc(vx, Jw) + _xc(w, Jx)
    return _Point(b, x, k.R, Jx, Jw, vx, w, ax, alpha, dvx_dq, dw_dq, dax_dq, dax_dv, dAq[:, 3:], dAv[:, 3:])


def _left_jacobian_inverse(e):
    """``J_l(e)^-1`` (B, 3, 3) of rotation vectors ``e`` (B, 3): ``d log(exp(w) E) / dw`` at
    ``w = 0`` for ``E = exp(e)``; ``I - [e]x / 2 + k [e]x^2``, ``k = 1/t^2 - (1 + cos t) /
    (2 t sin t)`` (``1/12`` at ``t = 0``)."""
    t = np.linalg.norm(e, axis=1)
    small = t < 1e-4
    ts = np.where(small, 1.0, t)
    k = np.where(small, 1.0 / 12.0 + t * t / 720.0, 1.0 / ts ** 2 - (1.0 + np.cos(ts)) / (2.0 * ts * np.sin(ts)))
    E = np.cross(e[:, :, None], np.eye(3)[None], axis=1)  # [e]x
    return np.eye(3) - 0.5 * E + k[:, None, None] * (E @ E)


def _rows(c, model, q, v, a, lam, alpha, beta):
    """Constraint ``c``'s rows at ``(q, v, a)`` with its force ``lam`` (B, dim): ``(J, dc/dq,
    dc/dv, forces, extra)``, ``forces`` a list of ``(point, f (B, 3), n (B, 3))`` acting on
    bodies (world axes) and ``extra`` (B, nv, nv) or None a further term of ``dID/dq``."""
    kv, kp = 2.0 * alpha, beta * beta
    if isinstance(c, CouplingConstraint):  # J constant: J a + 2 alpha J v + beta^2 (q_b - r q_a - o)
        J = c.rows(model, q, v)[0]
        return J, kp * J, kv * J, [], None
    if isinstance(c, (PointConstraint, WeldConstraint)):
        p = _point(model, q, v, a, c.body, np.zeros(3) if isinstance(c, WeldConstraint) else c.point)
        J, cq, cv = p.Jx, p.dax_dq + kv * p.dvx_dq + kp * p.Jx, p.dax_dv + kv * p.Jx
        if isinstance(c, PointConstraint):
            return J, cq, cv, [(p, lam, None)], None
        e = Rotation.from_matrix(p.R @ c.target[:3, :3].T).as_rotvec()
        cq_w = p.dalpha_dq + kv * p.dw_dq + kp * (_left_jacobian_inverse(e) @ p.Jw)
        return (np.concatenate([J, p.Jw], 1), np.concatenate([cq, cq_w], 1),
                np.concatenate([cv, p.dalpha_dv + kv * p.Jw], 1), [(p, lam[:, :3], lam[:, 3:])], None)
    pa = _point(model, q, v, a, c.body_a, c.point_a)
    pb = _point(model, q, v, a, c.body_b, c.point_b)
    Jd, dvd_dq = pa.Jx - pb.Jx, pa.dvx_dq - pb.dvx_dq
    dad_dq, dad_dv = pa.dax_dq - pb.dax_dq, pa.dax_dv - pb.dax_dv
    if isinstance(c, LoopConstraint):
        return (Jd, dad_dq + kv * dvd_dq + kp * Jd, dad_dv + kv * Jd, [(pa, lam, None), (pb, -lam, None)], None)
    # DistanceConstraint: c = (d . a_d + u . u + 2 alpha d . u + beta^2 (d . d - L^2) / 2) / L
    L = c.length
    d, u, ad = pa.x - pb.x, pa.vx - pb.vx, pa.ax - pb.ax
    dT = d[:, None, :]
    J = dT @ Jd / L
    cq = (dT @ dad_dq + ad[:, None, :] @ Jd + 2.0 * u[:, None, :] @ dvd_dq
          + kv * (u[:, None, :] @ Jd + dT @ dvd_dq) + kp * dT @ Jd) / L
    cv = (dT @ dad_dv + 2.0 * u[:, None, :] @ Jd) / L + kv * J
    f = lam * d / L
    extra = -(lam[:, 0] / L)[:, None, None] * (np.swapaxes(Jd, 1, 2) @ Jd)
    return J, cq, cv, [(pa, f, None), (pb, -f, None)], extra


def constrained_dynamics_derivatives(model, q, v, tau, constraints, baumgarte=(0.0, 0.0), *,
                                     rcond: float = RCOND, friction: bool = True, armature: bool = True,
                                     check_finite: bool = True) -> ConstrainedDynamicsDerivatives:
    """Partial derivatives of the constrained forward dynamics, ``(a, lambda) =
    constrained_dynamics(q, v, tau, constraints, baumgarte)``, analytical.

    Differentiates ``M a + h - J_c^T lambda = tau`` and ``J_c a + Jdot_c v + 2 alpha J_c v +
    beta^2 phi = 0`` at the solution: ``[[M, J_c^T], [J_c, 0]] [da; -dlambda] = [dtau - dID;
    -dc]`` (module docstring). ``dx_dq[:, k] = d x(q ⊕ eps e_k) / d eps`` at 0 (the tangent
    direction of :func:`robodyn.integrate`), ``dx_dv = dx / dv``, ``dx_dtau = dx / dtau``; the
    same quantities as Pinocchio's ``computeConstraintDynamicsDerivatives`` (``ddq_dq``, ...,
    ``dlambda_dtau``) for its 3D contacts in ``LOCAL_WORLD_ALIGNED`` (a
    :class:`robodyn.PointConstraint`) and, at states where the welded frame is at rest, its
    6D contacts in ``LOCAL_WORLD_ALIGNED`` (a :class:`robodyn.WeldConstraint`).

    Args:
        q: (..., nq). v, tau: (..., nv).
        constraints: a sequence of :class:`robodyn.PointConstraint`,
            :class:`robodyn.WeldConstraint`, :class:`robodyn.LoopConstraint`,
            :class:`robodyn.DistanceConstraint`, :class:`robodyn.CouplingConstraint` (or a
            single one); ``lambda`` (m,) stacks their forces in this order, in their frames
            (world axes for the points, welds, loops).
        baumgarte: ``(alpha, beta)`` >= 0 in 1/s, as in :func:`robodyn.constrained_dynamics`;
            the derivatives of the stabilisation terms are included.
        rcond, friction, armature, check_finite: as in :func:`robodyn.constrained_dynamics`.

    Returns:
        :class:`ConstrainedDynamicsDerivatives` ``(da_dq, da_dv, da_dtau)`` (..., nv, nv) and
        ``(dlambda_dq, dlambda_dv, dlambda_dtau)`` (..., m, nv).

    Raises ValueError for bad shapes or values, unknown bodies or joints, a mass matrix that is
    not positive definite, and redundant constraints (rank below ``m``: the forces, and so
    their derivatives, are not unique). Reference: Carpentier and Mansard, "Analytical
    derivatives of rigid body dynamics algorithms", RSS 2018.
    """
    constraints = check_constraints(constraints)
    alpha, beta = check_baumgarte(baumgarte)
    if any_lazy(q, v, tau):
        return deferred(constrained_dynamics_derivatives, locals())
    what = "constrained_dynamics_derivatives"
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    if check_finite:
        for name, arr in x.items():
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{what}: {name} contains NaN or Inf")
    Q, V, TAU = x["q"], x["v"], x["tau"]  # (n,) for one state (the kernels' single-state paths), else (B, n)
    B, nv, nb = _inputs.as_batch(Q).shape[0], model.nv, model.nbodies
    res = constrained_dynamics(model, Q, V, TAU, constraints, (alpha, beta), rcond=rcond, friction=friction,
                               armature=armature, check_finite=False)
    A, rank = res.a, np.atleast_1d(res.rank)
    m = sum(c.dim for c in constraints)
    if np.any(rank < m):
        raise ValueError(f"{what}: the constraints are redundant (rank {int(rank.min())} < {m} rows): the "
                         "constraint forces are not unique and have no derivative; remove the redundant rows "
                         "(e.g. close a planar loop with a 1-dof CouplingConstraint or fewer rows)")
    W, extra = np.zeros((B, nb, 6)), np.zeros((B, nv, nv))
    rows = []
    for c, lam in zip(constraints, res.forces):
        J, cq, cv, forces, more = _rows(c, model, Q, V, A, lam.reshape(B, c.dim), alpha, beta)
        rows.append((J, cq, cv))
        if more is not None:
            extra += more
        for p, f, n in forces:
            if p.body < 0:
                continue
            W[:, p.body, :3] += f
            W[:, p.body, 3:] += np.cross(p.x, f) + (0.0 if n is None else n)
            extra += np.swapaxes(p.Jw, 1, 2) @ _xc(f, p.Jx)  # the point of application moves
    dID_dq, dID_dv, M = (d.reshape(B, nv, nv) for d in rnea_derivatives(
        model, Q, V, A, f_ext=W.reshape(W.shape[1:]) if Q.ndim == 1 else W, frame="world", friction=friction,
        armature=armature, check_finite=False))
    dID_dq = dID_dq + extra
    # [[M, J^T], [J, 0]] [da; -dl] = [r1; r2] for x = (q, v, tau): r1 = (-dID_dq, -dID_dv, I), r2 = (-cq, -cv, 0)
    r1 = np.concatenate([-dID_dq, -dID_dv, np.broadcast_to(np.eye(nv), (B, nv, nv))], axis=2)
    L = cholesky(M, what)
    LT = np.swapaxes(L, 1, 2)
    Minv_r1 = np.linalg.solve(LT, np.linalg.solve(L, r1))
    if m:
        J, cq, cv = (np.concatenate([r[k] for r in rows], axis=1) for k in range(3))
        r2 = np.concatenate([-cq, -cv, np.zeros((B, m, nv))], axis=2)
        Y = np.linalg.solve(LT, np.linalg.solve(L, np.swapaxes(J, 1, 2)))  # M^-1 J^T (B, nv, m)
        dl = np.linalg.solve(J @ Y, r2 - J @ Minv_r1)
        da = Minv_r1 + Y @ dl
    else:
        dl, da = np.zeros((B, 0, 3 * nv)), Minv_r1
    parts = [da[..., :nv], da[..., nv:2 * nv], da[..., 2 * nv:], dl[..., :nv], dl[..., nv:2 * nv], dl[..., 2 * nv:]]
    return ConstrainedDynamicsDerivatives(*(np.ascontiguousarray(p[0]) if batch == () else
                                            p.reshape(batch + p.shape[1:]) for p in parts))
