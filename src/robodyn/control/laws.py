"""Control laws that run in compiled code: inside :func:`robodyn.simulate`'s integrator (a
controller's ``kernel_law``) and at every integrator stage of the Python-driven controllers,
where a batch kernel's thread start-up would dominate.

Law codes: ``CONSTANT`` (the command ``tau_cmd``; zero: the free robot), ``PD_GRAVITY``
(``Kp (q_d - q) - Kd qd + g(q)``), ``COMPUTED_TORQUE``
(``rnea(q, qd, qdd_d + Kd (qd_d - qd) + Kp (q_d - q))``) and ``JOINT_PD``
(``tau_ff + Kp (q_d - q) - Kd v`` on the actuated joints of any robot, floating bases
included), with the reference a piecewise
polynomial (:func:`reference_at`). Reference: Siciliano et al., *Robotics: Modelling, Planning
and Control* (2009), chapter 8.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline, kernel
from ..algorithms.jacobian import jacobian_one
from ..algorithms.rnea import motion_workspace, rnea_one
from ..algorithms.rnea import workspace as rnea_workspace
from ..algorithms.status import CHECKED, NO_WRENCH, OK

CONSTANT = 0         # the constant command tau_cmd (zero: the free robot)
PD_GRAVITY = 1       # Kp (q_d - q) - Kd qd + g(q)
COMPUTED_TORQUE = 2  # rnea(q, qd, qdd_d + Kd (qd_d - qd) + Kp (q_d - q))
JOINT_PD = 3         # tau_ff + Kp (q_d - q) - Kd v on the actuated dofs (JointPD; any base)


@inline
def reference_at(breaks, coefs, t, qd, vd, ad):
    """Piecewise polynomial reference (scipy ``PPoly`` layout: ``coefs[i, seg, j]`` multiplies
    ``(t - breaks[seg])^(k - 1 - i)``) and its two derivatives at ``t``; outside
    ``[breaks[0], breaks[-1]]`` it holds its end value at rest."""
    m, k = breaks.shape[0] - 1, coefs.shape[0]
    hold = t < breaks[0] or t > breaks[m]
    if t < breaks[0]:
        seg, x = 0, 0.0
    else:
        lo, hi = 0, m - 1  # the last segment with breaks[seg] <= t
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if breaks[mid] <= t:
                lo = mid
            else:
                hi = mid - 1
        seg = lo
        x = min(t, breaks[m]) - breaks[seg]
    for j in range(coefs.shape[2]):
        p, dp, ddp = 0.0, 0.0, 0.0
        for i in range(k):  # Horner's rule with the first two derivatives
            ddp = ddp * x + 2.0 * dp
            dp = dp * x + p
            p = p * x + coefs[i, seg, j]
        qd[j] = p
        vd[j] = 0.0 if hold else dp
        ad[j] = 0.0 if hold else ddp


@inline
def law_torque(law, c, gains, breaks, coefs, t, q, v, tau_cmd, cws, out):
    """The command of a compiled control law at ``(t, q, v)`` into ``out``; returns a status.

    ``c = (ints, body, dofs_gravity, dofs_full, params, zero_wrench)`` of the controller's model
    (``dofs_gravity`` without friction and armature, ``dofs_full`` with them);
    ``gains[0] = Kp``, ``gains[1] = Kd``."""
    if law == CONSTANT:
        for k in range(out.shape[0]):
            out[k] = tau_cmd[k]
        return OK
    if law == JOINT_PD:  # gains: Kp, Kd, the dof's index in q, q_d, tau_ff (zero gains: unactuated)
        for k in range(out.shape[0]):
            out[k] = gains[4, k] + gains[0, k] * (gains[3, k] - q[int(gains[2, k])]) - gains[1, k] * v[k]
        return OK
    ws, qd, vd, ad, acc, zero = cws
    reference_at(breaks, coefs, t, qd, vd, ad)
    if law == PD_GRAVITY:
        st = rnea_one(c[0], c[1], c[2], c[4], q, zero, zero, c[5], NO_WRENCH, CHECKED, out, ws)
        for k in range(out.shape[0]):
            out[k] += gains[0, k] * (qd[k] - q[k]) - gains[1, k] * v[k]
        return st
    for k in range(out.shape[0]):
        acc[k] = ad[k] + gains[1, k] * (vd[k] - v[k]) + gains[0, k] * (qd[k] - q[k])
    return rnea_one(c[0], c[1], c[3], c[4], q, v, acc, c[5], NO_WRENCH, CHECKED, out, ws)


@kernel
def law_workspace(nb, nv):
    """Scratch ``cws`` of :func:`law_torque` for a controller model of ``nb`` bodies and ``nv``
    dofs: the RNEA's, the reference ``(q_d, v_d, a_d)``, the commanded acceleration, zeros."""
    return rnea_workspace(nb), np.empty(nv), np.empty(nv), np.empty(nv), np.empty(nv), np.zeros(nv)


@kernel
def body_jacobian(ints, body, dofs, q, b, J, oRb, opb):
    """World Jacobian ``J`` (6, nv) of body ``b`` and its world pose; returns a status."""
    ws = motion_workspace(ints.shape[0], dofs.shape[0])
    return jacobian_one(ints, body, dofs, q, q[:0], b, CHECKED, J, oRb, opb, np.empty(6), np.empty(6), ws)
