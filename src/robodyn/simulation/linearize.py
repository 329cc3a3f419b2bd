"""Linearisation of one simulation step: the discrete-time ``x+ = f(x, u)`` of :func:`simulate`.

The state ``x = (q, v)`` is perturbed in tangent coordinates, ``q ⊕ dq`` (:func:`robodyn.integrate`,
a body twist for a free joint) and ``v + dv``; the next state's perturbation is measured the same
way at ``x+``. The input ``u`` is the joint force held over the step (clipped to the model's
effort limits, as :func:`simulate` does). With ``Aq, Av, Bu`` the derivatives of the
acceleration (:func:`robodyn.aba_derivatives`, ``Bu = M^-1`` on the joints below their limit):

* ``"semi_implicit_euler"``: ``v+ = v + dt a(q, v, u)``, ``q+ = q ⊞ dt v+`` (the simulator's
  chart: ``q + dt v+`` for 1-dof joints; a free joint's position ``p + dt R v_lin+`` and
  orientation ``R exp(dt w+)``), so::

      dv+ = dt Aq dq + (1 + dt Av) dv + dt Bu du,     dq+ = Gq dq + Gv dv+

  with ``Gq = 1``, ``Gv = dt 1`` for 1-dof joints and, for a free joint (``E = exp(dt w+)``,
  ``Jr`` the right Jacobian of SO(3))::

      Gq = [[E^T, -dt E^T [v_lin+]x], [0, E^T]],     Gv = [[dt E^T, 0], [0, dt Jr(dt w+)]]

* ``"rk4"``: the classic Runge-Kutta method on ``(q, v)`` (models whose joints all have one
  dof, where the chart is ``q + theta``): each stage's Jacobian ``K_j = F_j (1 + c_j dt K_{j-1})``
  with ``F_j = [[0, 1], [Aq_j, Av_j]]`` at the stage's state, and ``A = 1 + dt/6 (K_1 + 2 K_2
  + 2 K_3 + K_4)`` (likewise for ``B``).

Both are exact derivatives of the step :func:`simulate` takes (not of the continuous dynamics).
Reference: Hairer, Lubich, Wanner, *Geometric Numerical Integration* (2006), IV.8; the right
Jacobian of SO(3): Barfoot, *State Estimation for Robotics* (2017), section 7.1.5.
"""

from __future__ import annotations

import numpy as np

from .. import joints as J
from ..lie import exp_so3, right_jacobian_so3, skew
from .simulate import INTEGRATORS


def _acceleration_derivatives(model, q, v, tau):
    """``(a, Aq, Av, Bu)``: the simulator's acceleration for the command ``tau`` clipped to the
    effort limits and its derivatives (``Bu``'s columns are zero for the clipped joints)."""
    from ..algorithms.aba import aba
    from ..algorithms.aba_derivatives import aba_derivatives

    tau = np.asarray(tau, dtype=float)
    if tau.shape[-1:] != (model.nv,):
        raise ValueError(f"tau: expected shape (..., {model.nv}), got {tau.shape}")
    limit = model.effort_limit
    clipped = np.clip(tau, -limit, limit)
    Aq, Av, Minv = aba_derivatives(model, q, v, clipped)
    return aba(model, q, v, clipped), Aq, Av, Minv * (np.abs(tau) <= limit)[..., None, :]


def linearize(model, q, v, tau, dt: float, integrator: str = "semi_implicit_euler") -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of one step ``x+ = f(x, u)`` of :func:`simulate` from ``x = (q, v)`` under the
    joint force ``u = tau`` held for ``dt``, in tangent coordinates (see the module docstring).

    Args:
        q: (..., nq). v, tau: (..., nv). dt: the step, seconds (> 0).
        integrator: ``"semi_implicit_euler"`` or ``"rk4"`` (joints of one dof only: no free joint).

    Returns:
        ``A`` (..., 2 nv, 2 nv) and ``B`` (..., 2 nv, nv), acting on ``[dq; dv]`` and ``du``.

    Equivalence: ``[difference(q+, q+'); v+' - v+] = A [dq; dv] + B du`` to first order, where
    ``(q+', v+')`` is the step from ``(integrate(q, dq), v + dv)`` under ``tau + du``.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator: unknown {integrator!r}; choose one of {INTEGRATORS}")
    if not (isinstance(dt, (int, float, np.floating, np.integer)) and np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt: expected a positive number of seconds, got {dt!r}")
    dt = float(dt)
    free = np.flatnonzero(model.joint_type == J.FREE)
    if integrator == "rk4":
        if free.size:
            raise ValueError(f"linearize: integrator 'rk4' needs joints of one dof; {model.body_joint_names[free[0]]!r} "
                             "is a free joint (use integrator='semi_implicit_euler')")
        return _rk4(model, q, v, tau, dt)
    return _semi_implicit_euler(model, q, v, tau, dt, free)


def _assemble(Aq, Av, Bu, Gq, Gv, dt):
    """``A``, ``B`` of ``dv+ = dt Aq dq + (1 + dt Av) dv + dt Bu du``, ``dq+ = Gq dq + Gv dv+``."""
    n = Aq.shape[-1]
    eye = np.eye(n)
    Vq, Vv, Vu = dt * Aq, eye + dt * Av, dt * Bu
    A = np.concatenate([np.concatenate([Gq + Gv @ Vq, Gv @ Vv], -1), np.concatenate([Vq, Vv], -1)], -2)
    return A, np.concatenate([Gv @ Vu, Vu], -2)


def _semi_implicit_euler(model, q, v, tau, dt, free):
    a, Aq, Av, Bu = _acceleration_derivatives(model, q, v, tau)
    n = model.nv
    v_next = np.asarray(v, dtype=float) + dt * a
    Gq = np.broadcast_to(np.eye(n), Aq.shape).copy()
    Gv = dt * Gq
    for i in free:
        k = model.idx_v[i]
        lin, ang = slice(k, k + 3), slice(k + 3, k + 6)
        E, Jr = exp_so3(dt * v_next[..., ang]), right_jacobian_so3(dt * v_next[..., ang])
        Et = np.swapaxes(E, -1, -2)
        Gq[..., lin, lin] = Et
        Gq[..., lin, ang] = -dt * Et @ skew(v_next[..., lin])
        Gq[..., ang, ang] = Et
        Gv[..., lin, lin] = dt * Et
        Gv[..., ang, ang] = dt * Jr
    return _assemble(Aq, Av, Bu, Gq, Gv, dt)


def _rk4(model, q, v, tau, dt):
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    n = model.nv
    eye = np.eye(n)
    zero = np.zeros(np.broadcast_shapes(q.shape[:-1], v.shape[:-1], np.shape(tau)[:-1]) + (n, n))
    Kx, Ku = [], []
    dq, dv = np.zeros_like(q), np.zeros_like(v)
    Px, Pu = None, None  # the previous stage's Jacobians
    for c in (0.0, 0.5, 0.5, 1.0):
        qs, vs = q + c * dt * dq, v + c * dt * dv
        a, Aq, Av, Bu = _acceleration_derivatives(model, qs, vs, tau)
        F = np.concatenate([np.concatenate([zero, zero + eye], -1), np.concatenate([Aq, Av], -1)], -2)
        Fu = np.concatenate([zero, Bu], -2)
        if Px is None:
            kx, ku = F, Fu
        else:
            kx = F + c * dt * F @ Px
            ku = Fu + c * dt * F @ Pu
        Kx.append(kx)
        Ku.append(ku)
        Px, Pu, dq, dv = kx, ku, vs, a
    w = (1.0, 2.0, 2.0, 1.0)
    A = np.eye(2 * n) + dt / 6.0 * sum(wi * k for wi, k in zip(w, Kx))
    B = dt / 6.0 * sum(wi * k for wi, k in zip(w, Ku))
    return A, B
