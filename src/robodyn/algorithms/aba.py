"""Forward dynamics by the Articulated-Body Algorithm (RBDA Table 7.1), O(n).

    a = (M(q) + armature)^-1 (tau - C(q, v) v - g(q) - friction(v) + sum_i J_i^T f_ext_i)

Pass 1 (root to leaves): ``v_i = iX_p v_p + S_i qd_i``,
``c_i = v_i x S_i qd_i``, ``IA_i = I_i``, ``pA_i = v_i x* I_i v_i - f_ext_i``.

Pass 2 (leaves to root): ``U_i = IA_i S_i``, ``D_i = S_i^T U_i (+ armature)``,
``u_i = tau_i - S_i^T pA_i (- friction)``; the articulated inertia
``Ia = IA_i - U_i D_i^-1 U_i^T`` and bias ``pa = pA_i + Ia c_i + U_i D_i^-1 u_i`` are added to
the parent: ``IA_p += iX_p^T Ia iX_p``, ``pA_p += iX_p^T pa``.

Pass 3 (root to leaves), with ``a_0 = -g``: ``a_i' = iX_p a_p + c_i``,
``qdd_i = D_i^-1 (u_i - U_i^T a_i')``, ``a_i = a_i' + S_i qdd_i``.

Coordinates: each body's quantities are expressed at the body's origin with the world's
axes. A transform between parent and child is then a pure shift by the vector ``d_i``
between their origins, and the inertia passed to the parent costs a third of a rotated one
(:func:`robodyn.spatial.congruence_shift`); the rotation is applied once per body, to its
rigid inertia and motion subspace. World coordinates would save the shifts too, but there a
light body far from the origin has a rotational inertia dominated by ``m |p|^2``, and
``D_i`` loses digits to cancellation (measured on the iCub hands: 10-100x larger errors);
about each body's own origin the inertias keep the size of the bodies.

A body whose ``D_i`` is singular (a massless leaf, a point mass on its joint axis) makes the
forward dynamics undefined: ``aba`` raises ``ValueError`` naming it.

The recursion is written once, as the hybrid dynamics (:func:`hybrid_one`, RBDA section 9.2,
used by ``hybrid.py``): the ABA is its case with no joint of known acceleration.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._deprecated import renamed_keyword
from .._jit import MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, by_address, core, fast, inline, scratch, splice
from ..layout import ARMATURE, GRAVITY, INERTIA, INERTIA_END, IQ, IV, JTYPE, NDOF, PARENT, SMOOTHING, UNIT_AXIS
from ..joint_kernels import local_placement, nq_of, passive_torque
from ..joints import FREE
from ..spatial import (congruence_shift, cross_into, force_cross, inertia_matrix, inertia_rotated, matvec6, mirror_upper,
                       momentum, motion_cross, rotate6, shift_motion, shifted_motion, unshift_force, upper_triangle,
                       wrench_to_aligned)
from ..coupling import is_coupled
from . import coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status, raise_singular
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, take
from ._inputs import one_state
from .status import BAD_QUATERNION, NONFINITE, OK, WRONG_SIZE, finite, result_status
from .driver import batch_kernel

# D_i is singular when a pivot is below this fraction of the body's articulated inertia scale.
SINGULAR_RTOL = 1e-12


@inline
def workspace_views(buf, nb, nv):
    """The scratch arrays of :func:`hybrid_state` carved from ``buf`` (see :func:`workspace`),
    after ``buf`` itself (which an ``inline`` function may not return: see ``_jit``)."""
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
    d, o = take(buf, o, (nb, 3))
    S, o = take(buf, o, (nv, 6))
    Ia, o = take(buf, o, (6, 6))
    t1, o = take(buf, o, (6,))
    t2, o = take(buf, o, (6,))
    tau, o = take(buf, o, (nv,))
    return (P, vel, c, IA, pA, acc, U, Dinv, u, UD, G, d, S, Ia, t1, t2, tau)


@scratch
def buffer(nb, nv):
    """``(buffer, known)``: the memory of :func:`workspace` and its ``known``, the workspace of
    the batch code (which carves the views once per chunk, :func:`aba_views`)."""
    return np.empty((POSES_SIZE_NB + 63) * nb + 20 * nv + POSES_SIZE + 156), np.zeros(nv, dtype=np.bool_)


@scratch
def workspace(nb, nv):
    """Scratch of :func:`hybrid_state`: ``(buffer, (liR, lip, oR, op, Rj, pj), vel, c, IA, pA, acc, U,
    Dinv, u, UD, G, d, S, Ia, t1, t2, tau, known)``; ``tau`` receives :func:`aba_one`'s copy
    of the joint forces and ``known`` is all False (no joint of known acceleration)."""
    buf, known = buffer(nb, nv)
    return (buf,) + workspace_views(buf, nb, nv) + (known,)


@inline
def pivot(G, col, n, lo, hi, tol):
    """Partial pivoting of column ``col`` of ``G[:n]``: swap in (columns ``lo..hi``) the row
    below ``col`` of largest magnitude. Returns False when that magnitude is not above
    ``tol`` (NaN input with check_finite=False propagates instead)."""
    piv, best = col, abs(G[col, col])
    for r in range(col + 1, n):
        if abs(G[r, col]) > best:
            piv, best = r, abs(G[r, col])
    if best <= tol:
        return False
    if piv != col:
        for c in range(lo, hi):
            G[col, c], G[piv, c] = G[piv, c], G[col, c]
    return True


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
        if not pivot(G, col, n, 0, 2 * n, tol):
            return False
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
def solve_block(A, y, n, G, x, tol):
    """``x = A^-1 y`` for the n x n block ``A[:n, :n]`` (Gaussian elimination with partial
    pivoting on ``G[:n, :n + 1]``). Returns False when a pivot is not above ``tol``."""
    for r in range(n):
        for cc in range(n):
            G[r, cc] = A[r, cc]
        G[r, n] = y[r]
    for col in range(n):
        if not pivot(G, col, n, col, n + 1, tol):
            return False
        inv = 1.0 / G[col, col]
        for r in range(col + 1, n):
            fac = G[r, col] * inv
            for cc in range(col + 1, n + 1):
                G[r, cc] -= fac * G[col, cc]
    for r in range(n - 1, -1, -1):
        s = G[r, n]
        for cc in range(r + 1, n):
            s -= G[r, cc] * x[cc]
        x[r] = s / G[r, r]
    return True


@inline
def free_root(ints, dofs, i):
    """True when body ``i`` is a root on a free joint without armature: its joint's
    ``D = S^T IA S`` needs no inverse (see :func:`hybrid_state`, pass 3)."""
    if ints[i, PARENT] >= 0 or ints[i, JTYPE] != FREE:
        return False
    iv = ints[i, IV]
    for k in range(iv, iv + 6):
        if dofs[k, ARMATURE] != 0.0:
            return False
    return True


@inline
def inertia_scale(IA_i):
    """``sum_r |IA_i[r, r]|``, the size a singular pivot is measured against."""
    scale = 0.0
    for r in range(6):
        scale += abs(IA_i[r, r])
    return scale


@inline
def joint_inertia(IA_i, S, dofs, iv, n, U, Dinv, G):
    """``U_k = IA_i S_k`` (rows ``iv..iv+n`` of ``U``) and ``D^-1 = (S^T IA_i S + armature)^-1``
    (rows ``iv..iv+n`` of ``Dinv``) for one joint, with ``S_k = S[k, :6]`` in the frame of
    ``IA_i`` and the armature in ``dofs[k, ARMATURE]``. Returns False when ``D`` is singular: a pivot
    below ``SINGULAR_RTOL`` times the scale of ``IA_i`` (NaN input propagates)."""
    scale = inertia_scale(IA_i)
    for k in range(iv, iv + n):
        matvec6(IA_i, S[k, :6], U[k])
        for j in range(iv, iv + n):
            d = 0.0
            for r in range(6):
                d += S[j, r] * U[k, r]
            Dinv[j, k - iv] = d + (dofs[k, ARMATURE] if j == k else 0.0)
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
def articulate_single_dof(IA_i, S, armature, c_i, pA_i, tau_f, iv, U_k, Dinv, u, t, pa, lo, hi):
    """Pass 2 of the ABA for a joint of one dof ``iv`` (the common case, written out):
    ``U = IA_i S``, ``D = S^T U + armature``, ``u = tau_f - S^T pA_i`` (``tau_f``: the joint
    force less friction) and the bias force passed to the parent
    ``pa = pA_i + IA_i c_i + U (u - U^T c_i) / D`` (``= pA_i + Ia c_i + U u / D``, with ``Ia``
    from :func:`single_dof_articulated`). Reads the upper triangle of ``IA_i`` only. ``S`` is
    zero outside ``lo <= r < hi`` (``(3, 6)``: a rotation about an axis through the origin,
    ``(0, 3)``: a translation, ``(0, 6)``: any motion); callers pass constants, so the loops
    unroll. ``t`` (6,) is scratch. Returns False when ``D`` is singular (see
    :func:`joint_inertia`)."""
    c0, c1, c2, c3, c4, c5 = c_i[0], c_i[1], c_i[2], c_i[3], c_i[4], c_i[5]
    D, Uc, Sp = armature, 0.0, 0.0
    for r in range(6):
        ur = 0.0
        for j in range(lo, hi):
            ur += IA_i[min(r, j), max(r, j)] * S[j]
        U_k[r] = ur
        t[r] = (IA_i[min(r, 0), max(r, 0)] * c0 + IA_i[min(r, 1), max(r, 1)] * c1 + IA_i[min(r, 2), max(r, 2)] * c2
                + IA_i[min(r, 3), max(r, 3)] * c3 + IA_i[min(r, 4), max(r, 4)] * c4 + IA_i[min(r, 5), max(r, 5)] * c5)
        Uc += ur * c_i[r]
    for j in range(lo, hi):
        D += S[j] * U_k[j]
        Sp += S[j] * pA_i[j]
    if abs(D) <= SINGULAR_RTOL * inertia_scale(IA_i):
        return False
    dinv = 1.0 / D
    Dinv[iv, 0] = dinv
    uk = tau_f - Sp
    u[iv] = uk
    uh = (uk - Uc) * dinv
    for r in range(6):
        pa[r] = pA_i[r] + t[r] + U_k[r] * uh
    return True


@inline
def single_dof_articulated(IA_i, U_k, dinv):
    """The upper triangle (:func:`robodyn.spatial.upper_triangle`) of the inertia a joint of
    one dof passes to its parent, ``Ia = IA_i - U U^T / D``, from the upper triangle of
    ``IA_i``: values, never stored (:func:`robodyn.spatial.congruence_shift` takes them)."""
    u0, u1, u2, u3, u4, u5 = U_k[0], U_k[1], U_k[2], U_k[3], U_k[4], U_k[5]
    w0, w1, w2, w3, w4, w5 = u0 * dinv, u1 * dinv, u2 * dinv, u3 * dinv, u4 * dinv, u5 * dinv
    return (IA_i[0, 0] - w0 * u0, IA_i[0, 1] - w0 * u1, IA_i[0, 2] - w0 * u2, IA_i[0, 3] - w0 * u3,
            IA_i[0, 4] - w0 * u4, IA_i[0, 5] - w0 * u5, IA_i[1, 1] - w1 * u1, IA_i[1, 2] - w1 * u2,
            IA_i[1, 3] - w1 * u3, IA_i[1, 4] - w1 * u4, IA_i[1, 5] - w1 * u5, IA_i[2, 2] - w2 * u2,
            IA_i[2, 3] - w2 * u3, IA_i[2, 4] - w2 * u4, IA_i[2, 5] - w2 * u5, IA_i[3, 3] - w3 * u3,
            IA_i[3, 4] - w3 * u4, IA_i[3, 5] - w3 * u5, IA_i[4, 4] - w4 * u4, IA_i[4, 5] - w4 * u5,
            IA_i[5, 5] - w5 * u5)


@inline
def joint_motion(iv, n, axis, R, dofs, v, S, vJ, vp, vel_i, c_i):
    """Motion subspace ``S[k]`` of a body's joint in world axes (``R`` the body's world
    rotation), its velocity ``vel_i = vp + vJ`` (``vp``: the parent's velocity at the body's
    origin, as values; ``vJ = S qd``) and ``c_i = vel_i x vJ``. ``axis`` >= 0 when the
    joint's ``S`` is the unit motion ``e_axis`` (see ``layout.pack``): then ``S`` is a column
    of ``R`` in one half and zero in the other, and nothing goes through ``vJ``."""
    v0, v1, v2, v3, v4, v5 = vp
    if axis >= 0:
        lo = 0 if axis < 3 else 3
        col, qd = axis - lo, v[iv]
        x0, x1, x2 = R[0, col], R[1, col], R[2, col]
        j0, j1, j2 = x0 * qd, x1 * qd, x2 * qd
        if lo == 3:  # vel x [0; w] = [v x w; omega x w]
            S[iv, 0], S[iv, 1], S[iv, 2], S[iv, 3], S[iv, 4], S[iv, 5] = 0.0, 0.0, 0.0, x0, x1, x2
            v3, v4, v5 = v3 + j0, v4 + j1, v5 + j2
            cross_into(v0, v1, v2, j0, j1, j2, c_i, 0)
            cross_into(v3, v4, v5, j0, j1, j2, c_i, 3)
        else:  # vel x [v; 0] = [omega x v; 0]
            S[iv, 0], S[iv, 1], S[iv, 2], S[iv, 3], S[iv, 4], S[iv, 5] = x0, x1, x2, 0.0, 0.0, 0.0
            v0, v1, v2 = v0 + j0, v1 + j1, v2 + j2
            cross_into(v3, v4, v5, j0, j1, j2, c_i, 0)
            c_i[3], c_i[4], c_i[5] = 0.0, 0.0, 0.0
        vel_i[0], vel_i[1], vel_i[2], vel_i[3], vel_i[4], vel_i[5] = v0, v1, v2, v3, v4, v5
        return
    for r in range(6):
        vJ[r] = 0.0
    for k in range(iv, iv + n):
        rotate6(R, dofs[k], S[k])
        for r in range(6):
            vJ[r] += S[k, r] * v[k]
    vel_i[0], vel_i[1], vel_i[2] = v0 + vJ[0], v1 + vJ[1], v2 + vJ[2]
    vel_i[3], vel_i[4], vel_i[5] = v3 + vJ[3], v4 + vJ[4], v5 + vJ[5]
    motion_cross(vel_i, vJ, c_i)


@inline
def finite_where(x, mask, value):
    """True when ``x[k]`` is finite for every ``k`` with ``mask[k] == value``."""
    for k in range(x.shape[0]):
        if mask[k] == value and not np.isfinite(x[k]):
            return False
    return True


@inline
def aligned_placement(i, par, Rl, pl, oR, op, d):
    """World placement ``oR[i], op[i]`` of body ``i`` from its local one ``(Rl, pl)`` (the
    values of :func:`robodyn.joint_kernels.local_placement`), and ``d[i]``, the vector from
    the origin of its parent ``par`` (``-1``: the world) to its own, in world axes."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = Rl
    p0, p1, p2 = pl
    if par < 0:
        d[i, 0], d[i, 1], d[i, 2] = p0, p1, p2
        op[i, 0], op[i, 1], op[i, 2] = p0, p1, p2
        oR[i, 0, 0], oR[i, 0, 1], oR[i, 0, 2] = r00, r01, r02
        oR[i, 1, 0], oR[i, 1, 1], oR[i, 1, 2] = r10, r11, r12
        oR[i, 2, 0], oR[i, 2, 1], oR[i, 2, 2] = r20, r21, r22
        return
    Rp = oR[par]
    for r in range(3):
        a0, a1, a2 = Rp[r, 0], Rp[r, 1], Rp[r, 2]
        d[i, r] = a0 * p0 + a1 * p1 + a2 * p2
        op[i, r] = op[par, r] + d[i, r]
        oR[i, r, 0] = a0 * r00 + a1 * r10 + a2 * r20
        oR[i, r, 1] = a0 * r01 + a1 * r11 + a2 * r21
        oR[i, r, 2] = a0 * r02 + a1 * r12 + a2 * r22


@inline
def hybrid_state(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws):
    """Hybrid dynamics of one state into ``qdd`` and ``tau`` (nv,) (RBDA section 9.2, see
    ``hybrid.py``). ``known[k]``: the acceleration of dof ``k`` is given (all dofs of a joint
    alike); with no dof known this is the ABA. Returns a status (see
    ``_inputs``): ``i + 1`` when the articulated inertia of body ``i`` is singular.

    Inlined into :func:`hybrid_one`, the function other kernels call (the simulation, the
    hybrid dynamics), and into :func:`aba_at`, the state of the batch code (which ``aba``
    runs for a single state too, as a batch of one), where a call per state would cost about
    a tenth of the work.

    Spatial quantities of body ``i`` are expressed at its origin with world axes (see the
    module docstring): ``S[k]`` is motion-subspace column ``k`` turned into world axes, and
    ``d[i]`` the shift from the parent's origin."""
    (_, (_, _, oR, op, Rj, _), vel, c, IA, pA, acc, U, Dinv, u, UD, G, d, S, Ia, t1, t2,
     _, _) = ws
    nb, nv = ints.shape[0], dofs.shape[0]
    if not (q.shape[0] == nq_of(ints) and v.shape[0] == nv and qdd_known.shape[0] == nv
            and tau_known.shape[0] == nv and known.shape[0] == nv):
        return WRONG_SIZE
    if check and not (finite(q) and finite(v) and finite_where(qdd_known, known, True)
                      and finite_where(tau_known, known, False)):
        return NONFINITE
    eps = params[SMOOTHING]
    # Pass 1: placements, velocities, velocity-product accelerations (with the known joint
    # accelerations), rigid-body inertias and bias forces
    for i in range(nb):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        ok, Rl, pl = local_placement(ints[i, JTYPE], body[i], q, ints[i, IQ], Rj)
        if not ok:
            return BAD_QUATERNION
        aligned_placement(i, par, Rl, pl, oR, op, d)
        vp = shifted_motion(d[i], vel[par]) if par >= 0 else (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        joint_motion(iv, n, ints[i, UNIT_AXIS], oR[i], dofs, v, S, t1, vp, vel[i], c[i])
        if known[iv]:
            for k in range(iv, iv + n):
                for r in range(6):
                    c[i, r] += S[k, r] * qdd_known[k]
        theta = inertia_rotated(oR[i], body[i, INERTIA:INERTIA_END])
        force_cross(vel[i], momentum(theta, vel[i]), pA[i])
        inertia_matrix(theta, IA[i], False)  # the upper triangle (see pass 2)
        if fcode >= 0:
            wrench_to_aligned(fcode, oR[i], op[i], fext[i], t1)
            for r in range(6):
                pA[i, r] -= t1[r]
    # Pass 2: articulated inertias, the joints of known acceleration held rigid; each body
    # passes Ia and pa to its parent: IA_p += iX_p^T Ia iX_p, pA_p += iX_p^T pa. Children add
    # to the upper triangle of IA_p only (the joints of one dof read no more); the other
    # joints complete theirs first.
    for i in range(nb - 1, -1, -1):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        if n == 1 and not known[iv]:
            tau_f, axis = tau_known[iv] - passive_torque(dofs, eps, q, ints[i, IQ], v, iv), ints[i, UNIT_AXIS]
            if axis >= 3:
                ok = articulate_single_dof(IA[i], S[iv], dofs[iv, ARMATURE], c[i], pA[i], tau_f, iv, U[iv], Dinv, u,
                                           t1, t2, 3, 6)
            elif axis >= 0:
                ok = articulate_single_dof(IA[i], S[iv], dofs[iv, ARMATURE], c[i], pA[i], tau_f, iv, U[iv], Dinv, u,
                                           t1, t2, 0, 3)
            else:
                ok = articulate_single_dof(IA[i], S[iv], dofs[iv, ARMATURE], c[i], pA[i], tau_f, iv, U[iv], Dinv, u,
                                           t1, t2, 0, 6)
            if not ok:
                return i + 1
            if par < 0:
                continue
            Ia_upper = single_dof_articulated(IA[i], U[iv], Dinv[iv, 0])
        else:
            mirror_upper(IA[i])
            if known[iv]:
                matvec6(IA[i], c[i], t1)
                for r in range(6):
                    t2[r] = pA[i, r] + t1[r]
                if par < 0:
                    continue
                Ia_upper = upper_triangle(IA[i])
            else:
                for k in range(iv, iv + n):
                    s = 0.0
                    for r in range(6):
                        s += S[k, r] * pA[i, r]
                    u[k] = tau_known[k] - s - passive_torque(dofs, eps, q, ints[i, IQ], v, k)
                if free_root(ints, dofs, i):
                    continue  # solved in pass 3
                if not joint_inertia(IA[i], S, dofs, iv, n, U, Dinv, G):
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
                Ia_upper = upper_triangle(Ia)
        congruence_shift(d[i], Ia_upper, IA[par], False)
        unshift_force(d[i], t2, t1)
        for r in range(6):
            pA[par, r] += t1[r]
    # Pass 3: accelerations of the joints of unknown acceleration, forces of the others;
    # a_0 = -g needs no shift to a root's origin (its angular part is zero)
    for i in range(nb):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        if par >= 0:
            shift_motion(d[i], acc[par], acc[i])
        else:
            acc[i, 0], acc[i, 1], acc[i, 2] = -params[GRAVITY], -params[GRAVITY + 1], -params[GRAVITY + 2]
            acc[i, 3], acc[i, 4], acc[i, 5] = 0.0, 0.0, 0.0
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
                    s += S[k, r] * t1[r]
                tau[k] = s + dofs[k, ARMATURE] * qdd_known[k] + passive_torque(dofs, eps, q, ints[i, IQ], v, k)
            continue
        if n == 1:
            s = 0.0
            for r in range(6):
                s += U[iv, r] * acc[i, r]
            qdd[iv] = Dinv[iv, 0] * (u[iv] - s)
            for r in range(6):
                acc[i, r] += S[iv, r] * qdd[iv]
        elif free_root(ints, dofs, i):
            # S = diag(R, R) is orthogonal, so with D = S^T IA S and U = IA S:
            # qdd = D^-1 (u - U^T a) = S^T (IA^-1 S u - a), and a + S qdd = IA^-1 S u
            rotate6(oR[i], u[iv:iv + 6], t1)
            if not solve_block(IA[i], t1, 6, G, t2, SINGULAR_RTOL * inertia_scale(IA[i])):
                return i + 1
            for r in range(6):
                t1[r] = t2[r] - acc[i, r]
                acc[i, r] = t2[r]
            R = oR[i]
            for r in range(3):
                qdd[iv + r] = R[0, r] * t1[0] + R[1, r] * t1[1] + R[2, r] * t1[2]
                qdd[iv + 3 + r] = R[0, r] * t1[3] + R[1, r] * t1[4] + R[2, r] * t1[5]
        else:
            joint_acceleration(S, U, Dinv, u, iv, n, acc[i], qdd, t1)
        for k in range(iv, iv + n):
            tau[k] = tau_known[k]
    return result_status(check, finite(qdd) and finite(tau))


@core
def hybrid_one(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws):
    """:func:`hybrid_state` of one state (the compiled function other kernels call)."""
    return hybrid_state(ints, body, dofs, params, q, v, qdd_known, tau_known, known, fext, fcode, check, qdd, tau, ws)


_hybrid_one = by_address(hybrid_one)


@splice
def aba_one(ints, body, dofs, params, q, v, tau, fext, fcode, check, qdd, ws):
    """Forward dynamics of one state into ``qdd`` (nv,): :func:`hybrid_one` with no joint of
    known acceleration (``ws[18]`` is all False; ``ws[17]`` receives the copy of ``tau``);
    spliced into its callers, which call the compiled ``hybrid_one`` at its address
    (``_jit.by_address``: not copied into them).
    Returns a status (see ``_inputs``): ``i + 1`` when the articulated inertia of body ``i``
    is singular."""
    return _hybrid_one(ints, body, dofs, params, q, v, qdd, tau, ws[18], fext, fcode, check, qdd, ws[17], ws)


@inline
def aba_at(args, s, ws):
    """The forward dynamics of state ``s`` of a batch (see :func:`aba_one`)."""
    ints, body, dofs, params, Q, V, T, F, fcode, check, QDD = args
    return hybrid_state(ints, body, dofs, params, Q[s], V[s], QDD[s], T[s], ws[18], F[s if F.shape[0] > 1 else 0],
                        fcode, check, QDD[s], ws[17], ws)


@inline
def aba_views(args, ws):
    """The workspace views carved once per chunk from the buffer, where the compiler sees
    their shapes."""
    return (ws[0],) + workspace_views(ws[0], args[0].shape[0], args[2].shape[0]) + (ws[1],)


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, MAT, MAT, MAT, TENSOR, int64, boolean, MAT), (int64, int64))
_aba_batch = batch_kernel(aba_at, buffer, aba_views, ONE_STATE)
_aba_call_one = _aba_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, boolean, VEC)
def _aba_packed(address, ints, packed, q, v, tau, check, qdd):
    """One state without external wrenches, the model in one array (the fast path): the
    batch's code at ``address`` (``_aba_batch.one_address``) for a batch of one."""
    ok, args = one_state(ints, packed, q, v, tau, check, qdd)
    return _aba_call_one(address, args, buffer(ints.shape[0], qdd.shape[0])) if ok else WRONG_SIZE


def aba(model, q, v, tau, f_ext=None, frame: str = "local", *, friction: bool = True,
        armature: bool = True, check_finite: bool = True, out: np.ndarray | None = None,
        f_ext_frame=None) -> np.ndarray:
    """Forward dynamics: the acceleration produced by joint forces ``tau`` at ``(q, v)``.

    ``a = (M(q) + armature)^-1 (tau - C(q, v) v - g(q) - friction(v) - spring(q) + sum_i J_i^T f_ext_i)``

    Args:
        q: (..., nq). v, tau: (..., nv). f_ext, frame, friction, armature,
        check_finite, out: as in :func:`robodyn.rnea`.

    Returns:
        a: (..., nv), the inverse of :func:`robodyn.rnea`: ``aba(q, v, rnea(q, v, a)) == a``.

    Raises ValueError when a body's articulated inertia is singular (e.g. a chain of massless
    leaf bodies), or, for a model with mimic couplings (:class:`robodyn.CoupledModel`, solved
    as ``(G^T M G)^-1 G^T (tau_full - h)``), when its mass matrix in the independent
    coordinates is not positive definite: the forward dynamics is undefined there.
    Reference: RBDA Table 7.1.
    """
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "aba()")
    if f_ext is None and frame in _inputs.WRENCH_FRAMES:
        qdd = _inputs.fast_out(out, (model.nv,))  # fast path for one state: the kernel checks
        try:  # sizes and values
            k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
            if _aba_packed(_aba_batch.one_address, k.ints, k.packed[friction, armature], q, v, tau, check_finite,
                           qdd) == OK:
                return qdd
        except (TypeError, KeyError, AttributeError):  # not contiguous float64 arrays (or options not bool)
            pass
    if any_lazy(q, v, tau, f_ext):
        return deferred(aba, locals())
    if is_coupled(model):  # mimic joints: the compiled coupled path (after the fast path: free for a tree)
        return coupled.run_aba(model, q, v, tau, f_ext, frame, friction, armature, check_finite, out)
    k = model.kernel
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    dofs, params = k.dofs[(bool(friction), bool(armature))], k.params[True]
    qdd, result = _inputs.output(out, batch, (model.nv,), x)
    Q, V, T, F, QDD = _inputs.batched(batch, x["q"], x["v"], x["tau"], F, qdd)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args, sizes = (k.ints, k.body, dofs, params, Q, V, T, F, fcode, check_finite, QDD), (model.nbodies, model.nv)
    _aba_batch.run(args, sizes, status, batch)
    raise_singular(model, raise_for_status(model, status, x, "aba"), "aba")
    return result
