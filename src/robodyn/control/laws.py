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

from .._jit import by_address, inline, kernel, scratch
from ..algorithms.jacobian import jacobian_one
from ..algorithms.rnea import motion_workspace, rnea_coupled_state, rnea_one
from ..algorithms.rnea import workspace as rnea_workspace
from ..algorithms.status import CHECKED, NO_WRENCH, OK
from ..joint_kernels import nq_of

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

    ``c = (ints, body, dofs_gravity, dofs_full, params, zero_wrench, cints, cfloats)`` of the
    controller's model (``dofs_gravity`` without friction and armature, ``dofs_full`` with
    them; for a model with mimic couplings its full tree's and its ``CouplingTables``, empty
    for a tree), the law in the model's coordinates; ``gains[0] = Kp``, ``gains[1] = Kd``."""
    if law == CONSTANT:
        for k in range(out.shape[0]):
            out[k] = tau_cmd[k]
        return OK
    if law == JOINT_PD:  # gains: Kp, Kd, the dof's index in q, q_d, tau_ff (zero gains: unactuated)
        for k in range(out.shape[0]):
            out[k] = gains[4, k] + gains[0, k] * (gains[3, k] - q[int(gains[2, k])]) - gains[1, k] * v[k]
        return OK
    ws, qd, vd, ad, acc, zero, buf = cws
    reference_at(breaks, coefs, t, qd, vd, ad)
    if law == PD_GRAVITY:
        st = law_rnea(c, c[2], q, zero, zero, ws, buf, out)
        for k in range(out.shape[0]):
            out[k] += gains[0, k] * (qd[k] - q[k]) - gains[1, k] * v[k]
        return st
    for k in range(out.shape[0]):
        acc[k] = ad[k] + gains[1, k] * (vd[k] - v[k]) + gains[0, k] * (qd[k] - q[k])
    return law_rnea(c, c[3], q, v, acc, ws, buf, out)


_rnea_one = by_address(rnea_one)  # called at its compiled code's address, not copied (see ``_jit``)

@inline
def law_rnea(c, dofs, q, v, a, ws, buf, out):
    """The RNEA of the controller's model ``c`` (see :func:`law_torque`) with ``dofs``: the
    tree's, or with mimic couplings ``G^T rnea_full(E(q), G v, G a)`` (``buf``: the full
    tree's state, see ``rnea.coupled_workspace``)."""
    if c[6].shape[0] == 0:
        return _rnea_one(c[0], c[1], dofs, c[4], q, v, a, c[5], NO_WRENCH, CHECKED, out, ws)
    return rnea_coupled_state(c[0], c[1], dofs, c[4], c[6], c[7], q, v, a, c[5], NO_WRENCH, CHECKED, out, (ws, buf))


@scratch
def law_workspace(nb, nv, nqf, nvf):
    """Scratch ``cws`` of :func:`law_torque` for a controller model of ``nb`` bodies and ``nv``
    dofs (``nqf``, ``nvf``: its tree's sizes, see :func:`law_sizes`): the RNEA's, the
    reference ``(q_d, v_d, a_d)``, the commanded acceleration, zeros, and the full tree's
    state of a model with mimic couplings."""
    return (rnea_workspace(nb), np.empty(nv), np.empty(nv), np.empty(nv), np.empty(nv), np.zeros(nv),
            np.empty(nqf + 3 * nvf))


@inline
def law_sizes(c):
    """``(nb, nq, nv)`` of the tree of the controller model ``c`` (see :func:`law_torque`)."""
    return c[0].shape[0], nq_of(c[0]), c[2].shape[0]


@kernel
def body_jacobian(ints, body, dofs, q, b, J, oRb, opb):
    """World Jacobian ``J`` (6, nv) of body ``b`` and its world pose; returns a status."""
    ws = motion_workspace(ints.shape[0], dofs.shape[0])
    return jacobian_one(ints, body, dofs, q, q[:0], b, CHECKED, J, oRb, opb, np.empty(6), np.empty(6), ws)
