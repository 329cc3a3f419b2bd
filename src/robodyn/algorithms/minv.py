"""Inverse of the joint-space inertia matrix by the articulated-body algorithm, O(n^2).

``M(q)^-1`` is the forward dynamics of unit joint forces without velocity and gravity: its
column ``k`` is ``aba(q, 0, e_k)`` with ``g = 0``. The ABA runs once on all ``nv`` columns at
once (Carpentier and Mansard 2018; RBDA section 7.3), the bias forces and
accelerations becoming 6 x nv matrices:

Pass 2 (leaves to root), with ``F_i = 0`` (6, nv) at the start:
``U_i = IA_i S_i``, ``D_i = S_i^T U_i (+ armature)``, ``u_i = E_i - S_i^T F_i`` (``E_i`` the rows
of the identity of the joint's dofs), ``IA_p += iX_p^T (IA_i - U_i D_i^-1 U_i^T) iX_p``,
``F_p += iX_p^T (F_i + U_i D_i^-1 u_i)``.

Pass 3 (root to leaves), with ``A_0 = 0``: ``A_i' = iX_p A_p``,
``Minv[dofs of i, :] = D_i^-1 (u_i - U_i^T A_i')``, ``A_i = A_i' + S_i Minv[dofs of i, :]``.

Bodies are numbered after their ancestors, so the dofs of a body's subtree all come at or
after its own first dof ``k_i``, before the end ``e_i`` of its subtree's dofs (``ints[i, SUBTREE_END]``):
``F_i`` and ``u_i`` are zero outside the columns ``k_i <= col < e_i`` (a unit force outside
the subtree does not reach it in pass 2), where pass 2 runs. Pass 3 computes the upper
triangle (columns ``>= k_i`` of the rows of body ``i``), then mirrors it. The column loops of a
body with a parent and a joint of one dof hold the joint's vectors in registers
(:func:`bias_forces_one_dof`, :func:`accelerations_one_dof`); joints of several dofs (a
spherical joint anywhere, a free joint at a root) take general loops.

Coordinates: as in the ABA (``aba.py``), each body's quantities are expressed at its origin
with the world's axes, so that ``iX_p`` is a pure shift by the vector ``d_i`` between the
origins (:func:`robodyn.spatial.congruence_shift`, ``unshifted_force``, ``shifted_motion``).

Reference: J. Carpentier and N. Mansard, "Analytical derivatives of rigid body dynamics
algorithms", Robotics: Science and Systems, 2018; Featherstone, RBDA (2008), Table 7.1.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._jit import MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, core, fast, inline, scratch
from ..layout import INERTIA, INERTIA_END, IQ, IV, JTYPE, NDOF, PARENT, SUBTREE_END
from ..joint_kernels import local_placement, nq_of
from ..spatial import (congruence_shift, inertia_matrix, inertia_rotated, rotate6, shifted_motion, unshifted_force,
                       upper_triangle)
from ..coupling import is_coupled
from . import coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status, raise_singular
from .status import BAD_QUATERNION, NONFINITE, OK, WRONG_SIZE, finite, finite2, result_status
from ._inputs import matrix_one_state
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, take
from .aba import aligned_placement, articulated_inertia, joint_acceleration, joint_inertia
from .driver import batch_kernel


@scratch
def workspace(nb, nv):
    """Scratch of :func:`minv_one`, carved from one buffer: ``(buffer, liR, lip, oR, op, d, Rj,
    IA, S, U, Dinv, F, UD, G, Ia, t1, t2)``; ``F[i, col]`` is column ``col`` of body ``i``'s
    6 x nv matrix ``F_i``."""
    buf = np.empty((POSES_SIZE_NB + 39 + 6 * nv) * nb + 18 * nv + POSES_SIZE + 156)
    (liR, lip, oR, op, Rj, _), o = poses(buf, 0, nb)
    d, o = take(buf, o, (nb, 3))
    IA, o = take(buf, o, (nb, 6, 6))
    S, o = take(buf, o, (nv, 6))
    U, o = take(buf, o, (nv, 6))
    Dinv, o = take(buf, o, (nv, 6))
    F, o = take(buf, o, (nb, nv, 6))
    UD, o = take(buf, o, (6, 6))
    G, o = take(buf, o, (6, 12))
    Ia, o = take(buf, o, (6, 6))
    t1, o = take(buf, o, (6,))
    t2, o = take(buf, o, (6,))
    return buf, liR, lip, oR, op, d, Rj, IA, S, U, Dinv, F, UD, G, Ia, t1, t2


@inline
def add_unshifted(shift, f, p):
    """``p += iX_p^T f``: the force ``f`` (a 6-tuple) moved by ``shift`` to the parent's origin."""
    f0, f1, f2, n0, n1, n2 = unshifted_force(shift, f)
    p[0] += f0
    p[1] += f1
    p[2] += f2
    p[3] += n0
    p[4] += n1
    p[5] += n2


@inline
def bias_forces_one_dof(k, end, d, S, UD, F_i, F_p, Minv):
    """Pass 2 of a body whose joint has the one dof ``k`` (every body but a root), with the
    joint's vectors and the shift held in registers (read from the workspace, which every
    store into ``F`` may alias, they would be reloaded per column): for the columns
    ``k <= col < end``, ``u = e_k - S^T F_i``, then ``F_p += iX_p^T (F_i + U D^-1 u)``."""
    s0, s1, s2, s3, s4, s5 = S[k, 0], S[k, 1], S[k, 2], S[k, 3], S[k, 4], S[k, 5]
    g0, g1, g2, g3, g4, g5 = UD[0, 0], UD[1, 0], UD[2, 0], UD[3, 0], UD[4, 0], UD[5, 0]
    shift = (d[0], d[1], d[2])
    for col in range(k, end):
        f = F_i[col]
        u = (1.0 if col == k else 0.0) - (s0 * f[0] + s1 * f[1] + s2 * f[2] + s3 * f[3] + s4 * f[4] + s5 * f[5])
        Minv[k, col] = u
        add_unshifted(shift, (f[0] + g0 * u, f[1] + g1 * u, f[2] + g2 * u, f[3] + g3 * u, f[4] + g4 * u,
                              f[5] + g5 * u), F_p[col])


@inline
def accelerations_one_dof(k, d, S, U, dinv, F_p, F_i, Minv):
    """Pass 3 of a body whose joint has the one dof ``k`` (vectors in registers, as in
    :func:`bias_forces_one_dof`): for the columns ``col >= k``, ``A' = iX_p A_p``,
    ``Minv[k, col] = D^-1 (u - U^T A')``, ``A_i = A' + S Minv[k, col]``."""
    s0, s1, s2, s3, s4, s5 = S[k, 0], S[k, 1], S[k, 2], S[k, 3], S[k, 4], S[k, 5]
    u0, u1, u2, u3, u4, u5 = U[k, 0], U[k, 1], U[k, 2], U[k, 3], U[k, 4], U[k, 5]
    shift = (d[0], d[1], d[2])
    for col in range(k, Minv.shape[1]):
        v0, v1, v2, w0, w1, w2 = shifted_motion(shift, F_p[col])
        m = dinv * (Minv[k, col] - (u0 * v0 + u1 * v1 + u2 * v2 + u3 * w0 + u4 * w1 + u5 * w2))
        Minv[k, col] = m
        b = F_i[col]
        b[0], b[1], b[2] = v0 + s0 * m, v1 + s1 * m, v2 + s2 * m
        b[3], b[4], b[5] = w0 + s3 * m, w1 + s4 * m, w2 + s5 * m


@inline
def bias_forces_dofs(iv, n, end, d, S, UD, F_i, F_p, Minv, t):
    """Pass 2 of a body with a parent whose joint has the ``n`` dofs ``iv..iv+n`` (a spherical
    joint): as :func:`bias_forces_one_dof`, ``u = E - S^T F_i`` in the rows of the joint's dofs
    and ``F_p += iX_p^T (F_i + U D^-1 u)`` (``t`` (6,) scratch)."""
    shift = (d[0], d[1], d[2])
    for col in range(iv, end):
        f = F_i[col]
        for r in range(6):
            t[r] = f[r]
        for j in range(n):
            k = iv + j
            u = 1.0 if col == k else 0.0
            for r in range(6):
                u -= S[k, r] * f[r]
            Minv[k, col] = u
            for r in range(6):
                t[r] += UD[r, j] * u
        add_unshifted(shift, (t[0], t[1], t[2], t[3], t[4], t[5]), F_p[col])


@inline
def accelerations_dofs(iv, n, d, S, U, Dinv, F_p, F_i, Minv, t):
    """Pass 3 of a body with a parent whose joint has ``n`` dofs: for the columns ``col >= iv``,
    ``A' = iX_p A_p``, ``Minv[dofs, col] = D^-1 (u - U^T A')``, ``A_i = A' + S Minv[dofs, col]``."""
    shift = (d[0], d[1], d[2])
    for col in range(iv, Minv.shape[1]):
        b = F_i[col]
        b[0], b[1], b[2], b[3], b[4], b[5] = shifted_motion(shift, F_p[col])
        column = Minv[:, col]
        joint_acceleration(S, U, Dinv, column, iv, n, b, column, t)


@core
def minv_one(ints, body, dofs, q, check, Minv, ws):
    """``Minv`` (nv, nv) at ``q``; returns a status (see ``_inputs``), ``i + 1`` when the
    articulated inertia of body ``i`` is singular."""
    _, _, _, oR, op, d, Rj, IA, S, U, Dinv, F, UD, G, Ia, t1, t2 = ws
    nb, nv = ints.shape[0], dofs.shape[0]
    if q.shape[0] != nq_of(ints):
        return WRONG_SIZE
    if check and not finite(q):
        return NONFINITE
    # Pass 1: placements, motion subspaces S[k] and rigid-body inertias in world axes
    for i in range(nb):
        ok, Rl, pl = local_placement(ints[i, JTYPE], body[i], q, ints[i, IQ], Rj)
        if not ok:
            return BAD_QUATERNION
        aligned_placement(i, ints[i, PARENT], Rl, pl, oR, op, d)
        for k in range(ints[i, IV], ints[i, IV] + ints[i, NDOF]):
            rotate6(oR[i], dofs[k], S[k])
        inertia_matrix(inertia_rotated(oR[i], body[i, INERTIA:INERTIA_END]), IA[i], True)
        F[i, ints[i, IV]:ints[i, SUBTREE_END], :] = 0.0  # pass 2 uses the columns of the subtree only
    # Pass 2: articulated inertias and the bias forces of the unit joint forces;
    # u_i is kept in the rows of Minv of the joint's dofs until pass 3 replaces it.
    for i in range(nb - 1, -1, -1):
        par, iv, n, end = ints[i, PARENT], ints[i, IV], ints[i, NDOF], ints[i, SUBTREE_END]
        if not joint_inertia(IA[i], S, dofs, iv, n, U, Dinv, G):
            return i + 1
        for k in range(iv, iv + n):
            Minv[k, end:] = 0.0
        if par >= 0:
            articulated_inertia(IA[i], U, Dinv, iv, n, UD, Ia)
            congruence_shift(d[i], upper_triangle(Ia), IA[par], True)
            if n == 1:
                bias_forces_one_dof(iv, end, d[i], S, UD, F[i], F[par], Minv)
            else:
                bias_forces_dofs(iv, n, end, d[i], S, UD, F[i], F[par], Minv, t1)
            continue
        for k in range(iv, iv + n):  # a root: u_i only
            for col in range(iv, end):
                s = 0.0
                for r in range(6):
                    s += S[k, r] * F[i, col, r]
                Minv[k, col] = (1.0 if col == k else 0.0) - s
    # Pass 3: accelerations of the unit joint forces (F now holds the body accelerations)
    for i in range(nb):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        if par >= 0:
            if n == 1:
                accelerations_one_dof(iv, d[i], S, U, Dinv[iv, 0], F[par], F[i], Minv)
            else:
                accelerations_dofs(iv, n, d[i], S, U, Dinv, F[par], F[i], Minv, t1)
            continue
        for col in range(iv, nv):  # a root: A_i' = 0
            for k in range(n):
                t1[k] = Minv[iv + k, col]
            t2[:] = 0.0
            for j in range(iv, iv + n):
                s = 0.0
                for k in range(n):
                    s += Dinv[j, k] * t1[k]
                Minv[j, col] = s
                for r in range(6):
                    t2[r] += S[j, r] * s
            for r in range(6):
                F[i, col, r] = t2[r]
    for k in range(nv):
        for col in range(k + 1, nv):
            Minv[col, k] = Minv[k, col]
    return result_status(check, finite2(Minv))


@inline
def minv_at(args, s, ws):
    """The inverse mass matrix of state ``s`` of a batch."""
    ints, body, dofs, Q, check, MM = args
    return minv_one(ints, body, dofs, Q[s], check, MM[s], ws)


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, MAT, boolean, TENSOR), (int64, int64))
_minv_batch = batch_kernel(minv_at, workspace, one_state=ONE_STATE)
_minv_call_one = _minv_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, boolean, MAT)
def _minv_packed(address, ints, packed, q, check, Minv):
    """One state, the model in one array (the fast path): the batch's code at ``address``
    (``_minv_batch.one_address``) for a batch of one."""
    ok, args = matrix_one_state(ints, packed, q, check, Minv)
    return _minv_call_one(address, args, workspace(ints.shape[0], Minv.shape[0])) if ok else WRONG_SIZE


def inverse_mass_matrix(model, q, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Inverse of the joint-space inertia matrix, ``M(q)^-1``, full and symmetric, in O(n^2).

    q: (..., nq). Returns (..., nv, nv). ``armature`` as in :func:`robodyn.crba`: the inverse
    of ``crba(q, armature=armature)``.

    Equivalences: ``inverse_mass_matrix(q) @ crba(q) == I``; column ``k`` is the acceleration
    of a unit force at dof ``k`` without velocity and gravity. Raises ValueError when a body's
    articulated inertia is singular (``M`` is then singular too). Reference: Carpentier and
    Mansard, RSS 2018 (Pinocchio's ``computeMinverse``); RBDA Table 7.1.
    """
    Minv = np.empty((model.nv, model.nv))  # fast path for one state: the kernel checks q
    try:
        k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
        if _minv_packed(_minv_batch.one_address, k.ints, k.packed[False, armature], q, check_finite, Minv) == OK:
            return Minv
    except (TypeError, KeyError, AttributeError):  # not a contiguous float64 vector (or armature not bool)
        pass
    if any_lazy(q):
        return deferred(inverse_mass_matrix, locals())
    if is_coupled(model):  # mimic joints: the inverse of G^T M_full G
        L = coupled.cholesky(coupled.mass_matrix(model, q, armature, check_finite), model, "inverse_mass_matrix")
        return coupled.solve(L, np.broadcast_to(np.eye(model.nv), L.shape))
    k = model.kernel
    batch, x = _inputs.states(model, q=q)
    Minv, result = _inputs.output(None, batch, (model.nv, model.nv), x)
    Q, MI = _inputs.batched(batch, x["q"], Minv)
    status = np.empty(Q.shape[0], dtype=np.int64)
    _minv_batch.run((k.ints, k.body, k.dofs[(False, bool(armature))], Q, check_finite, MI),
                    (model.nbodies, model.nv), status, batch)
    raise_singular(model, raise_for_status(model, status, x, "inverse_mass_matrix"), "inverse_mass_matrix",
                   "so M(q) is singular")
    return result
