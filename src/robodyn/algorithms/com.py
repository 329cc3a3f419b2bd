"""Centre of mass of the whole robot and its Jacobian.

    c = sum_i (m_i p_i + R_i h_i) / m_total                       (world frame)
    J_com[:, k] = (m^c_i S_lin,k + S_ang,k x h^c_i) / m_total     (k a dof of body i)

where ``(m^c_i, h^c_i)`` are the mass and first moment (world frame) of the subtree rooted at
body ``i`` and ``S_k = [S_lin,k; S_ang,k]`` the world-frame motion subspace column, so that
``J_com v`` is the velocity of the centre of mass.
"""

from __future__ import annotations

import numpy as np

from .._jit import core, inline, scratch
from ..layout import IV, NDOF, PARENT
from ..coupling import expand_q, is_coupled, reduce_columns
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .crba import world_inertias
from .status import OK, finite, finite2, result_status
from .kinematics import poses_checked, world_motion_subspace
from .driver import batch_kernel


@scratch
def workspace(nb, nv):
    return (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3, 3)), np.empty((nb, 3)),
            np.empty((3, 3)), np.empty(3), np.empty((nv, 6)), np.empty((nb, 10)))


@core
def com_one(ints, body, dofs, q, check, c, Jc, ws):
    """Centre of mass ``c`` (3,) and, if ``Jc`` has columns, its Jacobian (3, nv)."""
    liR, lip, oR, op, Rj, pj, oS, Ic = ws
    status = poses_checked(ints, body, q, q[:0], check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    world_inertias(ints, body, oR, op, Ic)
    if Jc.shape[1] > 0:
        world_motion_subspace(ints, dofs, oR, op, oS)
    for i in range(ints.shape[0] - 1, -1, -1):
        if Jc.shape[1] > 0:
            m, hx, hy, hz = Ic[i, 0], Ic[i, 1], Ic[i, 2], Ic[i, 3]
            for k in range(ints[i, IV], ints[i, IV] + ints[i, NDOF]):
                wx, wy, wz = oS[k, 3], oS[k, 4], oS[k, 5]
                Jc[0, k] = m * oS[k, 0] + wy * hz - wz * hy
                Jc[1, k] = m * oS[k, 1] + wz * hx - wx * hz
                Jc[2, k] = m * oS[k, 2] + wx * hy - wy * hx
        par = ints[i, PARENT]
        if par >= 0:
            for r in range(4):
                Ic[par, r] += Ic[i, r]
    mass = 0.0
    c[:] = 0.0
    for i in range(ints.shape[0]):
        if ints[i, PARENT] < 0:
            mass += Ic[i, 0]
            for r in range(3):
                c[r] += Ic[i, 1 + r]
    for r in range(3):
        c[r] /= mass
        for k in range(Jc.shape[1]):
            Jc[r, k] /= mass
    return result_status(check, finite(c) and finite2(Jc))


@inline
def com_at(args, s, ws):
    """The centre of mass and its Jacobian of state ``s`` of a batch."""
    ints, body, dofs, Q, check, C, JC = args
    return com_one(ints, body, dofs, Q[s], check, C[s], JC[s], ws)


_com_batch = batch_kernel(com_at, workspace)


def _run(model, q, check_finite, with_jacobian, what):
    if is_coupled(model):  # the full tree's at E(q); the Jacobian J_full G
        batch, C, JC = _run(model.full, expand_q(model, q), check_finite, with_jacobian, what)
        return batch, C, reduce_columns(model, JC) if with_jacobian else JC
    if model.total_mass <= 0:
        raise ValueError(f"{what}: the model has no mass: its centre of mass is undefined")
    batch, x = _inputs.states(model, q=q)
    k = model.kernel
    Q = _inputs.as_batch(x["q"])
    B = Q.shape[0]
    C, JC = np.empty((B, 3)), np.zeros((B, 3, model.nv if with_jacobian else 0))
    status = np.empty(B, dtype=np.int64)
    _com_batch.run((k.ints, k.body, k.dofs[(False, False)], Q, check_finite, C, JC), (model.nbodies, model.nv),
                   status, batch)
    raise_for_status(model, status, x, what)
    return batch, C, JC


def center_of_mass(model, q, *, check_finite: bool = True) -> np.ndarray:
    """World position of the centre of mass of all bodies: (..., 3) for q (..., nq)."""
    if any_lazy(q):
        return deferred(center_of_mass, locals())
    batch, C, _ = _run(model, q, check_finite, False, "center_of_mass")
    return C[0] if batch == () else C.reshape(batch + (3,))


def com_jacobian(model, q, *, check_finite: bool = True) -> np.ndarray:
    """Jacobian of the centre of mass, (..., 3, nv): ``J_com v`` is its world-frame velocity."""
    if any_lazy(q):
        return deferred(com_jacobian, locals())
    batch, _, JC = _run(model, q, check_finite, True, "com_jacobian")
    return JC[0] if batch == () else JC.reshape(batch + JC.shape[1:])
