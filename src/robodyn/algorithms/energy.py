"""Kinetic and potential energy.

    T(q, v) = 1/2 sum_i V_i . I_i V_i = 1/2 v^T M(q) v        (V_i: body twist, body frame)
    U(q)    = - sum_i m_i g . c_i = - g . sum_i (m_i p_i + R_i h_i)

``U`` is zero when every centre of mass is at the world origin; ``dU/dq = g(q)``.
Armature (rotor) kinetic energy is not included: it belongs to the motors, see ``armature``.
"""

from __future__ import annotations

import numpy as np

from .._jit import core, inline
from ..layout import INERTIA, INERTIA_END
from ..spatial import dot6, inertia_mul
from ..coupling import expand_q, expand_v
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .status import OK, finite, result_status
from .kinematics import poses_checked
from .rnea import motion_pass, motion_workspace
from .driver import batch_kernel


@core
def energy_one(ints, body, dofs, grav, q, v, check, out, ws):
    """``out[0]`` kinetic energy (when ``v`` has entries), ``out[1]`` potential energy."""
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, a0, zero_a, zero_g = ws
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    T, U = 0.0, 0.0
    if v.shape[0] > 0:
        motion_pass(ints, dofs, liR, lip, v, zero_a, zero_g, vel, acc, vJ, t1, a0)
    for i in range(ints.shape[0]):
        theta = body[i, INERTIA:INERTIA_END]
        if v.shape[0] > 0:
            inertia_mul(theta, vel[i], t1)
            T += 0.5 * dot6(vel[i], t1)
        for r in range(3):
            mc = theta[0] * op[i, r] + oR[i, r, 0] * theta[1] + oR[i, r, 1] * theta[2] + oR[i, r, 2] * theta[3]
            U -= grav[r] * mc
    out[0] = T
    out[1] = U
    return result_status(check, finite(out))


@inline
def energy_at(args, s, ws):
    """Energies of state ``s`` of a batch (``V`` has one row per state, or one row for all)."""
    ints, body, dofs, grav, Q, V, check, OUT = args
    return energy_one(ints, body, dofs, grav, Q[s], V[s if V.shape[0] > 1 else 0], check, OUT[s], ws)


_energy_batch = batch_kernel(energy_at, motion_workspace)


def _run(model, check_finite, what, **arrays):
    batch, x = _inputs.states(model, **arrays)
    try:
        k = model.kernel
    except AttributeError:  # a CoupledModel (mimic joints): the energies of the full tree at (E(q), G v)
        full = {name: expand_q(model, x) if name == "q" else expand_v(model, x, name) for name, x in arrays.items()}
        return _run(model.full, check_finite, what, **full)
    Q = _inputs.as_batch(x["q"])
    V = _inputs.as_batch(x["v"]) if "v" in x else np.zeros((1, 0))
    B = Q.shape[0]
    OUT, status = np.empty((B, 2)), np.empty(B, dtype=np.int64)
    _energy_batch.run((k.ints, k.body, k.dofs[(False, False)], model.gravity, Q, V, check_finite, OUT),
                      (model.nbodies, model.nv), status, batch)
    raise_for_status(model, status, x, what)
    return batch, OUT


def kinetic_energy(model, q, v, *, check_finite: bool = True):
    """Kinetic energy ``v^T M(q) v / 2`` of the rigid bodies: (...,) for q (..., nq), v (..., nv)."""
    if any_lazy(q, v):
        return deferred(kinetic_energy, locals())
    batch, OUT = _run(model, check_finite, "kinetic_energy", q=q, v=v)
    return OUT[:, 0].reshape(batch)[()]


def potential_energy(model, q, *, check_finite: bool = True):
    """Gravitational potential energy ``-sum_i m_i g^T c_i``: (...,) for q (..., nq)."""
    if any_lazy(q):
        return deferred(potential_energy, locals())
    batch, OUT = _run(model, check_finite, "potential_energy", q=q)
    return OUT[:, 1].reshape(batch)[()]
