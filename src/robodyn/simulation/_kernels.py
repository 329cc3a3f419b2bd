"""Compiled steps of the simulation: the chart of the configuration manifold, the state
derivative, and whole runs of the uncontrolled robot.

One step from ``(q_n, v_n)`` integrates in the chart ``q = q_n ⊞ theta`` centred at ``q_n``
(Runge-Kutta-Munthe-Kaas, Hairer, Lubich and Wanner, *Geometric Numerical Integration*,
section IV.8): 1-dof joints ``q_n + theta``; a free joint's position ``p_n + theta_p`` (parent
coordinates) and orientation ``R_n exp(phi)`` (a spherical joint's orientation alike; a planar
joint's position ``(x, y) + theta_xy`` and angle ``t + theta_t``, whose rates are
``Rz(t) (vx, vy)`` and ``wz``). The chart's derivative is exact::

    theta_p' = R(q) v_lin,    phi' = dexp^-1(phi) omega = omega + phi x omega / 2
                                                 + c(t) phi x (phi x omega),
    c(t) = (1 - (t / 2) cot(t / 2)) / t^2,  t = |phi|

so any Runge-Kutta method applied to ``(theta, v)`` keeps its order and every stage lies on
the manifold (unit quaternions by construction).
"""

from __future__ import annotations

import numpy as np

from .._jit import inline, kernel
from ..layout import IQ, IV, JTYPE
from ..algorithms.status import CHECKED, OK
from ..control.laws import law_sizes, law_torque, law_workspace
from ..algorithms.aba import aba_one
from ..algorithms.aba import workspace as aba_workspace
from ..joints import FREE, PLANAR, SPHERICAL
from ..sincos import sincos
from ..spatial import rotation_from_quaternion

SEMI_IMPLICIT_EULER = 0
RK4 = 1

@inline
def chart_point(ints, q0, theta, q):
    """``q = q0 ⊞ theta`` (see the module docstring)."""
    for i in range(ints.shape[0]):
        jt, iq, iv = ints[i, JTYPE], ints[i, IQ], ints[i, IV]
        if jt == PLANAR:  # (x, y) + theta_xy, the angle + theta_t
            q[iq], q[iq + 1] = q0[iq] + theta[iv], q0[iq + 1] + theta[iv + 1]
            st, ct = sincos(theta[iv + 2])
            c, s = q0[iq + 2] * ct - q0[iq + 3] * st, q0[iq + 3] * ct + q0[iq + 2] * st
            n = np.sqrt(c * c + s * s)
            q[iq + 2], q[iq + 3] = c / n, s / n
            continue
        if jt != FREE and jt != SPHERICAL:
            q[iq] = q0[iq] + theta[iv]
            continue
        k, o = iq, iv  # the quaternion in q, the rotation vector in theta
        if jt == FREE:
            for r in range(3):
                q[iq + r] = q0[iq + r] + theta[iv + r]
            k, o = iq + 3, iv + 3
        wx, wy, wz = theta[o], theta[o + 1], theta[o + 2]
        t = np.sqrt(wx * wx + wy * wy + wz * wz)
        s = 0.5 - t * t / 48.0 if t < 1e-4 else np.sin(0.5 * t) / t
        bx, by, bz, bw = s * wx, s * wy, s * wz, np.cos(0.5 * t)
        ax, ay, az, aw = q0[k], q0[k + 1], q0[k + 2], q0[k + 3]
        x = aw * bx + bw * ax + ay * bz - az * by
        y = aw * by + bw * ay + az * bx - ax * bz
        z = aw * bz + bw * az + ax * by - ay * bx
        w = aw * bw - ax * bx - ay * by - az * bz
        n = np.sqrt(x * x + y * y + z * z + w * w)
        q[k], q[k + 1], q[k + 2], q[k + 3] = x / n, y / n, z / n, w / n


@inline
def chart_rate(ints, q, theta, v, R, out):
    """``out = d theta / dt`` for velocity ``v`` at ``q = q0 ⊞ theta``; ``R`` is 3 x 3 workspace."""
    for i in range(ints.shape[0]):
        jt, iq, iv = ints[i, JTYPE], ints[i, IQ], ints[i, IV]
        if jt == PLANAR:  # (x, y)' = Rz(t) (vx, vy), t' = wz
            c, s = q[iq + 2], q[iq + 3]
            out[iv], out[iv + 1], out[iv + 2] = c * v[iv] - s * v[iv + 1], s * v[iv] + c * v[iv + 1], v[iv + 2]
            continue
        if jt != FREE and jt != SPHERICAL:
            out[iv] = v[iv]
            continue
        o = iv
        if jt == FREE:
            rotation_from_quaternion(q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6], R)
            for r in range(3):
                out[iv + r] = R[r, 0] * v[iv] + R[r, 1] * v[iv + 1] + R[r, 2] * v[iv + 2]
            o = iv + 3
        px, py, pz = theta[o], theta[o + 1], theta[o + 2]
        wx, wy, wz = v[o], v[o + 1], v[o + 2]
        t = np.sqrt(px * px + py * py + pz * pz)
        c = 1.0 / 12.0 + t * t / 720.0 if t < 1e-3 else (1.0 - 0.5 * t * np.cos(0.5 * t) / np.sin(0.5 * t)) / (t * t)
        ux, uy, uz = py * wz - pz * wy, pz * wx - px * wz, px * wy - py * wx  # phi x omega
        out[o] = wx + 0.5 * ux + c * (py * uz - pz * uy)
        out[o + 1] = wy + 0.5 * uy + c * (pz * ux - px * uz)
        out[o + 2] = wz + 0.5 * uz + c * (px * uy - py * ux)


@inline
def derivative(ints, body, dofs, params, fext, fcode, limit, q, theta, v, tau_cmd, check, tau, thetadot, a, R, ws):
    """State derivative ``(theta', a)`` at ``q = q0 ⊞ theta``, velocity ``v``, for the command
    ``tau_cmd`` clipped to ``[-limit, limit]`` (written to ``tau``). Returns the ABA status."""
    for k in range(tau.shape[0]):
        tau[k] = min(max(tau_cmd[k], -limit[k]), limit[k])
    status = aba_one(ints, body, dofs, params, q, v, tau, fext, fcode, check, a, ws)
    chart_rate(ints, q, theta, v, R, thetadot)
    return status


@kernel
def stage_workspace(nb, nq, nv):
    """Workspace of ``stage``: ABA's, a 3 x 3 rotation."""
    return aba_workspace(nb, nv), np.empty((3, 3))


@kernel
def point(ints, q0, theta, q):
    """Compiled ``chart_point`` for the Python-driven integrators."""
    chart_point(ints, q0, theta, q)


@kernel
def rate(ints, q, theta, v, R, out):
    """Compiled ``chart_rate`` for the Python-driven integrators."""
    chart_rate(ints, q, theta, v, R, out)


@kernel
def stage(ints, body, dofs, params, fext, fcode, limit, q, theta, v, tau_cmd, tau, thetadot, a, ws, R):
    """Compiled ``derivative`` (with the NaN/Inf check) for the Python-driven integrators."""
    return derivative(ints, body, dofs, params, fext, fcode, limit, q, theta, v, tau_cmd, CHECKED, tau, thetadot, a, R,
                      ws)


@kernel
def run(ints, body, dofs, params, fext, fcode, limit, c, law, gains, breaks, coefs, tau_cmd, method, q0, v0, s0, dt,
        Q, V, A, T):
    """Integrate from ``(q0, v0)`` at time ``s0 dt`` (sample ``s0``) with ``Q.shape[0] - 1`` steps of ``dt`` under
    a compiled control law (``law``, see ``law_torque``; ``CONSTANT`` applies ``tau_cmd``);
    writes the samples ``Q, V``, the accelerations ``A`` and the applied torques ``T``.
    Returns ``(status, sample)`` of the first failing evaluation (``(OK, -1)`` on success)."""
    nv = v0.shape[0]
    ws, R = stage_workspace(ints.shape[0], q0.shape[0], nv)
    nb, nqf, nvf = law_sizes(c)
    cws = law_workspace(nb, nv, nqf, nvf)
    th = np.zeros(nv)
    thi = np.empty(nv)
    vi = np.empty(nv)
    qi = np.empty(q0.shape[0])
    ka = np.empty((4, nv))
    kt = np.empty((4, nv))
    tau = np.empty(nv)
    cmd = np.empty(nv)
    Q[0, :] = q0
    V[0, :] = v0
    n = Q.shape[0] - 1
    for s in range(n + 1):
        q, v, t = Q[s], V[s], (s0 + s) * dt
        th[:] = 0.0
        st = law_torque(law, c, gains, breaks, coefs, t, q, v, tau_cmd, cws, cmd)
        if st == OK:
            st = derivative(ints, body, dofs, params, fext, fcode, limit, q, th, v, cmd, CHECKED, T[s], kt[0], A[s], R,
                            ws)
        if st != OK:
            return st, s
        if s == n:
            break
        if method == SEMI_IMPLICIT_EULER:
            for k in range(nv):
                V[s + 1, k] = v[k] + dt * A[s, k]
            chart_rate(ints, q, th, V[s + 1], R, thi)
            for k in range(nv):
                thi[k] *= dt
            chart_point(ints, q, thi, Q[s + 1])
            continue
        for k in range(nv):
            ka[0, k] = A[s, k]
        for j, h in ((1, 0.5 * dt), (2, 0.5 * dt), (3, dt)):
            for k in range(nv):
                thi[k] = h * kt[j - 1, k]
                vi[k] = v[k] + h * ka[j - 1, k]
            chart_point(ints, q, thi, qi)
            st = law_torque(law, c, gains, breaks, coefs, t + h, qi, vi, tau_cmd, cws, cmd)
            if st == OK:
                st = derivative(ints, body, dofs, params, fext, fcode, limit, qi, thi, vi, cmd, CHECKED, tau, kt[j],
                                ka[j], R, ws)
            if st != OK:
                return st, s
        for k in range(nv):
            thi[k] = dt / 6.0 * (kt[0, k] + 2.0 * kt[1, k] + 2.0 * kt[2, k] + kt[3, k])
            V[s + 1, k] = v[k] + dt / 6.0 * (ka[0, k] + 2.0 * ka[1, k] + 2.0 * ka[2, k] + ka[3, k])
        chart_point(ints, q, thi, Q[s + 1])
    return OK, -1
