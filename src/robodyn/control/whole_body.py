"""Whole-body inverse dynamics with contacts: the joint torques and contact forces that
realise desired accelerations of a floating-base robot standing on its contacts.

With ``b = rnea(q, v, a)`` (``M a + C v + g`` and the joints' friction), point contacts at
frames ``c`` with world-axes forces ``f_c`` and linear Jacobians ``J_c`` (3, nv) at their
origins, and ``S`` selecting the actuated dofs (all but a floating base's six):

    b = S^T tau + sum_c J_c^T f_c                       (the equation of motion)

The six base rows fix the contact forces up to the null space of the contact Jacobians; the
actuated rows then give ``tau = (b - sum J_c^T f_c)_actuated``. Among the admissible forces
(friction cones ``|f_t| <= mu f_n``, ``f_n >= 0`` about each contact's normal, torque limits
``|tau| <= effort_limit``) the quadratic program

    minimise  |tau|^2 + w |f|^2      subject to the equation of motion and the constraints

picks the one with the smallest torques (``w`` a small weight that spreads the load). Solved
by SciPy's SLSQP (a small dense QP: 3 variables per contact); a problem without an admissible
solution (accelerations the contacts cannot produce, friction too low, torque limits) raises
``ValueError`` naming what is violated. Reference: Herzog et al., "Momentum control with
hierarchical inverse dynamics on a torque-controlled humanoid", Autonomous Robots 40 (2016);
Wensing and Orin (2013).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import joints as J
from ..algorithms.jacobian import jacobian
from ..algorithms.rnea import rnea


class WholeBodyID(NamedTuple):
    """``tau`` (nv,) the joint forces (zero on the unactuated base dofs); ``forces`` (k, 3) the
    contact forces in world axes; ``residual``: the largest violation of the equation of
    motion (N or N m)."""
    tau: np.ndarray
    forces: np.ndarray
    residual: float


def actuated_dofs(model) -> np.ndarray:
    """The dofs a motor drives: every dof except those of free joints (a floating base)."""
    free = np.zeros(model.nv, dtype=bool)
    for i in np.flatnonzero(model.joint_type == J.FREE):
        free[model.idx_v[i]:model.idx_v[i] + 6] = True
    return np.flatnonzero(~free)


def whole_body_inverse_dynamics(model, q, v, a, contacts, *, mu=1.0, normal=(0.0, 0.0, 1.0),
                                force_weight: float = 1e-4, tol: float = 1e-6) -> WholeBodyID:
    """Torques and contact forces for the accelerations ``a`` (module docstring).

    Args:
        q: (nq,), v, a: (nv,) one state and the desired accelerations.
        contacts: link or frame names whose origins touch the world (point contacts).
        mu: friction coefficient, a number or one per contact. normal: the contact normal in
            world axes (one for all, or (k, 3)), unit.
        force_weight: ``w``, the weight of the contact forces' squares against the torques'.
        tol: the violations accepted, relative to the largest joint force ``|b|``: of the base
            rows of the equation of motion, of the cones (``f_n >= 0``, ``|f_t| <= mu f_n``)
            and of the torque limits.
    """
    from scipy.optimize import minimize

    contacts = list(contacts)
    k = len(contacts)
    if k == 0:
        raise ValueError("contacts: at least one contact")
    q, v, a = (np.asarray(x, dtype=float) for x in (q, v, a))
    b = rnea(model, q, v, a)
    Jc = np.concatenate([jacobian(model, q, c, "local_world_aligned")[:3] for c in contacts])  # (3k, nv)
    act = actuated_dofs(model)
    base = np.setdiff1d(np.arange(model.nv), act)
    mu = np.broadcast_to(np.asarray(mu, dtype=float), (k,))
    n = np.broadcast_to(np.asarray(normal, dtype=float), (k, 3))
    if np.any(mu < 0) or not np.all(np.isfinite(mu)):
        raise ValueError(f"mu: expected numbers >= 0, got {mu.tolist()}")
    if not np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-9):
        raise ValueError("normal: expected unit vectors")
    limit = model.effort_limit[act]

    def torques(f):
        return (b - Jc.T @ f)[act]

    def objective(f):
        tau = torques(f)
        return tau @ tau + force_weight * (f @ f)

    def gradient(f):
        return -2.0 * Jc[:, act] @ torques(f) + 2.0 * force_weight * f

    def cones(f):
        F = f.reshape(k, 3)
        fn = np.einsum("ij,ij->i", F, n)
        ft = F - fn[:, None] * n
        return np.concatenate([fn, (mu * fn) ** 2 - np.einsum("ij,ij->i", ft, ft)])

    constraints = [{"type": "eq", "fun": lambda f: (b - Jc.T @ f)[base], "jac": lambda f: -Jc.T[base]},
                   {"type": "ineq", "fun": cones}]
    finite = np.isfinite(limit)
    if np.any(finite):
        constraints.append({"type": "ineq", "fun": lambda f: np.concatenate([limit - torques(f), limit + torques(f)])[
            np.concatenate([finite, finite])]})
    # start: the least-squares forces of the base rows
    f0 = np.linalg.lstsq(Jc.T[base], b[base], rcond=None)[0] if base.size else np.zeros(3 * k)
    result = minimize(objective, f0, jac=gradient, constraints=constraints, method="SLSQP",
                      options={"maxiter": 500, "ftol": 1e-14})
    f = result.x
    residual = float(np.abs((b - Jc.T @ f)[base]).max()) if base.size else 0.0
    scale = max(1.0, float(np.abs(b).max()))
    violated = []
    if residual > tol * scale:
        violated.append(f"the base's equation of motion (residual {residual:.3g})")
    c = cones(f)
    outside = (c[:k] < -tol * scale) | (c[k:] < -tol * scale ** 2)   # f_n >= 0, (mu f_n)^2 >= |f_t|^2
    if np.any(outside):
        violated.append(f"the friction cones of {[contacts[i] for i in np.flatnonzero(outside)]}")
    tau = np.zeros(model.nv)
    tau[act] = torques(f)
    if np.any(np.abs(tau[act]) > limit * (1 + tol)):
        violated.append("the torque limits")
    if violated:
        raise ValueError(f"whole_body_inverse_dynamics: no admissible contact forces for these accelerations: "
                         f"{'; '.join(violated)} ({result.message})")
    return WholeBodyID(tau, f.reshape(k, 3), residual)
