"""Compiled time stepping with contacts: one step (the model of :mod:`robodyn.contact.solver`);
whole runs under a compiled control law are in :mod:`._contact_runs`.

A step from ``(q, v)`` under the command ``tau_cmd`` (clipped to the effort limits):
``h = rnea(q, v, 0)``, ``M = crba(q) = L L^T``, the free velocity ``v_f``, the contact pairs
within reach (a gap below ``margin`` plus the distance the free motion covers in the step),
their Jacobian rows in their contact frames, the Delassus matrix, the impulses by projected
Gauss-Seidel, then ``v+`` and ``q+ = q ⊞ dt v+`` in the chart of ``q`` (as
``simulate``'s semi-implicit Euler).
"""

from __future__ import annotations

import numpy as np

from .._jit import core, inline, kernel, scratch
from ..algorithms.crba import crba_one
from ..algorithms.crba import workspace as crba_workspace
from ..algorithms.dense import backward, cholesky, forward
from ..algorithms.rnea import rnea_one
from ..algorithms.rnea import workspace as rnea_workspace
from ..algorithms.status import CHECKED, NONFINITE_RESULT, NOT_POSITIVE_DEFINITE, OK, finite
from ..contact.solver import (ACTIVE, BODY, BODY_SPHERE, BOUNCE_SPEED, FRICTION, ITERATIONS, KIND, MARGIN,
                              MAX_CORRECTION, MAX_ITERATIONS, RESIDUAL, RESTITUTION, STABILIZATION, TOLERANCE,
                              contact_frame, delassus, point_rows, solve, surface_distance)
from ..joints import FREE, PLANAR
from ..layout import IV, JTYPE
from ._kernels import chart_point, chart_rate


@scratch
def pair_workspace(npairs):
    """Scratch of :func:`contact_rows` and :func:`contact_velocity` for ``npairs`` pairs (none of
    it depends on the model): Delassus matrix, free contact velocities, targets, friction,
    impulses, contact frames, pair indices, the solver's scratch and four 3-vectors."""
    m3 = 3 * npairs
    return (np.empty((m3, m3)), np.empty(m3), np.empty(npairs), np.empty(npairs), np.empty(m3),
            np.empty((npairs, 3, 3)), np.empty(npairs, np.int64),
            (np.empty((m3, m3)), np.empty((m3, m3)), np.empty((13, m3))),
            np.empty(3), np.empty(3), np.empty(3), np.empty(3))


@kernel
def workspace(nb, nv, npairs):
    """Scratch of :func:`step` for a model of ``nb`` bodies and ``nv`` dofs and ``npairs`` pairs."""
    m3 = 3 * npairs
    return (crba_workspace(nb, nv), rnea_workspace(nb), np.empty((nv, nv)), np.empty(nv), np.empty(nv),
            np.zeros(nv), np.empty((m3, nv)), np.empty((nv, m3)), np.empty((3, 3)), np.empty(nv),
            pair_workspace(npairs))


@inline
def moving_frame_terms(ints, v, h, out):
    """``out += h w x v_lin`` for the free joints (``v = [v_lin; w]`` in the child frame) and
    ``out[vx, vy] += h wz x (vx, vy)`` for the planar joints.

    Their linear velocities are coordinates in a frame that turns with the body, so that
    ``d v_lin / dt = a_lin = a_classical - w x v_lin`` (the spatial acceleration). Stepping
    that rotation explicitly, ``v_lin + dt a_lin``, lengthens ``v_lin`` by ``sqrt(1 + (|w| dt)^2)``
    each step (a rolling ball speeds up). The step instead moves the classical acceleration
    (``h = dt``: ``v_f`` gains ``dt w x v_lin``), then turns the result into the next frame
    (:func:`to_next_frame`): the velocity of the body's origin changes only by the forces."""
    for i in range(ints.shape[0]):
        jt, iv = ints[i, JTYPE], ints[i, IV]
        if jt == FREE:
            vx, vy, vz, wx, wy, wz = v[iv], v[iv + 1], v[iv + 2], v[iv + 3], v[iv + 4], v[iv + 5]
            out[iv] += h * (wy * vz - wz * vy)
            out[iv + 1] += h * (wz * vx - wx * vz)
            out[iv + 2] += h * (wx * vy - wy * vx)
        elif jt == PLANAR:
            vx, vy, wz = v[iv], v[iv + 1], v[iv + 2]
            out[iv] -= h * wz * vy
            out[iv + 1] += h * wz * vx


@inline
def to_next_frame(ints, v1, dt):
    """The free and planar joints' linear velocities ``v1`` (coordinates in the child frame at
    the start of the step) in the child frame at its end, turned by ``exp(-dt w)`` (Rodrigues)."""
    for i in range(ints.shape[0]):
        jt, iv = ints[i, JTYPE], ints[i, IV]
        if jt == FREE:
            wx, wy, wz = -dt * v1[iv + 3], -dt * v1[iv + 4], -dt * v1[iv + 5]
            t = np.sqrt(wx * wx + wy * wy + wz * wz)
            if t == 0.0:
                continue
            ux, uy, uz = wx / t, wy / t, wz / t
            c, s = np.cos(t), np.sin(t)
            x, y, z = v1[iv], v1[iv + 1], v1[iv + 2]
            d = (ux * x + uy * y + uz * z) * (1.0 - c)
            v1[iv] = x * c + (uy * z - uz * y) * s + ux * d
            v1[iv + 1] = y * c + (uz * x - ux * z) * s + uy * d
            v1[iv + 2] = z * c + (ux * y - uy * x) * s + uz * d
        elif jt == PLANAR:
            s, c = np.sin(-dt * v1[iv + 2]), np.cos(-dt * v1[iv + 2])
            x, y = v1[iv], v1[iv + 1]
            v1[iv], v1[iv + 1] = c * x - s * y, s * x + c * y


@inline
def _dot(a, b):
    s = 0.0
    for k in range(a.shape[0]):
        s += a[k] * b[k]
    return s


@inline
def contact_rows(ints, cws, points, centers, radii, surf, settings, v, vf, dt, geom, force, warm, Jc, pws):
    """The pairs within reach at ``q`` (``cws``: the CRBA's workspace at ``q``, holding the
    world poses and motion subspaces): every pair's ``geom`` (signed distance, normal) and a
    zero ``force``; for the ``m`` pairs the step may close (a gap below the margin plus the
    distance the free motion covers), their Jacobian rows in their contact frames
    ``Jc[3c:3c + 3]`` (as wide as ``v``), and in ``pws`` (:func:`pair_workspace`) their target
    normal velocity, friction, pair index and warm-start impulse. ``v``: the velocity at the
    start of the step, ``vf``: the free velocity at its end. Returns ``m``."""
    _, _, bias, mu, P, frames, pair_of, _, x, nrm, ysurf, point = pws
    oR, op, oS = cws[1][2], cws[1][3], cws[2]
    nv, ns = v.shape[0], surf.shape[0]
    m = 0
    for p in range(points.shape[0]):
        b, rad = points[p], radii[p]
        for r in range(3):
            x[r] = op[b, r] + oR[b, r, 0] * centers[p, 0] + oR[b, r, 1] * centers[p, 1] + oR[b, r, 2] * centers[p, 2]
        for s in range(ns):
            pair = p * ns + s
            other = int(surf[s, BODY]) if surf[s, KIND] == BODY_SPHERE else -1
            if other == b:  # a body does not touch itself
                geom[pair, 0] = np.inf
                for r in range(3):
                    geom[pair, 1 + r] = 0.0
                    force[pair, r] = 0.0
                    warm[pair, r] = 0.0
                continue
            phi = surface_distance(surf[s], x, rad, nrm, oR, op, ysurf)
            geom[pair, 0] = phi
            for r in range(3):
                geom[pair, 1 + r] = nrm[r]
                force[pair, r] = 0.0
            F, rows = frames[m], Jc[3 * m:3 * m + 3]
            contact_frame(nrm, F)
            for r in range(3):  # the sphere's point nearest the surface
                point[r] = x[r] - rad * F[0, r]
            for r in range(3):
                for k in range(nv):
                    rows[r, k] = 0.0
            point_rows(ints, oS, b, point, F, rows, 1.0)
            if other >= 0:  # the velocity relative to the other body's surface point
                point_rows(ints, oS, other, ysurf, F, rows, -1.0)
            u_free, u_before = _dot(rows[0], vf), _dot(rows[0], v)
            if phi >= settings[MARGIN] - dt * min(u_free, 0.0):
                for r in range(3):
                    warm[pair, r] = 0.0
                continue
            if phi > 0.0:  # may close the gap, not cross it
                target = -phi / dt
            else:  # push out, at a bounded speed
                target = min(settings[STABILIZATION] * -phi / dt, settings[MAX_CORRECTION])
            e = surf[s, RESTITUTION]
            if e > 0.0 and u_before < -settings[BOUNCE_SPEED] and phi + dt * u_free < 0.0:
                target = max(target, -e * u_before)  # Newton's impact law
            bias[m], mu[m], pair_of[m] = target, surf[s, FRICTION], pair
            for r in range(3):
                P[3 * m + r] = warm[pair, r]
            m += 1
    return m


@inline
def contact_velocity(L, Jc, m, vf, settings, info, Y, pws, dv):
    """The impulses ``P`` of the ``m`` contacts of :func:`contact_rows` (projected Gauss-Seidel
    on the Delassus matrix ``Jc M^-1 Jc^T``, ``L`` the Cholesky factor of ``M``) and the
    velocity they add, ``dv = M^-1 Jc^T P`` (zero without contacts); the solver's ``info``."""
    G, u0, bias, mu, P, _, _, sws, _, _, _, _ = pws
    nv = L.shape[0]
    for k in range(nv):
        dv[k] = 0.0
    info[ACTIVE] = m
    info[ITERATIONS], info[RESIDUAL] = 0.0, 0.0
    if m > 0:
        delassus(L, Jc, m, Y, G)
        for r in range(3 * m):  # the free contact velocities minus their targets
            u0[r] = _dot(Jc[r], vf)
        for c in range(m):
            u0[3 * c] -= bias[c]
        solve(G, u0, mu, m, P, int(settings[MAX_ITERATIONS]), settings[TOLERANCE], info, sws)
        for i in range(nv):
            s_ = 0.0
            for r in range(3 * m):
                s_ += Y[i, r] * P[r]
            dv[i] = s_
        backward(L, dv)


@inline
def contact_forces(m, dt, force, warm, pws):
    """Each active pair's force (world axes, ``F^T P / dt``) and its impulse kept as the next
    step's warm start."""
    _, _, _, _, P, frames, pair_of, _, _, _, _, _ = pws
    for c in range(m):
        pair, F = pair_of[c], frames[c]
        for r in range(3):
            force[pair, r] = (F[0, r] * P[3 * c] + F[1, r] * P[3 * c + 1] + F[2, r] * P[3 * c + 2]) / dt
            warm[pair, r] = P[3 * c + r]


@inline
def dynamics_terms(ints, body, dofs, params, fext, fcode, limit, q, v, tau_cmd, zero, tau, h, M, rws, cws):
    """The start of a step: ``tau`` the command clipped to the effort limits, the bias
    ``h = rnea(q, v, 0)`` (with the external wrenches) and ``M = crba(q)``. Returns a status."""
    for k in range(tau.shape[0]):
        tau[k] = min(max(tau_cmd[k], -limit[k]), limit[k])
    st = rnea_one(ints, body, dofs, params, q, v, zero, fext, fcode, CHECKED, h, rws)
    if st != OK:
        return st
    return crba_one(ints, body, dofs, q, CHECKED, M, cws)


@inline
def next_state(ints, q, zero, dt, v1, q1, R, tmp):
    """The end of a step: ``q1 = q ⊞ dt v1`` in the chart of ``q``, then ``v1``'s free and
    planar linear velocities turned into the next frame (:func:`to_next_frame`). Returns a
    status (non-finite results)."""
    chart_rate(ints, q, zero, v1, R, tmp)
    for k in range(tmp.shape[0]):
        tmp[k] *= dt
    chart_point(ints, q, tmp, q1)
    to_next_frame(ints, v1, dt)
    if not (finite(v1) and finite(q1)):
        return NONFINITE_RESULT
    return OK


@core
def step(ints, body, dofs, params, fext, fcode, limit, points, centers, radii, surf, settings, q, v, tau_cmd, dt,
         tau, a, q1, v1, force, geom, warm, info, ws):
    """One step from ``(q, v)``: the applied torque ``tau``, ``a = (v+ - v) / dt``, the next
    state ``(q1, v1)``, each pair's contact force (world axes, N; zero when apart) and
    geometry at ``q`` (``geom[pair] = [signed distance (m), surface normal (3)]``), the
    solver's ``info`` (sweeps, residual, active contacts; converged when the residual is at
    most ``settings[TOLERANCE]``). ``warm`` (npairs, 3): the previous step's impulses in the
    contact frames (read and written). Returns a status."""
    cws, rws, M, h, vf, zero, Jc, Y, R, tmp, pws = ws
    nv = v.shape[0]
    st = dynamics_terms(ints, body, dofs, params, fext, fcode, limit, q, v, tau_cmd, zero, tau, h, M, rws, cws)
    if st != OK:
        return st
    if not cholesky(M):
        return NOT_POSITIVE_DEFINITE
    for k in range(nv):
        tmp[k] = tau[k] - h[k]
    forward(M, tmp)
    backward(M, tmp)
    for k in range(nv):
        vf[k] = v[k] + dt * tmp[k]
    moving_frame_terms(ints, v, dt, vf)
    m = contact_rows(ints, cws, points, centers, radii, surf, settings, v, vf, dt, geom, force, warm, Jc, pws)
    contact_velocity(M, Jc, m, vf, settings, info, Y, pws, tmp)
    for k in range(nv):
        v1[k] = vf[k] + tmp[k]
        a[k] = (v1[k] - v[k]) / dt
    moving_frame_terms(ints, v, -1.0, a)  # the spatial acceleration M^-1 (tau - h + J^T lambda)
    contact_forces(m, dt, force, warm, pws)
    return next_state(ints, q, zero, dt, v1, q1, R, tmp)


@kernel
def step_kernel(ints, body, dofs, params, fext, fcode, limit, points, centers, radii, surf, settings, q, v, tau_cmd, dt,
                tau, a, q1, v1, force, geom, warm, info, ws):
    """Compiled :func:`step` for the Python-driven controllers."""
    return step(ints, body, dofs, params, fext, fcode, limit, points, centers, radii, surf, settings, q, v, tau_cmd, dt,
                tau, a, q1, v1, force, geom, warm, info, ws)
