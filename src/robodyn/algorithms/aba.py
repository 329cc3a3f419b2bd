"""Forward dynamics by the Articulated-Body Algorithm (RBDA Table 7.1), O(n).

    a = (M(q) + armature)^-1 (tau - C(q, v) v - g(q) - friction(v) + sum_i J_i^T f_ext_i)

Pass 1 (root to leaves), in body coordinates: ``v_i = iX_p v_p + S_i qd_i``,
``c_i = v_i x S_i qd_i``, ``IA_i = I_i``, ``pA_i = v_i x* I_i v_i - f_ext_i``.

Pass 2 (leaves to root): ``U_i = IA_i S_i``, ``D_i = S_i^T U_i (+ armature)``,
``u_i = tau_i - S_i^T pA_i (- friction)``; the articulated inertia
``Ia = IA_i - U_i D_i^-1 U_i^T`` and bias ``pa = pA_i + Ia c_i + U_i D_i^-1 u_i`` are added to
the parent: ``IA_p += iX_p^T Ia iX_p``, ``pA_p += iX_p^T pa``.

Pass 3 (root to leaves), with ``a_0 = -g``: ``a_i' = iX_p a_p + c_i``,
``qdd_i = D_i^-1 (u_i - U_i^T a_i')``, ``a_i = a_i' + S_i qdd_i``.

Body coordinates rather than world coordinates: in world coordinates a light body far from
the origin has a rotational inertia dominated by ``m |p|^2``, and ``D_i`` then loses digits
to cancellation (measured on the iCub hands: 10-100x larger errors than in body coordinates).

A body whose ``D_i`` is singular (a massless leaf, a point mass on its joint axis) makes the
forward dynamics undefined: ``aba`` raises ``ValueError`` naming it.

The recursion is written once, as the hybrid dynamics (:func:`hybrid_one`, RBDA section 9.2,
used by ``hybrid.py``): the ABA is its case with no joint of known acceleration.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, prange

from .._jit import MODEL_INTS, MODEL_PACKED, VEC, core, fast, inline, kernel, parallel
from ..joint_kernels import body_placement, friction_torque
from ..spatial import (congruence_to_parent, force_act, force_cross, inertia_matrix, inertia_mul, matvec6,
                       motion_act_inv, motion_cross, wrench_to_local)
from . import _inputs
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, take
from ._inputs import BAD_QUATERNION, NONFINITE, OK, WRONG_SIZE, finite, nq_of, result_status, unpack
from .kinematics import world_placement

# D_i is singular when a pivot is below this fraction of the body's articulated inertia scale.
SINGULAR_RTOL = 1e-12


@kernel
def workspace(nb, nv):
    """Scratch of :func:`hybrid_state`: ``(buffer, (liR, lip, oR, op, Rj, pj), vel, c, IA, pA, acc, U,
    Dinv, u, UD, G, B3, PB, Ia, t1, t2, tau, known)``; ``tau`` receives :func:`aba_one`'s copy
    of the joint forces and ``known`` is all False (no joint of known acceleration)."""
    buf = np.empty((POSES_SIZE_NB + 60) * nb + 14 * nv + POSES_SIZE + 192)
    P, o = poses(buf, 0, nb)
    vel, o = take(buf, o, (nb, 6))
    c, o = take(buf, o, (nb, 6))
    IA, o = take(buf, o, (nb, 6, 6))
    pA, o = take(buf, o, (nb, 6))
    acc, o = take(buf, o, (nb, 6))
    U, o = take(buf, o, (nv, 6))
    Dinv, o = take(buf, o, (nv, 6))
    u, o = take(buf, o, (nv,))
    UD, o = take(buf, o, (6, 6))
    G, o = take(buf, o, (6, 12))
    B3, o = take(buf, o, (3, 3, 3))
    PB, o = take(buf, o, (3, 3))
    Ia, o = take(buf, o, (6, 6))
    t1, o = take(buf, o, (6,))
    t2, o = take(buf, o, (6,))
    tau, o = take(buf, o, (nv,))
    return buf, P, vel, c, IA, pA, acc, U, Dinv, u, UD, G, B3, PB, Ia, t1, t2, tau, np.zeros(nv, dtype=np.bool_)


@inline
def invert_block(Dinv, iv, n, G, tol):
    """Invert the n x n block ``Dinv[iv:iv+n, :n]`` in place (Gauss-Jordan, partial pivoting).

    Returns False when a pivot is not above ``tol``.
    """
    for r in range(n):
        for c in range(n):
            G[r, c] = Dinv[iv + r, c]
            G[r, n + c] = 1.0 if r == c else 0.0
    for col in range(n):
        piv, best = col, abs(G[col, col])
        for r in range(col + 1, n):
            if abs(G[r, col]) > best:
                piv, best = r, abs(G[r, col])
        if best <= tol:  # (NaN input with check_finite=False propagates instead)
            return False
        if piv != col:
            for c in range(2 * n):
                G[col, c], G[piv, c] = G[piv, c], G[col, c]
        inv = 1.0 / G[col, col]
        for c in range(2 * n):
            G[col, c] *= inv
        for r in range(n):
            if r != col:
                fac = G[r, col]
                if fac != 0.0:
                    for c in range(2 * n):
                        G[r, c] -= fac * G[col, c]
    for r in range(n):
        for c in range(n):
            Dinv[iv + r, c] = G[r, n + c]
    return True


@inline
def joint_inertia(IA_i, S, dofs, iv, n, U, Dinv, G):
    """``U_k = IA_i S_k`` (rows ``iv..iv+n`` of ``U``) and ``D^-1 = (S^T IA_i S + armature)^-1``
    (rows ``iv..iv+n`` of ``Dinv``) for one joint, with ``S_k = S[k, :6]`` in the frame of
    ``IA_i`` and the armature in ``dofs[k, 6]``. Returns False when ``D`` is singular: a pivot
    below ``SINGULAR_RTOL`` times the scale of ``IA_i`` (NaN input propagates)."""
    scale = 0.0
    for r in range(6):
        scale += abs(IA_i[r, r])
    for k in range(iv, iv + n):
        matvec6(IA_i, S[k, :6], U[k])
        for j in range(iv, iv + n):
            d = 0.0
            for r in range(6):
                d += S[j, r] * U[k, r]
            Dinv[j, k - iv] = d + (dofs[k, 6] if j == k else 0.0)
    if n == 1:  # the common case: D is a scalar
        if abs(Dinv[iv, 0]) <= SINGULAR_RTOL * scale:
            return False
        Dinv[iv, 0] = 1.0 / Dinv[iv, 0]
        return True
    return invert_block(Dinv, iv, n, G, SINGULAR_RTOL * scale)


@inline
def articulated_inertia(IA_i, U, Dinv, iv, n, UD, Ia):
    """``UD = U D^-1`` (6 x n) and the inertia passed to the parent, ``Ia = IA_i - UD U^T``."""
    for r in range(6):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += U[iv + k, r] * Dinv[iv + k, j]
            UD[r, j] = s
    for r in range(6):
        for cc in range(6):
            s = IA_i[r, cc]
            for j in range(n):
                s -= UD[r, j] * U[iv + j, cc]
            Ia[r, cc] = s


@inline
def joint_acceleration(S, U, Dinv, u, iv, n, acc_i, qdd, t):
    """``qdd = D^-1 (u - U^T a_i)`` for one joint, then ``a_i += S qdd`` (``t`` (6,) scratch)."""
    for k in range(iv, iv + n):
        s = 0.0
        for r in range(6):
            s += U[k, r] * acc_i[r]
        t[k - iv] = u[k] - s
    for j in range(iv, iv + n):
        s = 0.0
        for k in range(n):
            s += Dinv[j, k] * t[k]
        qdd[j] = s
    for k in range(iv, iv + n):
        for r in range(6):
            acc_i[r] += S[k, r] * qdd[k]


@inline
def articulate_single_dof(IA_i, S, armature, c_i, pA_i, tau_f, iv, U_k, Dinv, u, t, Ia, pa):
    """Pass 2 of the ABA for a joint of one dof ``iv`` (the common case, written out):
    ``U = IA_i S``, ``D = S^T U + armature``, ``u = tau_f - S^T pA_i`` (``tau_f``: the joint
    force less friction), the inertia passed to the parent ``Ia = IA_i - U U^T / D``
    (symmetric by construction) and the bias force ``pa = pA_i + IA_i c_i + U (u - U^T c_i) / D``
    (``= pA_i + Ia c_i + U u / D``). ``t`` (6,) is scratch. Returns False when ``D`` is
    singular (see :func:`joint_inertia`)."""
    s0, s1, s2, s3, s4, s5 = S[0], S[1], S[2], S[3], S[4], S[5]
    c0, c1, c2, c3, c4, c5 = c_i[0], c_i[1], c_i[2], c_i[3], c_i[4], c_i[5]
    D, Uc, scale = armature, 0.0, 0.0
    for r in range(6):
        a0, a1, a2, a3, a4, a5 = IA_i[r, 0], IA_i[r, 1], IA_i[r, 2], IA_i[r, 3], IA_i[r, 4], IA_i[r, 5]
        ur = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3 + a4 * s4 + a5 * s5
        U_k[r] = ur
        t[r] = a0 * c0 + a1 * c1 + a2 * c2 + a3 * c3 + a4 * c4 + a5 * c5
        D += S[r] * ur
        Uc += ur * c_i[r]
        scale += abs(IA_i[r, r])
    if abs(D) <= SINGULAR_RTOL * scale:
        return False
    dinv = 1.0 / D
    Dinv[iv, 0] = dinv
    uk = tau_f - (s0 * pA_i[0] + s1 * pA_i[1] + s2 * pA_i[2] + s3 * pA_i[3] + s4 * pA_i[4] + s5 * pA_i[5])
    u[iv] = uk
    uh = (uk - Uc) * dinv
    for r in range(6):
        pa[r] = pA_i[r] + t[r] + U_k[r] * uh
        ud = U_k[r] * dinv
        for cc in range(r, 6):
            x = IA_i[r, cc] - ud * U_k[cc]
            Ia[r, cc] = x
            Ia[cc, r] = x
    return True


@inline
def finite_where(x, mask, value):
    """True when ``x[k]`` is finite for every ``k`` with ``mask[k] == value``."""
    for k in range(x.shape[0]):
        if mask[k] == value and not np.isfinite(x[k]):
            return False
    return True


@inline
def hybrid_state(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws):
    """Hybrid dynamics of one state into ``qdd`` and ``tau`` (nv,) (RBDA section 9.2, see
    ``hybrid.py``). ``known[k]``: the acceleration of dof ``k`` is given (all dofs of a joint
    alike); with no dof known this is the ABA. Returns a status (see
    ``_inputs``): ``i + 1`` when the articulated inertia of body ``i`` is singular. Inlined
    into :func:`hybrid_one` (one state) and :func:`aba_range` (a batch loop).

    Spatial quantities are in body coordinates (RBDA Table 7.1), where the articulated
    inertias keep the size of the bodies whatever their distance from the world origin."""
    (_, (liR, lip, oR, op, Rj, pj), vel, c, IA, pA, acc, U, Dinv, u, UD, G, B3, PB, Ia, t1, t2,
     _, _) = ws
    nb, nv = ints.shape[0], dofs.shape[0]
    if not (q.shape[0] == nq_of(ints) and v.shape[0] == nv and qdd_known.shape[0] == nv
            and tau_known.shape[0] == nv and known.shape[0] == nv):
        return WRONG_SIZE
    if check and not (finite(q) and finite(v) and finite_where(qdd_known, known, True)
                      and finite_where(tau_known, known, False)):
        return NONFINITE
    eps = params[3]
    # Pass 1: placements, velocities, velocity-product accelerations (with the known joint
    # accelerations), rigid-body inertias and bias forces
    for i in range(nb):
        par, iv, n = ints[i, 0], ints[i, 3], ints[i, 4]
        if not body_placement(ints[i, 1], body[i], q, ints[i, 2], liR[i], lip[i], Rj):
            return BAD_QUATERNION
        if fcode > 0:
            world_placement(i, par, liR, lip, oR, op)
        if par >= 0:
            motion_act_inv(liR[i], lip[i], vel[par], vel[i])
        else:
            vel[i, :] = 0.0
        for r in range(6):
            t1[r] = 0.0
        for k in range(iv, iv + n):
            for r in range(6):
                t1[r] += dofs[k, r] * v[k]
        for r in range(6):
            vel[i, r] += t1[r]
        motion_cross(vel[i], t1, c[i])
        if known[iv]:
            for k in range(iv, iv + n):
                for r in range(6):
                    c[i, r] += dofs[k, r] * qdd_known[k]
        theta = body[i, 15:25]
        inertia_matrix(theta, IA[i])
        inertia_mul(theta, vel[i], t1)
        force_cross(vel[i], t1, pA[i])
        if fcode >= 0:
            wrench_to_local(fcode, oR[i], op[i], fext[i], t1)
            for r in range(6):
                pA[i, r] -= t1[r]
    # Pass 2: articulated inertias, the joints of known acceleration held rigid; each body
    # passes Ia and pa to its parent: IA_p += iX_p^T Ia iX_p, pA_p += iX_p^T pa
    for i in range(nb - 1, -1, -1):
        par, iv, n = ints[i, 0], ints[i, 3], ints[i, 4]
        if known[iv]:
            matvec6(IA[i], c[i], t1)
            for r in range(6):
                t2[r] = pA[i, r] + t1[r]
                for cc in range(6):
                    Ia[r, cc] = IA[i, r, cc]
        elif n == 1:
            if not articulate_single_dof(IA[i], dofs[iv], dofs[iv, 6], c[i], pA[i],
                                         tau_known[iv] - friction_torque(dofs, eps, v, iv),
                                         iv, U[iv], Dinv, u, t1, Ia, t2):
                return i + 1
        else:
            for k in range(iv, iv + n):
                s = 0.0
                for r in range(6):
                    s += dofs[k, r] * pA[i, r]
                u[k] = tau_known[k] - s - friction_torque(dofs, eps, v, k)
            if not joint_inertia(IA[i], dofs, dofs, iv, n, U, Dinv, G):
                return i + 1
            if par < 0:
                continue
            articulated_inertia(IA[i], U, Dinv, iv, n, UD, Ia)
            matvec6(Ia, c[i], t1)
            for r in range(6):
                s = pA[i, r] + t1[r]
                for j in range(n):
                    s += UD[r, j] * u[iv + j]
                t2[r] = s
        if par >= 0:
            congruence_to_parent(liR[i], lip[i], Ia, B3, PB, IA[par])
            force_act(liR[i], lip[i], t2, t1)
            for r in range(6):
                pA[par, r] += t1[r]
    # Pass 3: accelerations of the joints of unknown acceleration, forces of the others
    for k in range(6):
        t2[k] = 0.0
    t2[0], t2[1], t2[2] = -params[0], -params[1], -params[2]
    for i in range(nb):
        par, iv, n = ints[i, 0], ints[i, 3], ints[i, 4]
        motion_act_inv(liR[i], lip[i], acc[par] if par >= 0 else t2, acc[i])
        for r in range(6):
            acc[i, r] += c[i, r]
        if known[iv]:
            matvec6(IA[i], acc[i], t1)
            for r in range(6):
                t1[r] += pA[i, r]
            for k in range(iv, iv + n):
                qdd[k] = qdd_known[k]
                s = 0.0
                for r in range(6):
                    s += dofs[k, r] * t1[r]
                tau[k] = s + dofs[k, 6] * qdd_known[k] + friction_torque(dofs, eps, v, k)
            continue
        if n == 1:
            s = 0.0
            for r in range(6):
                s += U[iv, r] * acc[i, r]
            qdd[iv] = Dinv[iv, 0] * (u[iv] - s)
            for r in range(6):
                acc[i, r] += dofs[iv, r] * qdd[iv]
        else:
            joint_acceleration(dofs, U, Dinv, u, iv, n, acc[i], qdd, t1)
        for k in range(iv, iv + n):
            tau[k] = tau_known[k]
    return result_status(check, finite(qdd) and finite(tau))


@core
def hybrid_one(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws):
    """:func:`hybrid_state` of one state (the compiled function other kernels call)."""
    return hybrid_state(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws)


@core
def aba_one(ints, body, dofs, params, q, v, tau, fext, fcode, check, qdd, ws):
    """Forward dynamics of one state into ``qdd`` (nv,): :func:`hybrid_one` with no joint of
    known acceleration (``ws[18]`` is all False; ``ws[17]`` receives the copy of ``tau``).
    Returns a status (see ``_inputs``): ``i + 1`` when the articulated inertia of body ``i``
    is singular."""
    return hybrid_one(ints, body, dofs, params, q, v, qdd, tau, ws[18], fext, fcode, check, qdd, ws[17], ws)


@core
def aba_range(ints, body, dofs, params, Q, V, T, F, fcode, check, QDD, status, lo, hi, ws):
    """The forward dynamics of the states ``lo <= s < hi`` of a batch (see :func:`aba_one`)."""
    for s in range(lo, hi):
        status[s] = hybrid_state(ints, body, dofs, params, Q[s], V[s], QDD[s], T[s], ws[18],
                                 F[s if F.shape[0] > 1 else 0], fcode, check, QDD[s], ws[17], ws)


@parallel
def _aba_batch(ints, body, dofs, params, Q, V, T, F, fcode, check, QDD, status, nchunk):
    B = Q.shape[0]
    for c in prange(nchunk):
        aba_range(ints, body, dofs, params, Q, V, T, F, fcode, check, QDD, status, c * B // nchunk,
                  (c + 1) * B // nchunk, workspace(ints.shape[0], dofs.shape[0]))


@kernel
def _aba_single(ints, body, dofs, params, q, v, tau, fext, fcode, check, qdd):
    return aba_one(ints, body, dofs, params, q, v, tau, fext, fcode, check, qdd,
                   workspace(ints.shape[0], dofs.shape[0]))


@fast(MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, boolean, VEC)
def _aba_packed(ints, packed, q, v, tau, check, qdd):
    """One state without external wrenches, the model in one array (the fast path)."""
    body, dofs, params, zero = unpack(ints, packed)
    return aba_one(ints, body, dofs, params, q, v, tau, zero, -1, check, qdd, workspace(ints.shape[0], dofs.shape[0]))


def aba(model, q, v, tau, f_ext=None, f_ext_frame: str = "local", *, friction: bool = True,
        armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """Forward dynamics: the acceleration produced by joint forces ``tau`` at ``(q, v)``.

    ``a = (M(q) + armature)^-1 (tau - C(q, v) v - g(q) - friction(v) + sum_i J_i^T f_ext_i)``

    Args:
        q: (..., nq). v, tau: (..., nv). f_ext, f_ext_frame, friction, armature,
        check_finite: as in :func:`robodyn.rnea`.

    Returns:
        a: (..., nv), the inverse of :func:`robodyn.rnea`: ``aba(q, v, rnea(q, v, a)) == a``.

    Raises ValueError when a body's articulated inertia is singular (e.g. a chain of massless
    leaf bodies): the forward dynamics is undefined there. Reference: RBDA Table 7.1.
    """
    k = model._kernel
    if f_ext is None and f_ext_frame in _inputs.WRENCH_FRAMES:
        qdd = np.empty(model.nv)  # fast path for one state: the kernel checks sizes and values
        try:
            if _aba_packed(k["ints"], k["packed"][friction, armature], q, v, tau, check_finite, qdd) == OK:
                return qdd
        except (TypeError, KeyError):  # not contiguous float64 vectors (or options not bool)
            pass
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, f_ext_frame)
    dofs, params = k["dofs"][(bool(friction), bool(armature))], k["params"][True]
    if batch == ():
        qdd = np.empty(model.nv)
        status = _aba_single(k["ints"], k["body"], dofs, params, x["q"], x["v"], x["tau"], F, fcode, check_finite, qdd)
    else:
        B = x["q"].shape[0]
        qdd, status = np.empty((B, model.nv)), np.empty(B, dtype=np.int64)
        _aba_batch(k["ints"], k["body"], dofs, params, x["q"], x["v"], x["tau"], F, fcode, check_finite, qdd, status,
                   _inputs.chunks(B))
    bad = _inputs.raise_for_status(model, status, x, "aba")
    if bad:
        i = bad - 1
        raise ValueError(
            f"aba: the articulated inertia of body {i} ({model.link_names[i]!r}, joint "
            f"{model.body_joint_names[i]!r}) is singular, so the forward dynamics is undefined; "
            "give the bodies beyond it mass and inertia about the joint axis (or armature)"
        )
    return _inputs.unflatten(qdd, batch)
