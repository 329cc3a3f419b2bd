"""Second-order partial derivatives of inverse dynamics: ``d2tau/dq2``, ``d2tau/dqdv``,
``d2tau/dv2`` and ``d2tau/dadq = dM/dq``, exact (second-order forward-mode differentiation).

The inverse dynamics in world coordinates (spatial vectors at the world origin, ``[lin; ang]``),
``J_n`` the world Jacobian column of dof ``n``, ``c(n)`` its body, ``λ`` a body's parent, ``Y_b``
the world inertia of body ``b``, ``W_b`` its external wrench at the world origin and ``a_0 =
[-g; 0]`` (RBDA Table 5.1 in world coordinates)::

    vJ_b = sum_{c(n) = b} J_n v_n,   ov_b = ov_λ + vJ_b
    oa_b = oa_λ + sum_{c(n) = b} J_n a_n + ov_b x vJ_b          (oa = a_0 above a root)
    h_b = Y_b ov_b,   f_b = Y_b oa_b + ov_b x* h_b - W_b,   F_b = f_b + sum_{children} F_c
    tau_n = J_n . F_c(n)  (+ friction and springs, + armature a_n)

Every line is a sum of products of ``J``, ``Y``, ``W`` (functions of ``q``) with ``v`` and
``a``, so it is differentiated exactly by the Leibniz rule (hyper-dual arithmetic, no step
size): pass 1 the values; pass 2 for each direction ``x`` (``q_k``, ``v_k`` or ``a_k``) the
first derivatives ``ov_x, oa_x, h_x, f_x, F_x`` (same lines, one factor differentiated at a
time); pass 3 for each pair ``(x, y)`` the mixed derivatives ``ov_xy, ..., F_xy`` and::

    tau_xy,n = J_xy,n . F + J_x,n . F_y + J_y,n . F_x + J_n . F_xy

A pair whose bodies are on no common path to the root has no mixed term, and ``f_xy`` is
nonzero only on the subtree of the deeper of the two bodies; pass 3 visits that subtree.

The directions of ``q`` are those of :func:`robodyn.integrate`: the step ``q ⊕ eps e_k`` moves
the subtree of dof ``k``'s body rigidly by ``exp(eps J_k)`` (every joint's placement is
``X_tree X_J(q)`` with ``X_J(q ⊕ d) = X_J(q) exp(S d)``), so a vector fixed in a body of the
subtree changes by ``J_k x J_n`` (a motion), ``J_k x* W`` (a wrench) or ``L_k(Y) = J_k x* Y - Y
J_k x`` (an inertia). The second step ``⊕ delta e_l`` moves the subtree of ``l``; a body in
both subtrees moves by ``exp(J_anc) exp(J_desc)``, the ancestor's factor first (for dofs of one
joint, ``exp(eps J_k) exp(delta J_l)``), so its mixed terms are, with ``C = J_l x J_k`` when
``c(l)`` is a strict ancestor of ``c(k)`` and 0 otherwise (Jacobi identity)::

    J_kl,n = J_k x (J_l x J_n) + C x J_n,   Y_kl = L_k(L_l(Y)) + L_C(Y)

External wrenches given in the body frame (``"local"``) turn with their body like ``J``; in
world axes about the world origin (``"world"``) they stay; in world axes about the body origin
(``"local_world_aligned"``) they keep their axes and move with the origin ``p``: ``W = [f; n
+ p x f]``, ``p_k = v_k + w_k x p`` (``J_k = [v_k; w_k]``), ``p_kl = w_k x p_l + C . p``.
The friction's second derivative in ``v``, ``d2/dv2 (b v + F(v) sgn(v))`` with ``F(v) = Fc + Fx
exp(-(v / v_s)^2)`` and ``sgn`` the ``tanh(v / eps)`` of ``Model.coulomb_smoothing`` (or the
sign), is on the diagonal ``i = j = k`` of ``d2tau_dv2``; the springs ``K (q - q_ref)`` (joints
of one dof) and the armature are linear and drop out.

Cost per state: ``3 nv nb`` body steps in pass 2, and in pass 3 ``4 nv^2`` pairs, each visiting
the subtree of its deeper body (a few hundred flops per body) and writing ``nv`` entries.

Reference: S. Singh, R. P. Russell and P. M. Wensing, "Efficient analytical derivatives of
rigid-body dynamics using spatial vector algebra", IEEE Robotics and Automation Letters 7(2),
2022 (the quantities; Pinocchio's ``ComputeRNEASecondOrderDerivatives`` layout); J. Carpentier
and N. Mansard, "Analytical derivatives of rigid body dynamics algorithms", RSS 2018 (the
world-frame derivatives of ``J`` and ``Y``); J. A. Fike and J. J. Alonso, "The development of
hyper-dual numbers for exact second-derivative calculations", AIAA 2011-886.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._jit import core, inline, scratch
from ..spatial import force_act, inertia_act, inertia_matrix, motion_act
from ..layout import (COULOMB, GRAVITY, INERTIA, INERTIA_END, IV, MOTION, NDOF, PARENT, SMOOTHING, STRIBECK,
                      STRIBECK_RATE)
from ..coupling import expand_q, expand_v, is_coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .kinematics import world_poses
from .driver import batch_kernel
from .status import NONFINITE, OK, raise_for_status, require_finite_result

WHAT = "rnea_second_derivatives"
Q_DIR, V_DIR, A_DIR = 0, 1, 2  # the kinds of directions


class RNEASecondDerivatives(NamedTuple):
    """Result of :func:`rnea_second_derivatives`, each (..., nv, nv, nv), entry ``[i, j, k]``:

    * ``d2tau_dq2[i, j, k] = d/dq_k (dtau_i/dq_j)``
    * ``d2tau_dqdv[i, j, k] = d/dv_k (dtau_i/dq_j) = d/dq_j (dtau_i/dv_k)``
    * ``d2tau_dv2[i, j, k] = d/dv_k (dtau_i/dv_j)``
    * ``d2tau_dadq[i, j, k] = d/dq_k (dtau_i/da_j) = dM_ij/dq_k``
    """
    d2tau_dq2: np.ndarray
    d2tau_dqdv: np.ndarray
    d2tau_dv2: np.ndarray
    d2tau_dadq: np.ndarray


# -- spatial algebra, accumulated: out += s * (...) ------------------------------------------
@inline
def _mx_add(m, x, s, out):
    """``out += s (m x x)``: ``m x x = [w x x_lin + v x x_ang; w x x_ang]``, ``m = [v; w]``."""
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    x0, x1, x2, x3, x4, x5 = x[0], x[1], x[2], x[3], x[4], x[5]
    out[0] += s * (w1 * x2 - w2 * x1 + v1 * x5 - v2 * x4)
    out[1] += s * (w2 * x0 - w0 * x2 + v2 * x3 - v0 * x5)
    out[2] += s * (w0 * x1 - w1 * x0 + v0 * x4 - v1 * x3)
    out[3] += s * (w1 * x5 - w2 * x4)
    out[4] += s * (w2 * x3 - w0 * x5)
    out[5] += s * (w0 * x4 - w1 * x3)


@inline
def _fx_add(m, f, s, out):
    """``out += s (m x* f)``: ``m x* f = [w x f_lin; w x f_ang + v x f_lin]``."""
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    f0, f1, f2, f3, f4, f5 = f[0], f[1], f[2], f[3], f[4], f[5]
    out[0] += s * (w1 * f2 - w2 * f1)
    out[1] += s * (w2 * f0 - w0 * f2)
    out[2] += s * (w0 * f1 - w1 * f0)
    out[3] += s * (w1 * f5 - w2 * f4 + v1 * f2 - v2 * f1)
    out[4] += s * (w2 * f3 - w0 * f5 + v2 * f0 - v0 * f2)
    out[5] += s * (w0 * f4 - w1 * f3 + v0 * f1 - v1 * f0)


@inline
def _mv_add(A, x, s, out):
    """``out += s A x`` (6 x 6)."""
    for r in range(6):
        acc = 0.0
        for c in range(6):
            acc += A[r, c] * x[c]
        out[r] += s * acc


@inline
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


@inline
def _zero(x):
    for r in range(x.shape[0]):
        x[r] = 0.0


@inline
def _point_moved(T, p, s, out):
    """``out[3:] += s (T . p) = s (v + w x p)`` (the motion of the point ``p`` under ``T``,
    kept in the angular half of a 6-vector for :func:`_lever_add`)."""
    out[3] += s * (T[0] + T[4] * p[2] - T[5] * p[1])
    out[4] += s * (T[1] + T[5] * p[0] - T[3] * p[2])
    out[5] += s * (T[2] + T[3] * p[1] - T[4] * p[0])


@inline
def _lever_add(dp, f, s, out):
    """``out += s [0; dp x f]`` (``dp`` in ``dp[3:]``, the change of a wrench ``[f; n + p x f]``
    whose point moves by ``dp``)."""
    out[3] += s * (dp[4] * f[2] - dp[5] * f[1])
    out[4] += s * (dp[5] * f[0] - dp[3] * f[2])
    out[5] += s * (dp[3] * f[1] - dp[4] * f[0])


@inline
def _skew_block(x, y, z, X, r0, c0):
    """``X[r0:r0 + 3, c0:c0 + 3] = [(x, y, z)]x``."""
    X[r0, c0 + 1], X[r0, c0 + 2] = -z, y
    X[r0 + 1, c0], X[r0 + 1, c0 + 2] = z, -x
    X[r0 + 2, c0], X[r0 + 2, c0 + 1] = -y, x


@inline
def _inertia_variation(T, Y, X, out):
    """``out = T x* Y - Y (T x)`` (6 x 6): the change of the inertia ``Y`` moved by the motion
    ``T``; ``X`` (6, 6) scratch for ``T x = [[[w]x, [v]x], [0, [w]x]]`` (``T x* = -(T x)^T``)."""
    for r in range(6):
        for c in range(6):
            X[r, c] = 0.0
    _skew_block(T[3], T[4], T[5], X, 0, 0)
    _skew_block(T[3], T[4], T[5], X, 3, 3)
    _skew_block(T[0], T[1], T[2], X, 0, 3)
    for r in range(6):
        for c in range(6):
            acc = 0.0
            for k in range(6):
                acc -= X[k, r] * Y[k, c] + Y[r, k] * X[k, c]
            out[r, c] = acc


# -- one state: the world quantities and the three passes ----------------------------------
# pass 3's blocks of pairs (x, y) = (kind of x, kind of y), and where each goes: the tensor
# (0 d2tau_dq2, 1 d2tau_dqdv, 2 d2tau_dv2, 3 d2tau_dadq) and whether the pair (x_k, y_j)
# fills [i, k, j] (1) or [i, j, k] (0)
BLOCKS = np.array([[Q_DIR, Q_DIR], [Q_DIR, V_DIR], [Q_DIR, A_DIR], [V_DIR, V_DIR]], dtype=np.int64)
TARGET = np.array([[0, 0], [1, 1], [3, 0], [2, 0]], dtype=np.int64)


@scratch
def _workspace(nb, nv):
    """The scratch arrays of :func:`_passes`, zeros: one per worker of the batch driver (which
    zeroes them again for every state: :func:`_state_at`)."""
    return (np.zeros((nv, 6)), np.zeros((nb, 6, 6)), np.zeros((nb, 6)), np.zeros((nb, 3)), np.zeros(10),
            np.zeros((9, nb, 6)), np.zeros((nv, nb, 6, 6)), np.zeros((2, nv, nb, 6)), np.zeros((3 * nv, nv, 6)),
            np.zeros((5, 3 * nv, nb, 6)), np.zeros((nv, 6)), np.zeros((9, 6)), np.zeros((6, 6)))


@core
def _passes(tree, S, theta, oR, op, f, fcode, v, a, a0, out, J, Y, W, fw, th, values, LY, LYv, Jx, firsts, Jxy,
            small, X):
    """One state (:func:`_state_at`) in its workspace (zeros on entry): world columns ``J`` (nv, 6), inertias
    ``Y`` (nb, 6, 6) and wrenches ``W`` (nb, 6) at the world origin, the forces ``fw`` (nb, 3)
    of wrenches about the body origins ``p = op``, ``th`` (10,); ``values`` (9, nb, 6), ``LY``
    (nv, nb, 6, 6), ``LYv`` (2, nv, nb, 6), ``Jx`` (3 nv, nv, 6), ``firsts`` (5, 3 nv, nb, 6),
    ``Jxy`` (nv, 6), ``small`` (9, 6), ``X`` (6, 6)."""
    parent, body_of, iv, nd, anc = tree
    nb, nv = parent.shape[0], J.shape[0]
    p = op
    vJ, ov, oa, h, Yoa, F, ovxy, oaxy, Fxy = (values[0], values[1], values[2], values[3], values[4], values[5],
                                              values[6], values[7], values[8])
    aJ, t, C, hxy, u, w, dp, vJxy, aJxy = (small[0], small[1], small[2], small[3], small[4], small[5], small[6],
                                           small[7], small[8])
    LYov, LYoa = LYv[0], LYv[1]
    vJx, ovx, oax, hx, Fx = firsts[0], firsts[1], firsts[2], firsts[3], firsts[4]
    # world coordinates: Jacobian columns, inertias, wrenches at the origin
    for n in range(nv):
        motion_act(oR[body_of[n]], op[body_of[n]], S[n], J[n])
    for b in range(nb):
        inertia_act(oR[b], op[b], theta[b], th)
        inertia_matrix(th, Y[b], True)
        if fcode == 0:
            force_act(oR[b], op[b], f[b], W[b])
        elif fcode >= 1:
            for r in range(6):
                W[b, r] = f[b, r]
            if fcode == 2:  # [f; n] about the body origin: [f; n + p x f] about the world origin
                for r in range(3):
                    fw[b, r] = f[b, r]
                W[b, 3] += p[b, 1] * f[b, 2] - p[b, 2] * f[b, 1]
                W[b, 4] += p[b, 2] * f[b, 0] - p[b, 0] * f[b, 2]
                W[b, 5] += p[b, 0] * f[b, 1] - p[b, 1] * f[b, 0]
    # pass 1: values
    for b in range(nb):
        par = parent[b]
        _zero(aJ)
        for n in range(iv[b], iv[b] + nd[b]):
            for r in range(6):
                vJ[b, r] += J[n, r] * v[n]
                aJ[r] += J[n, r] * a[n]
        for r in range(6):
            ov[b, r] = vJ[b, r] + (ov[par, r] if par >= 0 else 0.0)
            oa[b, r] = aJ[r] + (oa[par, r] if par >= 0 else a0[r])
        _mx_add(ov[b], vJ[b], 1.0, oa[b])
        _mv_add(Y[b], ov[b], 1.0, h[b])
        _mv_add(Y[b], oa[b], 1.0, Yoa[b])
        for r in range(6):
            F[b, r] = Yoa[b, r] - W[b, r]
        _fx_add(ov[b], h[b], 1.0, F[b])
    for b in range(nb - 1, -1, -1):
        if parent[b] >= 0:
            for r in range(6):
                F[parent[b], r] += F[b, r]
    # the inertias' variations along the q-directions, on the subtrees they move
    for k in range(nv):
        for b in range(nb):
            if anc[body_of[k], b]:
                _inertia_variation(J[k], Y[b], X, LY[k, b])
                _mv_add(LY[k, b], ov[b], 1.0, LYov[k, b])
                _mv_add(LY[k, b], oa[b], 1.0, LYoa[k, b])
    # pass 2: first derivatives along every direction
    for x in range(3 * nv):
        kind, m = x // nv, x % nv
        T = J[m]
        for b in range(nb):
            par = parent[b]
            moves = kind == Q_DIR and anc[body_of[m], b]
            _zero(aJ)
            for n in range(iv[b], iv[b] + nd[b]):
                if moves:
                    _mx_add(T, J[n], 1.0, Jx[x, n])
                for r in range(6):
                    vJx[x, b, r] += Jx[x, n, r] * v[n]
                    aJ[r] += Jx[x, n, r] * a[n]
                if n == m and kind == V_DIR:
                    for r in range(6):
                        vJx[x, b, r] += J[n, r]
                if n == m and kind == A_DIR:
                    for r in range(6):
                        aJ[r] += J[n, r]
            for r in range(6):
                ovx[x, b, r] = vJx[x, b, r] + (ovx[x, par, r] if par >= 0 else 0.0)
                oax[x, b, r] = aJ[r] + (oax[x, par, r] if par >= 0 else 0.0)
            _mx_add(ovx[x, b], vJ[b], 1.0, oax[x, b])
            _mx_add(ov[b], vJx[x, b], 1.0, oax[x, b])
            _mv_add(Y[b], ovx[x, b], 1.0, hx[x, b])
            _mv_add(Y[b], oax[x, b], 1.0, Fx[x, b])
            if moves:
                for r in range(6):
                    hx[x, b, r] += LYov[m, b, r]
                    Fx[x, b, r] += LYoa[m, b, r]
                if fcode == 0:
                    _fx_add(T, W[b], -1.0, Fx[x, b])
                elif fcode == 2:
                    _zero(t)
                    _point_moved(T, p[b], 1.0, t)
                    _lever_add(t, fw[b], -1.0, Fx[x, b])
            _fx_add(ovx[x, b], h[b], 1.0, Fx[x, b])
            _fx_add(ov[b], hx[x, b], 1.0, Fx[x, b])
        for b in range(nb - 1, -1, -1):
            if parent[b] >= 0:
                for r in range(6):
                    Fx[x, parent[b], r] += Fx[x, b, r]
    # pass 3: mixed derivatives along every pair (x, y) of BLOCKS, written where TARGET says
    for pr in range(4 * nv * nv):
        blk, k, j = pr // (nv * nv), (pr // nv) % nv, pr % nv
        x, y = BLOCKS[blk, 0] * nv + k, BLOCKS[blk, 1] * nv + j
        kx, mx, ky, my = x // nv, k, y // nv, j
        bx, by = body_of[mx], body_of[my]
        t_out, swap = TARGET[blk, 0], TARGET[blk, 1] == 1
        for n in range(nv):
            if swap:
                out[t_out, n, k, j] = 0.0
            else:
                out[t_out, n, j, k] = 0.0
        if not (anc[bx, by] or anc[by, bx]):
            continue  # on no common path: no mixed term
        deep = by if anc[bx, by] else bx
        qq = kx == Q_DIR and ky == Q_DIR
        Tx, Ty = J[mx], J[my]
        _zero(C)
        if qq and by != bx and anc[by, bx]:  # c(y) a strict ancestor of c(x): exp(J_y) exp(J_x)
            _mx_add(Ty, Tx, 1.0, C)
        for b in range(deep, nb):  # the subtree of deep, parents first
            if not anc[deep, b]:
                continue
            par = parent[b]
            _zero(vJxy)
            _zero(aJxy)
            _zero(Fxy[b])
            for n in range(iv[b], iv[b] + nd[b]):
                _zero(Jxy[n])
                if qq:
                    _zero(u)
                    _mx_add(Ty, J[n], 1.0, u)
                    _mx_add(Tx, u, 1.0, Jxy[n])
                    _mx_add(C, J[n], 1.0, Jxy[n])
                for r in range(6):
                    vJxy[r] += Jxy[n, r] * v[n]
                    aJxy[r] += Jxy[n, r] * a[n]
                if n == my and ky == V_DIR:
                    for r in range(6):
                        vJxy[r] += Jx[x, n, r]
                if n == mx and kx == V_DIR:
                    for r in range(6):
                        vJxy[r] += Jx[y, n, r]
                if n == my and ky == A_DIR:
                    for r in range(6):
                        aJxy[r] += Jx[x, n, r]
                if n == mx and kx == A_DIR:
                    for r in range(6):
                        aJxy[r] += Jx[y, n, r]
            for r in range(6):
                ovxy[b, r] = vJxy[r] + (ovxy[par, r] if b != deep else 0.0)
                oaxy[b, r] = aJxy[r] + (oaxy[par, r] if b != deep else 0.0)
            _mx_add(ovxy[b], vJ[b], 1.0, oaxy[b])
            _mx_add(ovx[x, b], vJx[y, b], 1.0, oaxy[b])
            _mx_add(ovx[y, b], vJx[x, b], 1.0, oaxy[b])
            _mx_add(ov[b], vJxy, 1.0, oaxy[b])
            # h_xy = Y ov_xy + Y_x ov_y + Y_y ov_x + Y_xy ov;  f_xy likewise with oa, plus the products
            _zero(hxy)
            f = Fxy[b]
            _mv_add(Y[b], ovxy[b], 1.0, hxy)
            _mv_add(Y[b], oaxy[b], 1.0, f)
            if kx == Q_DIR:
                _mv_add(LY[mx, b], ovx[y, b], 1.0, hxy)
                _mv_add(LY[mx, b], oax[y, b], 1.0, f)
            if ky == Q_DIR:
                _mv_add(LY[my, b], ovx[x, b], 1.0, hxy)
                _mv_add(LY[my, b], oax[x, b], 1.0, f)
            if qq:  # Y_xy u = T_x x* (L_y u) - L_y (T_x x u) + C x* (Y u) - Y (C x u), u = ov, oa
                _fx_add(Tx, LYov[my, b], 1.0, hxy)
                _fx_add(Tx, LYoa[my, b], 1.0, f)
                _fx_add(C, h[b], 1.0, hxy)
                _fx_add(C, Yoa[b], 1.0, f)
                _zero(u)
                _mx_add(Tx, ov[b], 1.0, u)
                _mv_add(LY[my, b], u, -1.0, hxy)
                _zero(u)
                _mx_add(Tx, oa[b], 1.0, u)
                _mv_add(LY[my, b], u, -1.0, f)
                _zero(w)
                _mx_add(C, ov[b], 1.0, w)
                _mv_add(Y[b], w, -1.0, hxy)
                _zero(w)
                _mx_add(C, oa[b], 1.0, w)
                _mv_add(Y[b], w, -1.0, f)
                if fcode == 0:  # W_xy = T_x x* (T_y x* W) + C x* W
                    _zero(u)
                    _fx_add(Ty, W[b], 1.0, u)
                    _fx_add(Tx, u, -1.0, f)
                    _fx_add(C, W[b], -1.0, f)
                elif fcode == 2:  # p_xy = w_x x p_y + C . p
                    _zero(dp)
                    _point_moved(Ty, p[b], 1.0, dp)
                    _zero(u)
                    for r in range(3):
                        u[3 + r] = Tx[3 + (r + 1) % 3] * dp[3 + (r + 2) % 3] - Tx[3 + (r + 2) % 3] * dp[3 + (r + 1) % 3]
                    _point_moved(C, p[b], 1.0, u)
                    _lever_add(u, fw[b], -1.0, f)
            _fx_add(ovxy[b], h[b], 1.0, f)
            _fx_add(ovx[x, b], hx[y, b], 1.0, f)
            _fx_add(ovx[y, b], hx[x, b], 1.0, f)
            _fx_add(ov[b], hxy, 1.0, f)
        for b in range(nb - 1, deep, -1):  # F_xy: the sums over the subtree of deep ...
            if anc[deep, b]:
                for r in range(6):
                    Fxy[parent[b], r] += Fxy[b, r]
        for n in range(nv):  # ... and F_xy[deep] above it; the rows on the path of deep and below
            c = body_of[n]
            if anc[deep, c]:
                val = _dot(J[n], Fxy[c]) + _dot(Jx[x, n], Fx[y, c]) + _dot(Jx[y, n], Fx[x, c]) + _dot(Jxy[n], F[c])
            elif anc[c, deep]:
                val = _dot(J[n], Fxy[deep]) + _dot(Jx[x, n], Fx[y, c]) + _dot(Jx[y, n], Fx[x, c])
            else:
                continue
            if swap:
                out[t_out, n, k, j] = val
            else:
                out[t_out, n, j, k] = val


@inline
def _state_at(args, s, ws):
    """:func:`_passes` of state ``s`` of a batch (``f``: (B or 1, nb, 6)) in the worker's
    scratch ``ws`` (:func:`_workspace`; no allocation here, where reference counting is off)."""
    parent, body_of, iv, nd, anc, S, theta, oR, op, f, fcode, V, A, a0, out = args  # flat: a parallel
    tree = (parent, body_of, iv, nd, anc)                                           # loop takes no nested tuples
    J, Y, W, fw, th, values, LY, LYv, Jx, firsts, Jxy, small, X = ws
    for x2 in (J, W, fw, Jxy, small, X):  # zeros on entry, as _passes needs them
        _zero(x2)
    for x3 in (Y, values, Jx):
        _zero(x3)
    for x4 in (LY, LYv, firsts):
        _zero(x4)
    _zero(th)
    _passes(tree, S, theta, oR[s], op[s], f[s if f.shape[0] > 1 else 0], fcode, V[s], A[s], a0, out[s], J, Y, W,
            fw, th, values, LY, LYv, Jx, firsts, Jxy, small, X)
    return OK


_batch = batch_kernel(_state_at, _workspace)


# -- the Python layer: world quantities, directions, friction ------------------------------
def _tree(model):
    """``(parent, body_of, iv, nd, anc)``: the parent of each body, the body of each dof, each
    body's first dof and dof count, and ``anc[a, b]`` when ``a`` is an ancestor of ``b`` or ``b``
    itself (parents precede their children)."""
    ints = model.kernel.ints
    parent, iv, nd = ints[:, PARENT].copy(), ints[:, IV].copy(), ints[:, NDOF].copy()
    nb = parent.shape[0]
    order = np.argsort(iv, kind="stable")
    body_of = np.repeat(order, nd[order]).astype(np.int64)
    anc = np.zeros((nb, nb), dtype=np.bool_)
    for b in range(nb):
        if parent[b] >= 0:
            anc[:, b] = anc[:, parent[b]]
        anc[b, b] = True
    return parent, body_of, iv, nd, anc


def _friction_dv2(dofs, eps, v):
    """``d2/dv2`` (B, nv) of the passive torque ``b v + F(v) sgn(v)`` of
    :func:`robodyn.joint_kernels.passive_torque`, ``F(v) = Fc + Fx exp(-(v r)^2)`` (``r = 1 /
    v_s``): ``F'' sgn + 2 F' sgn' + F sgn''`` with ``sgn = tanh(v / eps)`` (``sgn' = (1 - s^2) /
    eps``, ``sgn'' = -2 s sgn' / eps``) or the sign (``sgn' = sgn'' = 0``)."""
    fc, fx, r = dofs[:, COULOMB], dofs[:, STRIBECK], dofs[:, STRIBECK_RATE]
    x = v * r
    g = fx * np.exp(-x * x)
    F, dF, ddF = fc + g, -2.0 * x * r * g, 2.0 * r * r * g * (2.0 * x * x - 1.0)
    if eps > 0.0:
        s = np.tanh(v / eps)
        ds = (1.0 - s * s) / eps
        dds = -2.0 * s * ds / eps
        return ddF * s + 2.0 * dF * ds + F * dds
    return ddF * np.sign(v)


def rnea_second_derivatives(model, q, v, a, f_ext=None, frame: str = "local", *, friction: bool = True,
                            armature: bool = True, check_finite: bool = True) -> RNEASecondDerivatives:
    """Second-order partial derivatives of inverse dynamics, ``tau = rnea(q, v, a, f_ext)``, exact.

    Entry ``[i, j, k]`` of each tensor is ``d/dx_k (dtau_i/dy_j)`` for ``d2tau_dydx``, the
    layout of Pinocchio's ``ComputeRNEASecondOrderDerivatives`` (``d2tau_dqdq``,
    ``d2tau_dqdv``, ``d2tau_dvdv``, ``d2tau_dadq``)::

        d2tau_dq2[:, j, k]  = d/deps [dtau_dq(q ⊕ eps e_k, v, a)[:, j]] at 0
        d2tau_dqdv[:, j, k] = d/dv_k dtau_dq[:, j] = d/deps [dtau_dv(q ⊕ eps e_j, v, a)[:, k]]
        d2tau_dv2[:, j, k]  = d/dv_k dtau_dv[:, j]                 (symmetric in j, k)
        d2tau_dadq[:, j, k] = d/deps [M(q ⊕ eps e_k)[:, j]]         (dM/dq_k, symmetric in i, j)

    with ``(dtau_dq, dtau_dv, M)`` of :func:`robodyn.rnea_derivatives` and ``⊕`` the step of
    :func:`robodyn.integrate` (the tangent space). ``d2tau_dq2`` is symmetric in ``j, k`` when
    every joint has one dof (coordinates then add). For two dofs of one free, spherical or
    planar joint the steps do not commute (``exp(A) exp(B) != exp(B) exp(A)``) and
    ``d2tau_dq2[:, j, k] - d2tau_dq2[:, k, j] = dtau_dq @ [S_k, S_j]``, the Lie bracket of the
    two tangent directions in the joint's coordinates. Without friction ``d2tau_dv2 = Gamma +
    Gamma^T`` (last two axes) for the Christoffel symbols of :func:`robodyn.christoffel_symbols`.

    Exact to rounding (no step size): second-order forward-mode (hyper-dual) differentiation of
    the world-frame Newton-Euler equations, the tangent directions moving each subtree rigidly
    (see ``robodyn/algorithms/rnea_second_derivatives.py``); compiled, batches in parallel.

    Args:
        q: (..., nq). v, a: (..., nv).
        f_ext, frame: external wrenches (..., nbodies, 6) ``[force, torque]`` in ``"local"``,
            ``"world"`` or ``"local_world_aligned"`` coordinates, as in :func:`robodyn.rnea`
            (in the body frame they turn with their body; in world axes they keep their
            direction). They enter ``d2tau_dq2`` only.
        friction: include the friction's second derivative, ``d2/dv2 (b v + F(v) sgn(v))``, on
            the diagonal of ``d2tau_dv2`` (smoothed Coulomb friction and the Stribeck level; the
            unsmoothed sign contributes through the Stribeck level only). The joint springs are
            linear in ``q`` and contribute nothing.
        armature: accepted as in :func:`robodyn.rnea`; the armature's term ``armature * a`` is
            linear, so no tensor depends on it.
        check_finite: check the inputs and the results for NaN/Inf.

    Returns:
        :class:`RNEASecondDerivatives` ``(d2tau_dq2, d2tau_dqdv, d2tau_dv2, d2tau_dadq)``, each
        (..., nv, nv, nv).

    Raises ValueError naming the argument for bad shapes, NaN/Inf and quaternions far from unit
    norm, as :func:`robodyn.rnea_derivatives`. Reference: Singh, Russell and Wensing, "Efficient
    analytical derivatives of rigid-body dynamics using spatial vector algebra", IEEE RA-L 7(2),
    2022.
    """
    if frame not in _inputs.WRENCH_FRAMES:
        raise ValueError(f"frame must be one of {sorted(_inputs.WRENCH_FRAMES)}, got {frame!r}")
    if any_lazy(q, v, a, f_ext):
        return deferred(rnea_second_derivatives, locals())
    if is_coupled(model):  # mimic joints: T_ijk = sum G_ai G_bj G_ck T_full_abc at (E(q), G v, G a)
        full = rnea_second_derivatives(model.full, expand_q(model, q), expand_v(model, v), expand_v(model, a, "a"),
                                       f_ext, frame, friction=friction, armature=armature, check_finite=check_finite)
        G = model.G
        return RNEASecondDerivatives(*(np.einsum("...abc,ai,bj,ck->...ijk", T, G, G, G) for T in full))
    batch, x = _inputs.states(model, q=q, v=v, a=a)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    if check_finite:
        for name in ("v", "a"):
            if not np.isfinite(x[name]).all():
                raise_for_status(model, NONFINITE, {name: x[name]}, WHAT)
    oR, op = world_poses(model, x["q"], batch, check_finite, WHAT)
    V, A = _inputs.as_batch(x["v"]), _inputs.as_batch(x["a"])
    nv, B, k = model.nv, V.shape[0], model.kernel
    S = np.ascontiguousarray(k.dofs[(False, False)][:, MOTION:MOTION + 6])
    theta = np.ascontiguousarray(k.body[:, INERTIA:INERTIA_END])
    a0 = np.concatenate([-k.params[True][GRAVITY:GRAVITY + 3], np.zeros(3)])
    res = np.empty((B, 4, nv, nv, nv))
    F = F if F.flags.writeable else F.copy()  # the kernels are compiled for writeable arrays (see layout)
    oR, op, F = _inputs.batched(batch, oR, op, F)
    _batch.run(_tree(model) + (S, theta, oR, op, F, np.int64(fcode), V, A, a0, res), (model.nbodies, nv),
               np.empty(B, dtype=np.int64), batch)
    out = [res[0, t] if batch == () else np.ascontiguousarray(res[:, t]) for t in range(4)]
    if friction and nv:
        with np.errstate(all="ignore"):  # NaN/Inf when check_finite=False: the check below says so
            extra = _friction_dv2(k.dofs[(True, False)], k.params[True][SMOOTHING], V)
        d = np.arange(nv)
        if batch == ():
            out[2][d, d, d] += extra[0]
        else:
            out[2][:, d, d, d] += extra
    if check_finite:
        for o in out:
            require_finite_result(WHAT, o, True, x)
    return RNEASecondDerivatives(*(_inputs.unflatten(o, batch) for o in out))
