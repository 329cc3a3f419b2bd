"""Linearisation of one simulation step: the discrete-time ``x+ = f(x, u)`` of :func:`simulate`.

The state ``x = (q, v)`` is perturbed in tangent coordinates, ``q ⊕ dq`` (:func:`robodyn.integrate`,
a body twist for a free joint) and ``v + dv``; the next state's perturbation is measured the same
way at ``x+``. The input ``u`` is the joint force held over the step (clipped to the model's
effort limits, as :func:`simulate` does).

A step of :func:`simulate` integrates in the chart ``q = q0 ⊞ theta`` centred at the step's start
``q0`` (``_kernels.py``): ``q0 + theta`` for 1-dof joints; for a free joint the position
``p0 + theta_p`` and the orientation ``R0 exp(phi)``, with the chart's rate
``k(q0, theta, v) = [R v_lin; Jr(phi)^-1 omega]`` (``R = R0 exp(phi)``, ``Jr`` the right
Jacobian of SO(3), ``Jr^-1 w = w + phi x w / 2 + c(t) phi x (phi x w)``,
``c(t) = (1 - (t / 2) cot(t / 2)) / t^2``, ``t = |phi|``). Its derivatives, for a free joint
(``E = exp(phi)``; 1-dof joints: ``Dq0 = Dth = Kv = 1``, ``Kq = Kth = 0``):

    tangent of q0 ⊞ theta:   Dq0 = d/dq0 = diag(E^T, E^T),   Dth = d/dtheta = diag(R^T, Jr(phi))
    rate:   Kq = d/dq0 = [[0, -R [v_lin]x E^T], [0, 0]],    Kv = d/dv = diag(R, Jr(phi)^-1)
            Kth = d/dtheta = [[0, -R [v_lin]x Jr(phi)], [0, d(Jr(phi)^-1 w)/dphi]]
    d(Jr^-1 w)/dphi = -[w]x / 2 + c ((phi . w) 1 + phi w^T - 2 w phi^T) + (c'/t) (phi x (phi x w)) phi^T

With ``Aq, Av, Bu`` the derivatives of the acceleration (:func:`robodyn.aba_derivatives`,
``Bu = M^-1`` on the joints below their limit), every quantity of the step is differentiated
along ``(dq, dv, du)``:

* ``"semi_implicit_euler"``: ``v+ = v + dt a(q0, v, u)``, ``theta+ = dt k(q0, 0, v+)``;
* ``"rk4"``: stages ``theta_j = c_j dt k_{j-1}``, ``v_j = v + c_j dt a_{j-1}`` (``c = 0, 1/2,
  1/2, 1``) at ``q_j = q0 ⊞ theta_j``, then ``theta+ = dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4)`` and
  ``v+ = v + dt/6 (a_1 + 2 a_2 + 2 a_3 + a_4)``;

and ``dq+ = Dq0(theta+) dq + Dth(theta+) dtheta+``. Both are exact derivatives of the step
:func:`simulate` takes (not of the continuous dynamics). Reference: Hairer, Lubich, Wanner,
*Geometric Numerical Integration* (2006), IV.8 (Runge-Kutta-Munthe-Kaas); Barfoot, *State
Estimation for Robotics* (2017), section 7.1 (the Jacobians of SO(3)).
"""

from __future__ import annotations

import numpy as np

from .. import joints as J
from ..coupling import expand_q, expand_v, is_coupled, joint_tree, reduce_q
from ..algorithms.integrate import TWIST_COMPONENTS, check_configurations, joint_pose, joint_twist, set_joint_pose
from ..lie import exp_se3, exp_so3, inverse_jacobian_coefficients, quat_matrix, quat_mul, right_jacobian_so3, skew
from .simulate import INTEGRATORS


def _acceleration_derivatives(model, q, v, tau):
    """``(a, Aq, Av, Bu)``: the simulator's acceleration for the command ``tau`` clipped to the
    effort limits and its derivatives (``Bu``'s columns are zero for the joints at or beyond
    their limit, whose clipped force does not change with the command: an effort limit of 0
    makes a joint unactuated). The ABA runs again for ``a`` (``aba_derivatives`` computes it
    inside and does not return it)."""
    # imported here: importing the derivative kernels loads (or compiles) them, which
    # `import robodyn.simulation` should not wait for
    from ..algorithms.aba import aba
    from ..algorithms.aba_derivatives import aba_derivatives

    limit = model.effort_limit
    clipped = np.clip(tau, -limit, limit)
    Aq, Av, Minv = aba_derivatives(model, q, v, clipped, check_finite=False)
    return aba(model, q, v, clipped, check_finite=False), Aq, Av, Minv * (np.abs(tau) < limit)[..., None, :]


def _chart(model, q0, theta, v):
    """``(q, k, Dq0, Dth, Kq, Kth, Kv)``: the point ``q = q0 ⊞ theta``, the chart's rate
    ``k(q0, theta, v)`` and their Jacobians (see the module docstring), each (..., nv, nv).
    A model with mimic joints (scalar joints, whose chart is ``q0 + theta``): the full tree's
    chart at ``(E(q0), G theta, G v)`` on the independent coordinates."""
    if is_coupled(model):
        q, k, *D = _chart(model.full, expand_q(model, q0), expand_v(model, theta), expand_v(model, v))
        iv = model.independent_v
        return (reduce_q(model, q), k[..., iv], *(m[..., iv, :][..., :, iv] for m in D))
    n = model.nv
    eye = np.broadcast_to(np.eye(n), theta.shape[:-1] + (n, n))
    Dq0, Dth, Kv = eye.copy(), eye.copy(), eye.copy()
    Kq, Kth = np.zeros_like(Dq0), np.zeros_like(Dq0)
    q, k = q0.copy(), v.copy()
    one = J.NQ[model.joint_type] == 1
    q[..., model.idx_q[one]] += theta[..., model.idx_v[one]]
    lin, ang = slice(0, 3), slice(3, 6)
    for i in np.flatnonzero(~one):
        # free, spherical and planar joints: the free joint's chart in SE(3) coordinates, whose
        # blocks restricted to the joint's twist components are the joint's (the spherical and
        # planar motions are subgroups the chart maps into themselves)
        kind, iq, iv = int(model.joint_type[i]), model.idx_q[i], model.idx_v[i]
        sel = TWIST_COMPONENTS[kind]
        th, vv = joint_twist(theta, iv, kind), joint_twist(v, iv, kind)
        p0, quat0 = joint_pose(q0, iq, kind)
        phi, w, vl = th[..., ang], vv[..., ang], vv[..., lin]
        quat = quat_mul(quat0, exp_se3(np.concatenate([np.zeros_like(phi), phi], -1))[0])
        quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
        set_joint_pose(q, iq, kind, p0 + th[..., lin], quat)
        R, E, Jr = quat_matrix(quat), exp_so3(phi), right_jacobian_so3(phi)
        Et, P, W = np.swapaxes(E, -1, -2), skew(phi), skew(w)
        t = np.linalg.norm(phi, axis=-1)
        c, dc = inverse_jacobian_coefficients(t)
        c, dc = c[..., None, None], dc[..., None, None]
        Jr_inv = np.eye(3) + 0.5 * P + c * (P @ P)
        ppw = (P @ P @ w[..., None])  # phi x (phi x w), (..., 3, 1)
        pw = np.sum(phi * w, -1)[..., None, None]
        RV = R @ skew(vl)
        k6 = np.concatenate([np.einsum("...ij,...j->...i", R, vl), np.einsum("...ij,...j->...i", Jr_inv, w)], -1)
        blocks = [np.zeros(th.shape[:-1] + (6, 6)) for _ in range(5)]  # Dq0, Dth, Kq, Kth, Kv
        D0, Dt, Kq6, Kt6, Kv6 = blocks
        D0[..., lin, lin], D0[..., ang, ang] = Et, Et
        Dt[..., lin, lin], Dt[..., ang, ang] = np.swapaxes(R, -1, -2), Jr
        Kv6[..., lin, lin], Kv6[..., ang, ang] = R, Jr_inv
        Kq6[..., lin, ang] = -RV @ Et
        Kt6[..., lin, ang] = -RV @ Jr
        Kt6[..., ang, ang] = (-0.5 * W + c * (pw * np.eye(3) + phi[..., :, None] * w[..., None, :]
                                              - 2.0 * w[..., :, None] * phi[..., None, :])
                              + dc * ppw * phi[..., None, :])
        block = slice(iv, iv + len(sel))
        k[..., block] = k6[..., sel]
        for M, B in zip((Dq0, Dth, Kq, Kth, Kv), blocks):
            M[..., block, block] = B[..., sel, :][..., sel]
    return q, k, Dq0, Dth, Kq, Kth, Kv


def linearize(model, q, v, tau, dt: float, integrator: str = "rk4") -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of one step ``x+ = f(x, u)`` of :func:`simulate` from ``x = (q, v)`` under the
    joint force ``u = tau`` held for ``dt``, in tangent coordinates (see the module docstring).

    Args:
        q: (..., nq). v, tau: (..., nv). dt: the step, seconds (> 0).
        integrator: ``"rk4"`` (the default, as in :func:`simulate`) or ``"semi_implicit_euler"``.

    Returns:
        ``A`` (..., 2 nv, 2 nv) and ``B`` (..., 2 nv, nv), acting on ``[dq; dv]`` and ``du``.

    Equivalence: ``[difference(q+, q+'); v+' - v+] = A [dq; dv] + B du`` to first order, where
    ``(q+', v+')`` is the step from ``(integrate(q, dq), v + dv)`` under ``tau + du``.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator: unknown {integrator!r}; choose one of {INTEGRATORS}")
    if isinstance(dt, (bool, np.bool_)) or not (isinstance(dt, (int, float, np.floating, np.integer))
                                                 and np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt: expected a positive number of seconds, got {dt!r}")
    arrays = {}
    for name, x, size in (("q", q, model.nq), ("v", v, model.nv), ("tau", tau, model.nv)):
        try:
            x = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None
        if x.ndim == 0 or x.shape[-1] != size:
            raise ValueError(f"{name}: expected shape (..., {size}), got {x.shape}")
        arrays[name] = x
    check_configurations(joint_tree(model), True, "linearize",
                         **{**arrays, "q": expand_q(model, arrays["q"]) if is_coupled(model) else arrays["q"]})
    try:
        batch = np.broadcast_shapes(*(x.shape[:-1] for x in arrays.values()))
    except ValueError:
        raise ValueError("linearize: the batch shapes of q, v and tau do not broadcast: "
                         + ", ".join(f"{k} {x.shape}" for k, x in arrays.items())) from None
    q, v, tau = (np.broadcast_to(x, batch + x.shape[-1:]) for x in arrays.values())
    stages = ((1.0, 0.0),) if integrator == "semi_implicit_euler" else ((1.0, 0.0), (2.0, 0.5), (2.0, 0.5), (1.0, 1.0))
    return _step(model, q, v, tau, float(dt), stages, integrator == "semi_implicit_euler")


def _step(model, q0, v, tau, dt, stages, euler):
    """``(A, B)`` of a step with Runge-Kutta ``stages`` ``(weight, c)`` in the chart at ``q0``
    (the semi-implicit Euler step when ``euler``: one stage, then the chart moves with ``v+``)."""
    n = model.nv
    shape = q0.shape[:-1] + (n, 3 * n)
    Iq, Iv, Iu = (np.zeros(shape) for _ in range(3))
    for block, I in enumerate((Iq, Iv, Iu)):
        I[..., np.arange(n), block * n + np.arange(n)] = 1.0
    theta, dtheta = np.zeros_like(v), np.zeros(shape)
    vs, dvs = v, Iv
    total = sum(w for w, _ in stages)
    k_sum, dk_sum, a_sum, da_sum = 0.0, 0.0, 0.0, 0.0
    k, dk, a, da = None, None, None, None
    for weight, c in stages:
        if k is not None:
            theta, dtheta = c * dt * k, c * dt * dk
            vs, dvs = v + c * dt * a, Iv + c * dt * da
        qs, k, Dq0, Dth, Kq, Kth, Kv = _chart(model, q0, theta, vs)
        a, Aq, Av, Bu = _acceleration_derivatives(model, qs, vs, tau)
        da = Aq @ (Dq0 @ Iq + Dth @ dtheta) + Av @ dvs + Bu @ Iu
        if euler:  # the chart moves with the new velocity: its rate at v+
            vs, dvs = v + dt * a, Iv + dt * da
            _, k, _, _, Kq, Kth, Kv = _chart(model, q0, theta, vs)
        dk = Kq @ Iq + Kth @ dtheta + Kv @ dvs
        k_sum, dk_sum = k_sum + weight * k, dk_sum + weight * dk
        a_sum, da_sum = a_sum + weight * a, da_sum + weight * da
    theta_next, dtheta_next = dt / total * k_sum, dt / total * dk_sum
    _, _, Dq0, Dth, _, _, _ = _chart(model, q0, theta_next, v)
    dq_next = Dq0 @ Iq + Dth @ dtheta_next
    dv_next = Iv + dt / total * da_sum
    J_ = np.concatenate([dq_next, dv_next], -2)
    return np.ascontiguousarray(J_[..., :2 * n]), np.ascontiguousarray(J_[..., 2 * n:])
