"""Compiled time stepping with contacts of a model with mimic couplings
(:class:`~robodyn.coupling.CoupledModel`): :func:`_contact_step.step` in the independent
coordinates.

The state is the full tree's, on the coupling (``q = P q_r + o``, ``v = G v_r``); ``G``
(nv_full, nv) has one entry per row, ``G[k, cmap[k]] = cscale[k]`` (1 on an independent dof,
the multiplier on a mimic dof). One step: the full tree's ``h`` and ``M`` at ``q``, reduced to
``h_r = G^T h`` and ``M_r = G^T M G = L L^T``, the free velocity
``v_f = v_r + dt M_r^-1 (tau_r - h_r)``, the contact rows of the full tree reduced to
``J_r = J G``, the impulses of the Delassus matrix ``J_r M_r^-1 J_r^T`` (the coupled model's),
``v_r+ = v_f + M_r^-1 J_r^T P``; then ``v+ = G v_r+`` and ``q+ = q ⊞ dt v+``, which keeps the
linear couplings of the 1-dof mimic joints exactly. The applied torque ``tau`` is the full
tree's command, zero on the mimic dofs (``tau_r = G^T tau``). Free and planar joints are
never mimic joints, so their dofs (the moving-frame terms) are independent dofs of unit
scale, read and written through ``independent``.
"""

from __future__ import annotations

import numpy as np

from .._jit import core, kernel
from ..algorithms.crba import workspace as crba_workspace
from ..algorithms.rnea import workspace as rnea_workspace
from ..algorithms.status import NOT_POSITIVE_DEFINITE, OK
from ..algorithms.dense import backward, cholesky, forward
from ._contact_step import (contact_forces, contact_rows, contact_velocity, dynamics_terms, moving_frame_terms,
                            next_state, pair_workspace)


@kernel
def workspace(nb, nf, nr, npairs):
    """Scratch of :func:`step`: ``nb`` bodies, ``nf`` dofs of the full tree, ``nr``
    independent dofs, ``npairs`` pairs."""
    m3 = 3 * npairs
    return (crba_workspace(nb, nf), rnea_workspace(nb), np.empty((nf, nf)), np.empty(nf), np.empty(nf),
            np.zeros(nf), np.empty((m3, nf)), np.empty((nr, nr)), np.empty(nr), np.empty(nr), np.empty(nr),
            np.empty(nr), np.empty((m3, nr)), np.empty((nr, m3)), np.empty((3, 3)), np.empty(nf),
            pair_workspace(npairs))


@core
def step(ints, body, dofs, params, fext, fcode, limit, cmap, cscale, independent, points, centers, radii, surf,
         settings, q, v, tau_cmd, dt, tau, a, q1, v1, force, geom, warm, info, ws):
    """One step of the coupled model (module docstring), with the arguments of
    :func:`_contact_step.step` in the full tree's coordinates and the coupling ``cmap``,
    ``cscale`` (nv_full,) and ``independent`` (nv,: the full dofs of the independent ones).
    ``a`` is ``G (v_r+ - v_r) / dt``. Returns a status."""
    cws, rws, M, h, vf, zero, Jc, Mr, tau_r, vr, vfr, dvr, Jr, Y, R, tmp, pws = ws
    nf, nr = cmap.shape[0], independent.shape[0]
    st = dynamics_terms(ints, body, dofs, params, fext, fcode, limit, q, v, tau_cmd, zero, tau, h, M, rws, cws)
    if st != OK:
        return st
    for i in range(nr):
        vr[i] = v[independent[i]]
        tau_r[i] = 0.0
        for j in range(nr):
            Mr[i, j] = 0.0
    for k in range(nf):  # tau_r - h_r = G^T (tau - h), M_r = G^T M G
        tau_r[cmap[k]] += cscale[k] * (tau[k] - h[k])
        for j in range(nf):
            Mr[cmap[k], cmap[j]] += cscale[k] * cscale[j] * M[k, j]
    if not cholesky(Mr):
        return NOT_POSITIVE_DEFINITE
    forward(Mr, tau_r)
    backward(Mr, tau_r)
    for k in range(nf):
        tmp[k] = 0.0
    moving_frame_terms(ints, v, dt, tmp)
    for i in range(nr):
        vfr[i] = vr[i] + dt * tau_r[i] + tmp[independent[i]]
    for k in range(nf):
        vf[k] = cscale[k] * vfr[cmap[k]]
    m = contact_rows(ints, cws, points, centers, radii, surf, settings, v, vf, dt, geom, force, warm, Jc, pws)
    for r in range(3 * m):  # J_r = J G
        for i in range(nr):
            Jr[r, i] = 0.0
        for k in range(nf):
            Jr[r, cmap[k]] += cscale[k] * Jc[r, k]
    contact_velocity(Mr, Jr, m, vfr, settings, info, Y, pws, dvr)
    for k in range(nf):
        tmp[k] = 0.0
    moving_frame_terms(ints, v, -1.0, tmp)  # the spatial acceleration, as in _contact_step.step
    for k in range(nf):
        v1[k] = cscale[k] * (vfr[cmap[k]] + dvr[cmap[k]])
        a[k] = (v1[k] - v[k]) / dt + tmp[k]
    contact_forces(m, dt, force, warm, pws)
    return next_state(ints, q, zero, dt, v1, q1, R, tmp)


@kernel
def step_kernel(ints, body, dofs, params, fext, fcode, limit, cmap, cscale, independent, points, centers, radii, surf,
                settings, q, v, tau_cmd, dt, tau, a, q1, v1, force, geom, warm, info, ws):
    """Compiled :func:`step` for the Python-driven controllers."""
    return step(ints, body, dofs, params, fext, fcode, limit, cmap, cscale, independent, points, centers, radii, surf,
                settings, q, v, tau_cmd, dt, tau, a, q1, v1, force, geom, warm, info, ws)
