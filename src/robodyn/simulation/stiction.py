"""Exact stiction: joint friction as a set-valued force in the time stepping, so that a joint
comes to rest and stays there (``v = 0`` exactly) while the torque on it stays below its
breakaway level, with no smoothing and no chattering.

The dry friction of dof ``k`` is ``f_k = F_k(v_k) sgn(v_k)`` when the joint slides and any
``|f_k| <= F_k`` when it sticks, with the Coulomb level and Stribeck effect of the model
(``F(v) = coulomb + stribeck exp(-(v / v_s)^2)``, the breakaway torque ``F(0)`` at rest:
:func:`robodyn.joint_kernels.coulomb_level`). Semi-implicit Euler with the friction implicit
in the new velocity (Moreau's time stepping; Stewart, "Rigid-body dynamics with friction and
impact", SIAM Review 42(1), 2000):

    v_free = v + dt a_0(q, v)            (a_0: aba without the dry friction; viscous, springs in)
    v+     = v_free - dt M(q)^-1 f,      v+_k > 0 => f_k = F_k,   v+_k < 0 => f_k = -F_k,
                                         v+_k = 0 => |f_k| <= F_k
    q+     = q ⊞ dt v+

with ``F_k`` taken at the step's starting velocity. The friction ``f`` solves the box
complementarity problem of the (positive definite) Delassus matrix ``G = dt M^-1`` restricted
to the dofs with dry friction: ``min 1/2 f^T G f - f^T v_free`` over ``|f| <= F``, solved by
a primal-dual active set method (Hintermüller, Ito & Kunisch, SIAM J. Optim. 13(3), 2002),
exact once the sets are right, with projected Gauss-Seidel as the fallback.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from ..algorithms.minv import inverse_mass_matrix
from ..errors import RobodynWarning, user_stacklevel

MAX_ACTIVE_SET = 50
MAX_SWEEPS = 2000


class BoxFriction(NamedTuple):
    """``f`` (m,) the friction torques, ``residual`` the largest violation of the
    complementarity conditions (rad/s), ``iterations`` the active-set steps (or Gauss-Seidel
    sweeps when it fell back to them)."""
    f: np.ndarray
    residual: float
    iterations: int


def complementarity_residual(G, b, bound, f) -> float:
    """The largest violation (velocity units) of ``v = b - G f``: ``v_k <= 0`` where ``f_k``
    sits at ``-bound``, ``>= 0`` at ``+bound``, ``= 0`` inside, and of ``|f| <= bound``."""
    v = b - G @ f
    scale = np.diag(G)
    lower, upper = f <= -bound, f >= bound
    violation = np.where(lower, np.maximum(v, 0.0), np.where(upper, np.maximum(-v, 0.0), np.abs(v)))
    outside = np.maximum(np.abs(f) - bound, 0.0) * scale
    return float(np.max(violation + outside, initial=0.0))


def box_friction(G, b, bound, f0=None, tolerance: float = 1e-12) -> BoxFriction:
    """The friction ``f`` (m,) with ``|f| <= bound`` complementary to ``v = b - G f``
    (module docstring). ``G`` (m, m) symmetric positive definite, ``b`` (m,) the free
    velocities, ``bound`` (m,) >= 0, ``f0`` a warm start (the previous step's friction)."""
    m = b.shape[0]
    f = np.zeros(m) if f0 is None else np.clip(f0, -bound, bound)
    c = 1.0 / np.diag(G)
    scale = tolerance * max(1.0, float(np.max(np.abs(b), initial=0.0)))
    previous = None
    for it in range(1, MAX_ACTIVE_SET + 1):
        y = f + c * (b - G @ f)  # the multiplier test: where the unconstrained step would go
        sets = (y >= bound).astype(np.int8) - (y <= -bound).astype(np.int8)
        if previous is not None and np.array_equal(sets, previous):
            break
        previous = sets
        free = sets == 0
        f = np.where(sets > 0, bound, np.where(sets < 0, -bound, 0.0))
        if free.any():
            rhs = b[free] - G[np.ix_(free, ~free)] @ f[~free]
            f[free] = np.linalg.solve(G[np.ix_(free, free)], rhs)
    residual = complementarity_residual(G, b, bound, f)
    if residual <= scale and np.all(np.abs(f) <= bound):
        return BoxFriction(f, residual, it)
    f = np.clip(f, -bound, bound)
    for sweep in range(1, MAX_SWEEPS + 1):  # projected Gauss-Seidel, monotone for G > 0
        for k in range(m):
            f[k] = min(bound[k], max(-bound[k], f[k] + c[k] * (b[k] - G[k] @ f)))
        if sweep % 10 == 0:
            residual = complementarity_residual(G, b, bound, f)
            if residual <= scale:
                break
    return BoxFriction(f, complementarity_residual(G, b, bound, f), it + sweep)


def friction_bound(model, v) -> np.ndarray:
    """``F_k(v_k) = coulomb_k + stribeck_k exp(-(v_k / v_s,k)^2)`` (nv,): the dry friction
    level of every dof at velocity ``v`` (the breakaway torque at rest)."""
    vs = model.stribeck_velocity
    x = np.divide(v, vs, out=np.zeros_like(v), where=vs > 0)
    return model.coulomb + model.stribeck * np.exp(-x * x)


def run_stiction(model, plant, law, q0, v0, dt, t, Q, V, Z, A, T, bar, warn_above: float = 1e-9, coupling=None):
    """Semi-implicit Euler with exact stiction (module docstring). ``plant`` steps the model
    without its dry friction (``coulomb`` and ``stribeck`` zero); ``model`` holds them.
    Returns ``(friction, residual)``: the friction torques (N, nv) over each step and the
    solves' complementarity residuals (N,). Warns when a solve stopped above ``warn_above``
    (rad/s).

    With ``coupling`` (a :class:`~robodyn.coupling.CoupledModel` whose ``full`` is ``model``,
    stepped by ``plant`` under its couplings) the friction is solved in the independent
    coordinates: a dof ``k`` of the tree moves as ``E[k, i] v_i`` with one independent
    coordinate ``i``, so the dry friction the tree's dofs put on ``i`` is any torque of
    magnitude up to ``sum_k |E[k, i]| F_k(v_k)`` (the box of each independent coordinate),
    with the coupled model's ``M^-1``; ``friction`` holds it in the columns of the independent
    dofs. (``E`` is the coupling's ``G``; here ``G`` names the Delassus matrix.)"""
    nv, nz = V.shape[1], Z.shape[1]
    n = Q.shape[0] - 1
    zero, thetadot, vdot = np.zeros(nv), np.empty(nv), np.empty(nv)
    E = np.eye(nv) if coupling is None else coupling.G  # v = E v_r
    dry = np.flatnonzero(np.abs(E).T @ ((model.coulomb > 0) | (model.stribeck > 0)))
    columns = dry if coupling is None else coupling.independent_v[dry]
    friction, residual = np.zeros((n + 1, nv)), np.zeros(n + 1)
    zdot = np.empty(nz)
    Q[0], V[0] = q0, v0
    every = max(1, n // 100)
    f_dry = np.zeros(dry.size)
    for s in range(n + 1):
        q, v, z = Q[s], V[s], Z[s]
        plant.derivative(t[s], q, zero, v, law, z, T[s], thetadot, vdot, zdot)
        v_free = v + dt * vdot
        v_next = v_free.copy()
        if dry.size:
            if coupling is None:
                Minv, v_free_r = inverse_mass_matrix(model, q), v_free
            else:
                Minv = inverse_mass_matrix(coupling, q[coupling.independent_q])
                v_free_r = v_free[coupling.independent_v]
            W = dt * Minv[np.ix_(dry, dry)]
            bound = (np.abs(E).T @ friction_bound(model, v))[dry]
            sol = box_friction(W, v_free_r[dry], bound, f_dry)
            f_dry, residual[s] = sol.f, sol.residual
            friction[s, columns] = f_dry
            v_next_r = v_free_r - dt * (Minv[:, dry] @ f_dry)
            stuck = np.abs(f_dry) < bound
            v_next_r[dry[stuck]] = 0.0  # at rest exactly (the solve leaves rounding there)
            v_next = E @ v_next_r
        A[s] = (v_next - v) / dt
        if s == n:
            break
        V[s + 1] = v_next
        Z[s + 1] = z + dt * zdot
        plant.rate(q, zero, v_next, thetadot)
        plant.point(q, dt * thetadot, Q[s + 1])
        if s % every == 0:
            bar.update(s)
    bad = residual > warn_above
    if np.any(bad):
        warnings.warn(f"simulate: the joint friction solve stopped above {warn_above:g} rad/s in {int(bad.sum())} of "
                      f"{n + 1} steps (largest {residual.max():.3g} rad/s, first at t = {t[np.argmax(bad)]:.6g})",
                      RobodynWarning, stacklevel=user_stacklevel())
    return friction, residual
