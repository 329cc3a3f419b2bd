"""Analytical first derivatives of inverse dynamics: ``dtau/dq``, ``dtau/dv`` and ``dtau/da = M``.

The algorithm of Carpentier and Mansard (RSS 2018), in world coordinates, where the motion
subspace columns are the Jacobian columns ``J_k`` and composite quantities add without
transforms. Derivatives with respect to ``q`` are in the tangent space of
:func:`robodyn.integrate`: a step ``q ⊕ eps e_k`` moves the subtree of dof ``k``'s joint
rigidly by the motion ``J_k`` (every joint's placement is ``X_tree X_J(q)`` with
``X_J(q ⊕ d) = X_J(q) exp(S d)``).

Pass 1, from the root (``ov``, ``oa``: world velocity and acceleration, gravity included as
``oa_root parent = -g``; ``λ`` the parent of body ``i``)::

    ov_i = ov_λ + J_i qd_i,   oa_i = oa_λ + J_i qdd_i + ov_i x J_i qd_i
    dV_k = ov_λ x J_k                      (d ov_i / d q_k along the relative motion; 0 at a root)
    dA_k = oa_λ x J_k + ov_λ x dV_k,   dAv_k = ov_i x J_k + dV_k
    Y_i = oX_i* I_i oX_i,   h_i = Y_i ov_i,   of_i = Y_i oa_i + ov_i x* h_i - W_i
    dY_i = ov_i x* Y_i - Y_i ov_i x + (. x* h_i)      (a 6 x 6 matrix)

Pass 2, from the leaves, with ``Y``, ``dY``, ``of`` summed over the subtree of ``i``, for every
dof ``k`` of body ``i`` its columns (kept for the ancestors' rows)::

    Fa_k = Y J_k,   Fq_k = dY dV_k + Y dA_k,   Fv_k = dY J_k + Y dAv_k,   YJ_k = dY^T J_k

and then, for every dof ``l`` of ``i`` or of a descendant (``Fa_l``, ``Fq_l``, ``Fv_l``, ``YJ_l``:
the columns of ``l``'s own body, computed when it was visited)::

    M[k, l] = M[l, k] = J_k . Fa_l,   dtau_dq[k, l] = J_k . Fq_l,   dtau_dv[k, l] = J_k . Fv_l
    dtau_dq[l, k] = Fa_l . dA_k + YJ_l . dV_k,  dtau_dv[l, k] = Fa_l . dAv_k + YJ_l . J_k
                                                          (the second line: l in a strict descendant)

after which ``Fq_k += J_k x* of`` (the subtree turning rigidly, seen by the ancestors' rows).

External wrenches ``W_i`` (at the world origin) given in the body frame turn with their body
and are part of the rigid ``of``. Given in world axes about the world origin they do not move:
``of`` for the ``J x* of`` term leaves them out, and ``Z_l = J_l x* (-W_sub)`` adds
``J_k . Z_l`` to ``dtau_dq[l, k]`` for the dofs ``l`` of ``i`` and its descendants (the
Jacobian ``J_l`` turns while the wrench does not). Given in world axes about the body origin
``p_i`` they move with the origin without turning: the rigid term keeps them and
``G w = sum_i [w x f_i; w x n_i + p_i x (w x f_i)]`` (the turn they do not make) is added to
``Fq_k`` (``w`` the angular part of ``J_k``), and ``Z_l = [0; G^T J_l] = [0; sum_i f_i x (v_l +
w_l x p_i) + n_i x w_l]`` to the rows of the subtree, from the sums ``sum f_i``, ``sum f_i .
p_i``, ``sum p_i f_i^T`` and ``sum n_i``.

``dtau_dv`` adds the friction's derivative ``b + Fc d tanh(v / eps) / dv`` on its diagonal
(zero for the unsmoothed sign), ``M`` the armature, as :func:`robodyn.rnea` has them.

Reference: J. Carpentier and N. Mansard, "Analytical derivatives of rigid body dynamics
algorithms", Robotics: Science and Systems, 2018; Featherstone, RBDA (2008), Table 5.1.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._deprecated import renamed_keyword
from .._jit import MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, core, fast, inline, kernel, scratch
from ..joint_kernels import nq_of, passive_torque_dv
from ..layout import ARMATURE, IV, NDOF, PARENT, SMOOTHING, STIFFNESS, SUBTREE_END
from ..spatial import (dot6, force_act, force_cross, inertia_matrix, inertia_mul, matTvec6, matvec6, momentum,
                       motion_cross, wrench_to_local)
from ..coupling import expand_q, expand_v, is_coupled, reduce_matrix
from ._lazy import any_lazy, deferred
from . import _inputs
from ._inputs import fits, unpack
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, row, take
from .crba import world_state
from .driver import batch_kernel
from .rnea import base_acceleration
from .status import NO_WRENCH, NONFINITE, OK, WRONG_SIZE, finite, finite2, raise_for_status, result_status

PER_BODY = 10 + 4 * 6 + 16 + 36 + 1  # Ic, ov, oa, of, W, turn, dY, mark
PER_DOF = 6 * 9  # J, dV, dA, dAv, Fa, Fq, Fv, YJ, Z


@inline
def workspace_views(buf, nb, nv):
    """The scratch arrays of :func:`derivatives_state` carved from ``buf`` (which an
    ``inline`` function may not return: see ``_jit``)."""
    P, o = poses(buf, 0, nb)
    Ic, o = take(buf, o, (nb, 10))
    ov, o = take(buf, o, (nb, 6))
    oa, o = take(buf, o, (nb, 6))
    of, o = take(buf, o, (nb, 6))
    W, o = take(buf, o, (nb, 6))
    turn, o = take(buf, o, (nb, 16))
    dY, o = take(buf, o, (nb, 6, 6))
    mark, o = take(buf, o, (nb,))
    cols, o = take(buf, o, (9, nv, 6))
    Ym, o = take(buf, o, (6, 6))
    A, o = take(buf, o, (6, 6))
    t, o = take(buf, o, (3, 6))
    return P, (Ic, ov, oa, of, W, turn, dY, mark), cols, (Ym, A, t)


@scratch
def buffer(nb, nv):
    """``(buffer,)``: the memory of :func:`workspace`, the workspace of the batch code (which
    carves the views once per chunk, :func:`derivatives_views`)."""
    return (np.empty((POSES_SIZE_NB + PER_BODY) * nb + PER_DOF * nv + POSES_SIZE + 72 + 18),)


@kernel
def workspace(nb, nv):
    """Scratch of :func:`derivatives_one`: ``(buffer, poses, per-body arrays, per-dof columns,
    small scratch)``, views of the buffer."""
    buf = buffer(nb, nv)[0]
    return (buf,) + workspace_views(buf, nb, nv)


@inline
def add6(x, y):
    """``x += y`` for 6-vectors."""
    for r in range(6):
        x[r] += y[r]


@inline
def inertia_variation(theta, ov, h, Ym, A, out):
    """``out = ov x* Y - Y (ov x) + (. x* h)`` (6 x 6) for the inertia ``Y`` of 10 parameters:
    the derivative of ``Y m`` as the body moves with ``ov``, plus ``m x* h``. With ``A = Y
    (ov x)`` and ``(ov x*) = -(ov x)^T``, the first two terms are ``-(A + A^T)``."""
    inertia_matrix(theta, Ym, True)
    v0, v1, v2, w0, w1, w2 = ov[0], ov[1], ov[2], ov[3], ov[4], ov[5]
    for r in range(6):  # A[r] = Y[r] (ov x): (ov x) = [[W, V], [0, W]], W = [w]x, V = [v]x
        y0, y1, y2, y3, y4, y5 = Ym[r, 0], Ym[r, 1], Ym[r, 2], Ym[r, 3], Ym[r, 4], Ym[r, 5]
        A[r, 0] = y1 * w2 - y2 * w1
        A[r, 1] = y2 * w0 - y0 * w2
        A[r, 2] = y0 * w1 - y1 * w0
        A[r, 3] = y1 * v2 - y2 * v1 + y4 * w2 - y5 * w1
        A[r, 4] = y2 * v0 - y0 * v2 + y5 * w0 - y3 * w2
        A[r, 5] = y0 * v1 - y1 * v0 + y3 * w1 - y4 * w0
    for r in range(6):
        for c in range(6):
            out[r, c] = -(A[r, c] + A[c, r])
    # m x* h = [w x hl; w x ha + v x hl]: blocks (lin, ang) and (ang, lin) -[hl]x, (ang, ang) -[ha]x
    for (ro, co, o) in ((0, 3, 0), (3, 0, 0), (3, 3, 3)):
        out[ro, co + 1] += h[o + 2]
        out[ro, co + 2] -= h[o + 1]
        out[ro + 1, co] -= h[o + 2]
        out[ro + 1, co + 2] += h[o]
        out[ro + 2, co] += h[o + 1]
        out[ro + 2, co + 1] -= h[o]


@inline
def world_wrench(fcode, R, p, f, W, turn, t):
    """``W``: the external wrench ``f`` (given in ``fcode``'s frame) at the world origin in world
    axes; for ``fcode == 2`` (world axes about the body origin ``p``) also ``turn = [f; f . p;
    p f^T; n]`` (force and torque in world axes)."""
    wrench_to_local(fcode, R, p, f, t)
    force_act(R, p, t, W)
    if fcode == 2:
        for r in range(3):
            turn[r] = f[r]
        turn[3] = f[0] * p[0] + f[1] * p[1] + f[2] * p[2]
        for r in range(3):
            for c in range(3):
                turn[4 + 3 * r + c] = p[r] * f[c]
            turn[13 + r] = f[3 + r]


@inline
def turn_rows(turn, J, out):
    """``out = [0; G^T J] = [0; sum_i f_i x (v + w x p_i) + n_i x w]`` from the sums ``turn``."""
    F0, F1, F2, fp, N0, N1, N2 = turn[0], turn[1], turn[2], turn[3], turn[13], turn[14], turn[15]
    v0, v1, v2, w0, w1, w2 = J[0], J[1], J[2], J[3], J[4], J[5]
    out[0], out[1], out[2] = 0.0, 0.0, 0.0
    # sum f x (w x p) = w (sum f . p) - (sum p f^T) w
    out[3] = F1 * v2 - F2 * v1 + N1 * w2 - N2 * w1 + w0 * fp - (turn[4] * w0 + turn[5] * w1 + turn[6] * w2)
    out[4] = F2 * v0 - F0 * v2 + N2 * w0 - N0 * w2 + w1 * fp - (turn[7] * w0 + turn[8] * w1 + turn[9] * w2)
    out[5] = F0 * v1 - F1 * v0 + N0 * w1 - N1 * w0 + w2 * fp - (turn[10] * w0 + turn[11] * w1 + turn[12] * w2)


@inline
def turn_force(turn, J, out):
    """``out += G w = [w x sum f_i; w x sum n_i + w (sum f . p) - (sum f p^T) w]``, ``w`` the
    angular part of ``J``."""
    F0, F1, F2, fp, N0, N1, N2 = turn[0], turn[1], turn[2], turn[3], turn[13], turn[14], turn[15]
    w0, w1, w2 = J[3], J[4], J[5]
    out[0] += w1 * F2 - w2 * F1
    out[1] += w2 * F0 - w0 * F2
    out[2] += w0 * F1 - w1 * F0
    out[3] += w1 * N2 - w2 * N1 + w0 * fp - (turn[4] * w0 + turn[7] * w1 + turn[10] * w2)
    out[4] += w2 * N0 - w0 * N2 + w1 * fp - (turn[5] * w0 + turn[8] * w1 + turn[11] * w2)
    out[5] += w0 * N1 - w1 * N0 + w2 * fp - (turn[6] * w0 + turn[9] * w1 + turn[12] * w2)


@inline
def forward_pass(ints, v, a, a0, fext, fcode, oR, op, Ic, ov, oa, of, W, turn, dY, cols, Ym, A, t):
    """Pass 1 (see the module docstring): world motions, body forces, the columns ``dV, dA,
    dAv`` of every dof and the inertia variations ``dY``."""
    J, dV, dA, dAv = cols[0], cols[1], cols[2], cols[3]
    vJ, t1 = t[0], t[1]
    for i in range(ints.shape[0]):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        for r in range(6):
            s, u = 0.0, 0.0
            for k in range(iv, iv + n):
                s += J[k, r] * v[k]
                u += J[k, r] * a[k]
            vJ[r] = s
            ov[i, r] = s if par < 0 else ov[par, r] + s
            oa[i, r] = u + (a0[r] if par < 0 else oa[par, r])
        motion_cross(ov[i], vJ, t1)
        add6(oa[i], t1)
        for k in range(iv, iv + n):
            motion_cross(a0 if par < 0 else oa[par], J[k], dA[k])
            motion_cross(ov[i], J[k], dAv[k])
            if par < 0:
                for r in range(6):
                    dV[k, r] = 0.0
            else:
                motion_cross(ov[par], J[k], dV[k])
                motion_cross(ov[par], dV[k], t1)
                add6(dA[k], t1)
                add6(dAv[k], dV[k])
        theta = Ic[i]
        h = momentum(theta, ov[i])
        inertia_mul(theta, oa[i], of[i])
        force_cross(ov[i], h, t1)
        add6(of[i], t1)
        if fcode >= 0:
            world_wrench(fcode, oR[i], op[i], fext[i], W[i], turn[i], t1)
            for r in range(6):
                of[i, r] -= W[i, r]
        inertia_variation(theta, ov[i], h, Ym, A, dY[i])


@inline
def derivatives_state(ints, body, dofs, params, q, v, a, fext, fcode, check, dq, dv, M, ws):
    """``dq = dtau/dq``, ``dv = dtau/dv`` (nv, nv) and ``M = dtau/da`` at one state (``M`` is
    not written when it has no rows); returns a status (see ``_inputs``)."""
    _, P, (Ic, ov, oa, of, W, turn, dY, mark), cols, (Ym, A, t) = ws
    J, dV, dA, dAv, Fa, Fq, Fv, YJ, Z = cols[0], cols[1], cols[2], cols[3], cols[4], cols[5], cols[6], cols[7], \
        cols[8]
    nb, nv = ints.shape[0], dofs.shape[0]
    if not (q.shape[0] == nq_of(ints) and v.shape[0] == nv and a.shape[0] == nv):
        return WRONG_SIZE
    if check and not finite(a):
        return NONFINITE
    status = world_state(ints, body, dofs, q, v, check, P, J, Ic)
    if status != OK:
        return status
    a0 = t[2]
    base_acceleration(params, a0)
    forward_pass(ints, v, a, a0, fext, fcode, P[2], P[3], Ic, ov, oa, of, W, turn, dY, cols, Ym, A, t)
    dq[:, :] = 0.0
    dv[:, :] = 0.0
    mass = M.shape[0] > 0
    if mass:
        M[:, :] = 0.0
    t1 = t[0]
    for i in range(nb - 1, -1, -1):
        par, iv, n, end = ints[i, PARENT], ints[i, IV], ints[i, NDOF], ints[i, SUBTREE_END]
        theta, Yd = Ic[i], dY[i]
        for k in range(iv, iv + n):
            inertia_mul(theta, J[k], Fa[k])
            inertia_mul(theta, dA[k], Fq[k])
            matvec6(Yd, dV[k], t1)
            add6(Fq[k], t1)
            inertia_mul(theta, dAv[k], Fv[k])
            matvec6(Yd, J[k], t1)
            add6(Fv[k], t1)
            matTvec6(Yd, J[k], YJ[k])
            if fcode == 1:
                force_cross(J[k], W[i], Z[k])
                for r in range(6):
                    Z[k, r] = -Z[k, r]
            elif fcode == 2:
                turn_rows(turn[i], J[k], Z[k])
        # the rows of i's own dofs against the columns of the subtree (own dofs first)
        mark[i] = i
        b = i
        while b < nb and ints[b, IV] < end:
            if b > i:  # in the subtree when its parent is (a parent below i never is)
                p = ints[b, PARENT]
                if p < i or mark[p] != i:
                    b += 1
                    continue
                mark[b] = i
            for l in range(ints[b, IV], ints[b, IV] + ints[b, NDOF]):
                for k in range(iv, iv + n):
                    x = dot6(J[k], Fq[l])
                    if b == i and fcode > 0:
                        x += dot6(Z[k], J[l])
                    dq[k, l] = x
                    dv[k, l] = dot6(J[k], Fv[l])
                    if mass:
                        x = dot6(J[k], Fa[l])
                        M[k, l] = x
                        M[l, k] = x
                    if b > i:
                        x = dot6(Fa[l], dA[k]) + dot6(YJ[l], dV[k])
                        if fcode > 0:
                            x += dot6(Z[l], J[k])
                        dq[l, k] = x
                        dv[l, k] = dot6(Fa[l], dAv[k]) + dot6(YJ[l], J[k])
            b += 1
        ofr = of[i]
        if fcode == 1:  # the wrench fixed in the world does not turn with the subtree
            for r in range(6):
                t[1, r] = of[i, r] + W[i, r]
            ofr = t[1]
        for k in range(iv, iv + n):
            force_cross(J[k], ofr, t1)
            add6(Fq[k], t1)
            if fcode == 2:
                turn_force(turn[i], J[k], Fq[k])
        if par >= 0:
            for r in range(10):
                Ic[par, r] += Ic[i, r]
            for r in range(6):
                of[par, r] += of[i, r]
                for c in range(6):
                    dY[par, r, c] += Yd[r, c]
            if fcode == 1:
                add6(W[par], W[i])
            elif fcode == 2:
                for r in range(16):
                    turn[par, r] += turn[i, r]
    eps = params[SMOOTHING]
    for k in range(nv):
        dv[k, k] += passive_torque_dv(dofs, eps, v[k], k)
        dq[k, k] += dofs[k, STIFFNESS]  # the joint spring (joints of one dof: q's tangent is q)
        if mass:
            M[k, k] += dofs[k, ARMATURE]
    return result_status(check, finite2(dq) and finite2(dv))


@core
def derivatives_one(ints, body, dofs, params, q, v, a, fext, fcode, check, dq, dv, M, ws):
    """:func:`derivatives_state` of one state (the compiled function other kernels call)."""
    return derivatives_state(ints, body, dofs, params, q, v, a, fext, fcode, check, dq, dv, M, ws)


@inline
def derivatives_at(args, s, ws):
    """:func:`derivatives_state` of state ``s`` of a batch."""
    ints, body, dofs, params, Q, V, A, F, fcode, check, DQ, DV, MM = args
    return derivatives_state(ints, body, dofs, params, Q[s], V[s], A[s], F[s if F.shape[0] > 1 else 0], fcode,
                             check, DQ[s], DV[s], MM[s], ws)


@inline
def derivatives_views(args, ws):
    """The workspace views carved once per chunk from the buffer, where the compiler sees
    their shapes."""
    return (ws[0],) + workspace_views(ws[0], args[0].shape[0], args[2].shape[0])


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, MAT, MAT, MAT, TENSOR, int64, boolean, TENSOR, TENSOR, TENSOR),
             (int64, int64))
_derivatives_batch = batch_kernel(derivatives_at, buffer, derivatives_views, ONE_STATE)
_derivatives_call_one = _derivatives_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, boolean, MAT, MAT, MAT)
def _derivatives_packed(address, ints, packed, q, v, a, check, dq, dv, M):
    """One state without external wrenches, the model in one array (the fast path): the
    batch's code at ``address`` (``_derivatives_batch.one_address``) for a batch of one."""
    body, dofs, params, zero = unpack(ints, packed)
    nv = dofs.shape[0]
    if not (fits(dq, nv, q, v, a) and fits(dv, nv, q, v, a) and fits(M, nv, q, v, a)):
        return WRONG_SIZE
    args = (ints, body, dofs, params, row(q), row(v), row(a), row(zero), int64(NO_WRENCH), check, row(dq), row(dv),
            row(M))
    return _derivatives_call_one(address, args, buffer(ints.shape[0], nv))


def fast_path(packed, batch, model, q, v, x, friction, armature, check):
    """The three (nv, nv) results of the fast-path kernel ``packed`` (see ``_jit.fast``) for one
    state without external wrenches, which runs the code of the batch kernel ``batch`` at its
    ``one_address``, or None when it does not take the arguments (then the general path checks
    them and says what is wrong; a CoupledModel, which has no kernel)."""
    nv = model.nv
    out = np.empty((nv, nv)), np.empty((nv, nv)), np.empty((nv, nv))
    try:
        k = model.kernel
        if packed(batch.one_address, k.ints, k.packed[friction, armature], q, v, x, check, *out) == OK:
            return out
    except (TypeError, KeyError, AttributeError):  # not contiguous float64 arrays (or options not bool)
        pass
    return None


def rnea_derivatives(model, q, v, a, f_ext=None, frame: str = "local", *, friction: bool = True,
                     armature: bool = True, check_finite: bool = True,
                     f_ext_frame=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of inverse dynamics, ``tau = rnea(q, v, a, f_ext)``, analytical, O(n d).

    ``dtau_dq[:, k] = d tau(q ⊕ eps e_k, v, a) / d eps`` at 0 (the tangent direction of
    :func:`robodyn.integrate`: for a free joint, the twist in the base frame),
    ``dtau_dv = d tau / d v`` (with the friction's derivative when ``friction``: ``b + Fc d
    tanh(v / eps) / dv``, zero for the unsmoothed sign) and ``dtau_da = M(q)`` (with the
    armature when ``armature``), the same derivatives as Pinocchio's ``computeRNEADerivatives``.

    Args:
        q: (..., nq). v, a: (..., nv). f_ext, frame, friction, armature, check_finite:
            as in :func:`robodyn.rnea` (wrenches in the body frame turn with their body; in
            world axes they keep their direction).

    Returns:
        ``(dtau_dq, dtau_dv, dtau_da)``, each (..., nv, nv).

    Reference: J. Carpentier and N. Mansard, "Analytical derivatives of rigid body dynamics
    algorithms", RSS 2018 (the recursions are in ``robodyn/algorithms/rnea_derivatives.py``).
    """
    if any_lazy(q, v, a, f_ext):
        return deferred(rnea_derivatives, locals())
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "rnea_derivatives()")
    if f_ext is None and frame in _inputs.WRENCH_FRAMES:
        out = fast_path(_derivatives_packed, _derivatives_batch, model, q, v, a, friction, armature, check_finite)
        if out is not None:
            return out
    if is_coupled(model):  # mimic joints: G^T D_full G at (E(q), G v, G a)
        full = rnea_derivatives(model.full, expand_q(model, q), expand_v(model, v), expand_v(model, a, "a"), f_ext,
                                frame, friction=friction, armature=armature, check_finite=check_finite)
        return tuple(reduce_matrix(model, D) for D in full)
    batch, x = _inputs.states(model, q=q, v=v, a=a)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    return run(model, batch, x, F, fcode, check_finite, friction=friction, armature=armature)


def run(model, batch, x, F, fcode, check, gravity=True, friction=True, armature=True, what="rnea_derivatives",
        report=None, mass=True):
    """:func:`rnea_derivatives` on checked inputs ``x = {"q", "v", "a"}`` (see ``_inputs.states``),
    gravity, friction and armature switched as given; errors name the arrays of ``report``
    (default ``x``). ``mass=False`` leaves ``dtau_da`` out (an empty array in its place)."""
    k, nv = model.kernel, model.nv
    dofs, params = k.dofs[(bool(friction), bool(armature))], k.params[bool(gravity)]
    (dq, rq), (dv, rv) = (_inputs.output(None, batch, (nv, nv), x) for _ in range(2))
    M, rM = _inputs.output(None, batch, (nv, nv) if mass else (0, 0), x)
    Q, V, A, F, DQ, DV, MM = _inputs.batched(batch, x["q"], x["v"], x["a"], F, dq, dv, M)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args = (k.ints, k.body, dofs, params, Q, V, A, F, fcode, check, DQ, DV, MM)
    _derivatives_batch.run(args, (model.nbodies, nv), status, batch)
    raise_for_status(model, status, x if report is None else report, what)
    return rq, rv, rM
