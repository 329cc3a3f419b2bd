"""Kinetic and potential energy.

    T(q, v) = 1/2 sum_i V_i . I_i V_i = 1/2 v^T M(q) v        (V_i: body twist, body frame)
    U(q)    = - sum_i m_i g . c_i = - g . sum_i (m_i p_i + R_i h_i)

``U`` is zero when every centre of mass is at the world origin; ``dU/dq = g(q)``.
Armature (rotor) kinetic energy is not included: it belongs to the motors, see ``armature``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..spatial import dot6, inertia_mul
from . import _inputs
from .kinematics import placements, world_placements
from .rnea import motion_pass


@njit(cache=True)
def workspace(nb, nv):
    return (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3, 3)), np.empty((nb, 3)),
            np.empty((3, 3)), np.empty(3), np.empty((nb, 6)), np.empty((nb, 6)), np.empty(6), np.empty(6),
            np.empty(6), np.zeros(nv), np.zeros(3))


@njit(cache=True)
def energy_one(ints, body, S, grav, q, v, out, ws):
    """``out[0]`` kinetic energy (when ``v`` has entries), ``out[1]`` potential energy."""
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, a0, zero_a, zero_g = ws
    placements(ints, body, q, liR, lip, Rj, pj)
    world_placements(ints, liR, lip, oR, op)
    T, U = 0.0, 0.0
    if v.shape[0] > 0:
        motion_pass(ints, S, liR, lip, v, zero_a, zero_g, vel, acc, vJ, t1, a0)
    for i in range(ints.shape[0]):
        theta = body[i, 15:25]
        if v.shape[0] > 0:
            inertia_mul(theta, vel[i], t1)
            T += 0.5 * dot6(vel[i], t1)
        for r in range(3):
            mc = theta[0] * op[i, r] + oR[i, r, 0] * theta[1] + oR[i, r, 1] * theta[2] + oR[i, r, 2] * theta[3]
            U -= grav[r] * mc
    out[0] = T
    out[1] = U


@njit(cache=True, parallel=True)
def _energy_batch(ints, body, S, grav, Q, V, OUT, nchunk):
    B = Q.shape[0]
    for c in prange(nchunk):
        ws = workspace(ints.shape[0], S.shape[0])
        for s in range(c * B // nchunk, (c + 1) * B // nchunk):
            energy_one(ints, body, S, grav, Q[s], V[s if V.shape[0] > 1 else 0], OUT[s], ws)


@njit(cache=True)
def _energy_single(ints, body, S, grav, q, v, out):
    energy_one(ints, body, S, grav, q, v, out, workspace(ints.shape[0], S.shape[0]))


def _run(model, check_finite, **arrays):
    batch, flat = _inputs.states(model, check_finite, **arrays)
    ints, body, S, _ = model._kernel
    Q = flat["q"]
    V = flat.get("v", np.zeros((1, 0)))
    OUT = np.empty((Q.shape[0], 2))
    nchunk = _inputs.chunks(Q.shape[0])
    if nchunk:
        _energy_batch(ints, body, S, model.gravity, Q, V, OUT, nchunk)
    else:
        _energy_single(ints, body, S, model.gravity, Q[0], V[0], OUT[0])
    return batch, OUT


def kinetic_energy(model, q, v, *, check_finite: bool = True):
    """Kinetic energy ``v^T M(q) v / 2`` of the rigid bodies: (...,) for q (..., nq), v (..., nv)."""
    batch, OUT = _run(model, check_finite, q=q, v=v)
    return OUT[:, 0].reshape(batch)[()]


def potential_energy(model, q, *, check_finite: bool = True):
    """Gravitational potential energy ``-sum_i m_i g . c_i``: (...,) for q (..., nq)."""
    batch, OUT = _run(model, check_finite, q=q)
    return OUT[:, 1].reshape(batch)[()]
