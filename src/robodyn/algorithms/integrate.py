"""Motion on the configuration manifold: ``q ⊕ v`` and its inverse ``q1 ⊖ q0``.

Configurations of 1-dof joints add: ``q_i + v_i``. A free joint's configuration is a pose
``(p, R)`` (``q = [p, quaternion (x, y, z, w)]``) and its velocity a twist ``[v_lin, omega]``
in the child (base) frame; it moves by the exponential map of SE(3), as Pinocchio does (a
spherical joint, ``q = quaternion``, ``v = omega``, by its rotation part, that of SO(3); a
planar joint, ``q = [x, y, cos t, sin t]``, ``v = [vx, vy, wz]``, by that of SE(2))::

    integrate:   (p, R) ⊕ xi = (p, R) exp(xi),      exp(xi) = (V(omega) v_lin, exp3(omega))
    difference:  q1 ⊖ q0 = log((p0, R0)^-1 (p1, R1))

with ``V(w) = I + (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2``, ``t = |w|``. So
``integrate(q, v * dt)`` follows the motion of constant body twist ``v`` for a time ``dt``
exactly, and ``difference(q0, integrate(q0, d)) == d`` (rotations below pi).

Reference: Lynch and Park, *Modern Robotics* (2017), sections 3.2.3 and 3.3.3 (exponential
coordinates of SO(3) and SE(3)); Pinocchio's ``integrate`` / ``difference``.
"""

from __future__ import annotations

import numpy as np

from .. import joints as J
from ..lie import exp_se3, inverse_adjoint, log_se3, quat_matrix, quat_mul, right_jacobian_se3
from ..coupling import expand_q, expand_v, is_coupled, reduce_q
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import require_finite_result


# The components of an SE(3) twist ``[v_lin, omega]`` a joint of several dofs moves along: a
# spherical joint is a free joint without translation, a planar joint one restricted to the
# x-y plane and rotations about z (the subgroups' exponentials, logarithms and Jacobians are
# those of SE(3) restricted to them).
TWIST_COMPONENTS = {J.FREE: [0, 1, 2, 3, 4, 5], J.SPHERICAL: [3, 4, 5], J.PLANAR: [0, 1, 5]}


def _free_blocks(model):
    """``(q index, v index, joint type)`` of each free, spherical and planar joint."""
    for i in np.flatnonzero(J.NQ[model.joint_type] > 1):
        yield int(model.idx_q[i]), int(model.idx_v[i]), int(model.joint_type[i])


def joint_pose(q, kq, kind):
    """``(position (..., 3), quaternion (..., 4))`` of the joint at ``kq``."""
    if kind == J.FREE:
        return q[..., kq:kq + 3], q[..., kq + 3:kq + 7]
    zero = np.zeros(q.shape[:-1] + (3,))
    if kind == J.SPHERICAL:
        return zero, q[..., kq:kq + 4]
    half = 0.5 * np.arctan2(q[..., kq + 3], q[..., kq + 2])  # planar: (x, y, 0), a rotation about z
    p = zero.copy()
    p[..., :2] = q[..., kq:kq + 2]
    quat = np.stack([np.zeros_like(half), np.zeros_like(half), np.sin(half), np.cos(half)], -1)
    return p, quat


def set_joint_pose(out, kq, kind, p, quat) -> None:
    """Write a joint's pose into its ``q`` (a planar joint keeps x, y and the angle about z)."""
    if kind == J.FREE:
        out[..., kq:kq + 3], out[..., kq + 3:kq + 7] = p, quat
    elif kind == J.SPHERICAL:
        out[..., kq:kq + 4] = quat
    else:
        angle = 2.0 * np.arctan2(quat[..., 2], quat[..., 3])
        out[..., kq:kq + 2], out[..., kq + 2], out[..., kq + 3] = p[..., :2], np.cos(angle), np.sin(angle)


def joint_twist(v, kv, kind):
    """The joint's velocity as an SE(3) twist (..., 6) ``[v_lin, omega]``."""
    sel = TWIST_COMPONENTS[kind]
    xi = np.zeros(v.shape[:-1] + (6,))
    xi[..., sel] = v[..., kv:kv + len(sel)]
    return xi


def _scalar_indices(model):
    one = J.NQ[model.joint_type] == 1
    return model.idx_q[one], model.idx_v[one]


def integrate(model, q, v, *, check_finite: bool = True) -> np.ndarray:
    """The configuration reached from ``q`` by the velocity increment ``v`` (e.g. ``v dt``).

    ``q ⊕ v``: 1-dof joints ``q_i + v_i``; a free joint ``(p, R) exp([v_lin, omega])`` with
    the twist in the base frame (see the module docstring).

    Args:
        q: (..., nq) configuration (unit quaternions for free joints). v: (..., nv).

    Returns:
        (..., nq), unit quaternions of the sign nearer ``q``'s (``q_quat . out_quat >= 0``).
        Equals Pinocchio's ``integrate(model, q, v)``; ``difference(model, q, integrate(model,
        q, v)) == v`` for rotations below pi.
    Reference: Lynch and Park, *Modern Robotics*, eq. (3.88).
    """
    if any_lazy(q, v):
        return deferred(integrate, locals())
    if is_coupled(model):  # the independent coordinates of E(q) (+) G v
        return reduce_q(model, integrate(model.full, expand_q(model, q), expand_v(model, v), check_finite=check_finite))
    batch, x = _inputs.states(model, q=q, v=v)
    q, v = x["q"], x["v"]
    check_configurations(model, check_finite, "integrate", q=q, v=v)
    out = q.copy()
    iq, iv = _scalar_indices(model)
    out[..., iq] += v[..., iv]
    for kq, kv, kind in _free_blocks(model):
        p0, quat0 = joint_pose(q, kq, kind)
        quat0 = quat0 / np.linalg.norm(quat0, axis=-1, keepdims=True)
        dquat, dp = exp_se3(joint_twist(v, kv, kind))
        quat = quat_mul(quat0, dquat)
        quat *= np.where(np.sum(quat * quat0, -1, keepdims=True) < 0, -1.0, 1.0)  # the sign nearer q's
        quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
        set_joint_pose(out, kq, kind, p0 + np.einsum("...ij,...j->...i", quat_matrix(quat0), dp), quat)
    require_finite_result("integrate", out, check_finite, {"q": q, "v": v})
    return _inputs.unflatten(out, batch)


def difference(model, q0, q1, *, check_finite: bool = True) -> np.ndarray:
    """The velocity increment ``d`` (..., nv) with ``integrate(model, q0, d) == q1``.

    ``q1 ⊖ q0``: 1-dof joints ``q1_i - q0_i``; a free joint ``log((p0, R0)^-1 (p1, R1))``
    in the frame of ``q0``'s base, rotation part of norm at most pi. Equals Pinocchio's
    ``difference(model, q0, q1)``. Reference: Lynch and Park, *Modern Robotics*, sec. 3.3.3.
    """
    if any_lazy(q0, q1):
        return deferred(difference, locals())
    if is_coupled(model):  # a mimic dof's difference is its source's times the multiplier
        d = difference(model.full, expand_q(model, q0), expand_q(model, q1), check_finite=check_finite)
        return d[..., model.independent_v]
    return _difference(model, q0, q1, check_finite, "difference")


def _difference(model, q0, q1, check_finite: bool, what: str) -> np.ndarray:
    """:func:`difference`, its errors starting with ``what``."""
    q0, q1 = (_as_configuration(model, name, a) for name, a in (("q0", q0), ("q1", q1)))
    try:
        q0, q1 = np.broadcast_arrays(q0, q1)
    except ValueError:
        raise ValueError(f"{what}: shapes of q0 {q0.shape} and q1 {q1.shape} do not broadcast") from None
    check_configurations(model, check_finite, what, q0=q0, q1=q1)
    lead = q0.shape[:-1]
    d = np.zeros(lead + (model.nv,))
    iq, iv = _scalar_indices(model)
    d[..., iv] = q1[..., iq] - q0[..., iq]
    for kq, kv, kind in _free_blocks(model):
        (p0, quat0), (p1, quat1) = joint_pose(q0, kq, kind), joint_pose(q1, kq, kind)
        quat0 = quat0 / np.linalg.norm(quat0, axis=-1, keepdims=True)
        conj0 = quat0 * np.array([-1.0, -1.0, -1.0, 1.0])
        dp = np.einsum("...ji,...j->...i", quat_matrix(quat0), p1 - p0)
        sel = TWIST_COMPONENTS[kind]
        d[..., kv:kv + len(sel)] = log_se3(quat_mul(conj0, quat1), dp)[..., sel]
    return require_finite_result(what, d, check_finite, {"q0": q0, "q1": q1})


def integrate_jacobians(model, q, v, *, check_finite: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of ``q ⊕ v`` (:func:`integrate`) in tangent coordinates: ``(J_q, J_v)``, each
    (..., nv, nv), with ``integrate(q ⊕ dq, v + dv) = integrate(q, v) ⊕ (J_q dq + J_v dv)`` to
    first order (Pinocchio's ``dIntegrate``, arguments 0 and 1).

    1-dof joints: identity blocks. A free joint: ``J_q = Ad(exp(v))^-1``, ``J_v = Jr(v)``, the
    right Jacobian of SE(3) (:func:`robodyn.lie.right_jacobian_se3`). Reference: Sola, Deray
    and Atchuthan, "A micro Lie theory for state estimation in robotics" (2018), eqs. (68)-(69).
    """
    if any_lazy(q, v):
        return deferred(integrate_jacobians, locals())
    if is_coupled(model):  # mimic dofs are scalar: their blocks are identities, the rest as the full tree's
        return _independent_blocks(model, integrate_jacobians(model.full, expand_q(model, q), expand_v(model, v),
                                                              check_finite=check_finite))
    batch, x = _inputs.states(model, q=q, v=v)
    q, v = x["q"], x["v"]
    check_configurations(model, check_finite, "integrate_jacobians", q=q, v=v)
    Jq = np.broadcast_to(np.eye(model.nv), q.shape[:-1] + (model.nv, model.nv)).copy()
    Jv = Jq.copy()
    for _, kv, kind in _free_blocks(model):
        xi = joint_twist(v, kv, kind)
        quat, p = exp_se3(xi)
        sel, block = TWIST_COMPONENTS[kind], slice(kv, kv + len(TWIST_COMPONENTS[kind]))
        Jq[..., block, block] = inverse_adjoint(quat, p)[..., sel, :][..., sel]
        Jv[..., block, block] = right_jacobian_se3(xi)[..., sel, :][..., sel]
    return _inputs.unflatten(Jq, batch), _inputs.unflatten(Jv, batch)


def difference_jacobians(model, q0, q1, *, check_finite: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of ``d = q1 ⊖ q0`` (:func:`difference`) in tangent coordinates: ``(J_0, J_1)``,
    each (..., nv, nv), with ``(q1 ⊕ d1) ⊖ (q0 ⊕ d0) = d + J_0 d0 + J_1 d1`` to first order
    (Pinocchio's ``dDifference``, arguments 0 and 1).

    1-dof joints: ``-1`` and ``1``. A free joint: ``J_1 = Jr(d)^-1`` and ``J_0 = -Jr(-d)^-1``
    (the inverse left Jacobian). Reference: Sola et al. (2018), eqs. (75)-(76) and (79).
    """
    if any_lazy(q0, q1):
        return deferred(difference_jacobians, locals())
    if is_coupled(model):
        return _independent_blocks(model, difference_jacobians(model.full, expand_q(model, q0), expand_q(model, q1),
                                                               check_finite=check_finite))
    d = _difference(model, q0, q1, check_finite, "difference_jacobians")
    J1 = np.broadcast_to(np.eye(model.nv), d.shape[:-1] + (model.nv, model.nv)).copy()
    J0 = -J1
    for _, kv, kind in _free_blocks(model):
        xi = joint_twist(d, kv, kind)
        sel, block = TWIST_COMPONENTS[kind], slice(kv, kv + len(TWIST_COMPONENTS[kind]))
        J1[..., block, block] = np.linalg.inv(right_jacobian_se3(xi)[..., sel, :][..., sel])
        J0[..., block, block] = -np.linalg.inv(right_jacobian_se3(-xi)[..., sel, :][..., sel])
    return J0, J1


def _independent_blocks(model, matrices):
    """The rows and columns of the independent dofs of a coupled model's full-tree matrices."""
    k = model.independent_v
    return tuple(np.ascontiguousarray(m[..., k, :][..., :, k]) for m in matrices)


def _as_configuration(model, name: str, a) -> np.ndarray:
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(a).__name__}") from None
    if a.ndim == 0 or a.shape[-1] != model.nq:
        raise ValueError(f"{name}: expected shape (..., {model.nq}), got {a.shape}")
    return a


def check_configurations(model, check_finite: bool, what: str, **arrays) -> None:
    """NaN/Inf in any of ``arrays`` (by name, when ``check_finite``) and the unit norm of the
    free and spherical joints' quaternions in those of the configuration's size; errors start with ``what``."""
    if check_finite:
        for name, a in arrays.items():
            if not np.all(np.isfinite(a)):
                idx = tuple(np.argwhere(~np.isfinite(a))[0].tolist())
                raise ValueError(f"{what}: {name} contains NaN or Inf (first at index {idx})")
    for name, a in arrays.items():
        if a.shape[-1] != model.nq:
            continue
        for kq, _, kind in _free_blocks(model):
            k, size = kq + J.UNIT_OFFSET[kind], J.UNIT_SIZE[kind]
            n = np.linalg.norm(a[..., k:k + size], axis=-1)
            unit = "quaternion" if size == 4 else "(cos, sin)"
            if np.any(~(np.abs(n - 1.0) <= J.QUAT_TOL)):
                raise ValueError(f"{what}: {name}: {unit} {name}[{k}:{k + size}] has norm "
                                 f"{float(np.ravel(n)[np.argmax(np.ravel(np.abs(n - 1.0)))]):.6g}, not 1; normalise it")
