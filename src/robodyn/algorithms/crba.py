"""Joint-space inertia matrix by the Composite-Rigid-Body Algorithm (RBDA Table 6.2).

    M(q) = sum_i J_i^T I_i J_i  (+ diag(armature))

Computed in world coordinates, where composite inertias add without transforms
(``I^c_p += I^c_i``) and every motion-subspace column is the world-frame Jacobian column
``oS_k``:

    M[l, k] = oS_l^T (I^c_i oS_k)   for k a dof of body i and l a dof of i or of an ancestor.

Returns the full symmetric matrix.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..spatial import dot6, inertia_act, inertia_mul
from . import _inputs
from .kinematics import placements, world_motion_subspace, world_placements


@njit(cache=True)
def workspace(nb, nv):
    return (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3, 3)), np.empty((nb, 3)),
            np.empty((3, 3)), np.empty(3), np.empty((nv, 6)), np.empty((nb, 10)), np.empty(6))


@njit(cache=True, inline="always")
def world_inertias(ints, body, oR, op, Ic):
    """``Ic[i]``: inertial parameters of body ``i`` in world coordinates."""
    for i in range(ints.shape[0]):
        inertia_act(oR[i], op[i], body[i, 15:25], Ic[i])


@njit(cache=True)
def crba_one(ints, body, S, dof, q, M, ws):
    liR, lip, oR, op, Rj, pj, oS, Ic, F = ws
    placements(ints, body, q, liR, lip, Rj, pj)
    world_placements(ints, liR, lip, oR, op)
    world_motion_subspace(ints, S, oR, op, oS)
    world_inertias(ints, body, oR, op, Ic)
    M[:, :] = 0.0
    for i in range(ints.shape[0] - 1, -1, -1):
        par, iv, n = ints[i, 0], ints[i, 3], ints[i, 4]
        for k in range(iv, iv + n):
            inertia_mul(Ic[i], oS[k], F)
            j = i
            while j >= 0:
                for l in range(ints[j, 3], ints[j, 3] + ints[j, 4]):
                    val = dot6(oS[l], F)
                    M[l, k] = val
                    M[k, l] = val
                j = ints[j, 0]
            M[k, k] += dof[k, 0]
        if par >= 0:
            for r in range(10):
                Ic[par, r] += Ic[i, r]


@njit(cache=True, parallel=True)
def _crba_batch(ints, body, S, dof, Q, MM, nchunk):
    B = Q.shape[0]
    for c in prange(nchunk):
        ws = workspace(ints.shape[0], S.shape[0])
        for s in range(c * B // nchunk, (c + 1) * B // nchunk):
            crba_one(ints, body, S, dof, Q[s], MM[s], ws)


@njit(cache=True)
def _crba_single(ints, body, S, dof, q, M):
    crba_one(ints, body, S, dof, q, M, workspace(ints.shape[0], S.shape[0]))


def crba(model, q, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Joint-space inertia (mass) matrix ``M(q)``, full and symmetric.

    q: (..., nq). Returns (..., nv, nv). ``armature=True`` adds the model's reflected rotor
    inertias on the diagonal (as :func:`robodyn.rnea` and :func:`robodyn.aba` do).

    Equivalence: column ``j`` equals ``rnea(q, 0, e_j) - gravity(q)``; ``v^T M v / 2`` is the
    kinetic energy. Reference: RBDA Table 6.2 (composite-rigid-body algorithm).
    """
    batch, flat = _inputs.states(model, check_finite, q=q)
    ints, body, S, _ = model._kernel
    dof = model._dof(False, armature)
    Q = flat["q"]
    B = Q.shape[0]
    MM = np.empty((B, model.nv, model.nv))
    nchunk = _inputs.chunks(B)
    if nchunk:
        _crba_batch(ints, body, S, dof, Q, MM, nchunk)
    else:
        _crba_single(ints, body, S, dof, Q[0], MM[0])
    return _inputs.unflatten(MM, batch)
