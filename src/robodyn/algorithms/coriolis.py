"""Coriolis matrix ``C(q, v)`` with ``Mdot - 2C`` skew-symmetric, O(n d) (d: tree depth).

With world-frame Jacobians ``J_i`` and inertias ``I_i`` (Echeandia and Wensing, "Numerical
methods to compute the Coriolis matrix and Christoffel symbols for rigid-body systems",
J. Comput. Nonlinear Dynam. 2021)::

    C = sum_i J_i^T (I_i Jdot_i + B_i J_i),
    B_i = 1/2 [ (V_i x*) I_i - I_i (V_i x) + (I_i V_i) xbar ],    (f xbar) m = m x* f

so that ``C v`` is the Coriolis/centrifugal vector (``B_i V_i = V_i x* I_i V_i``) and
``Mdot - 2C = Jdot^T I J - J^T I Jdot`` is skew-symmetric. Accumulating composite ``I^c`` and
``B^c`` from the leaves, for a dof ``k`` of body ``i`` (``Sdot_k = V_i x oS_k``) and a dof ``l``
of ``i`` or of an ancestor::

    C[l, k] = oS_l . (I^c_i Sdot_k + B^c_i oS_k)
    C[k, l] = Sdot_l . (I^c_i oS_k) + oS_l . (B^c_i^T oS_k)     (l on a strict ancestor)

``C`` is linear in ``v`` and equals ``C_ij = sum_k Gamma_ijk v_k`` with the Christoffel symbols
of the first kind ``Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2``.
"""

from __future__ import annotations

import numpy as np
from numba import boolean

from .._jit import MAT, MODEL_INTS, MODEL_PACKED, VEC, core, fast, inline, scratch
from ..joint_kernels import nq_of
from ..layout import IV, NDOF, PARENT
from ..spatial import dot6, inertia_mul, matTvec6, matvec6, motion_cross, motion_cross_matrix
from ..coupling import expand_q, expand_v, into, is_coupled, reduce_matrix
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .crba import world_state
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, take
from ._inputs import fits, unpack
from .status import OK, WRONG_SIZE, finite2, result_status
from .driver import batch_kernel


@scratch
def workspace(nb, nv):
    """Scratch of :func:`coriolis_one`: ``(buffer, (liR, lip, oR, op, Rj, pj), oS, oSd, Ic, Bc, oV, K,
    Vx, F1, F2, F3, h)``."""
    buf = np.empty((POSES_SIZE_NB + 52) * nb + 12 * nv + POSES_SIZE + 96)
    P, o = poses(buf, 0, nb)
    oS, o = take(buf, o, (nv, 6))
    oSd, o = take(buf, o, (nv, 6))
    Ic, o = take(buf, o, (nb, 10))
    Bc, o = take(buf, o, (nb, 6, 6))
    oV, o = take(buf, o, (nb, 6))
    K, o = take(buf, o, (6, 6))
    Vx, o = take(buf, o, (6, 6))
    F1, o = take(buf, o, (6,))
    F2, o = take(buf, o, (6,))
    F3, o = take(buf, o, (6,))
    h, o = take(buf, o, (6,))
    return buf, P, oS, oSd, Ic, Bc, oV, K, Vx, F1, F2, F3, h


@inline
def body_B(theta, V, K, Vx, h, B):
    """``B = 1/2 [ (V x*) I - I (V x) + (I V) xbar ]`` (6 x 6) of one body.

    With ``K = I (V x)`` and ``(V x*) = -(V x)^T``: ``(V x*) I - I (V x) = -(K + K^T)``.
    """
    motion_cross_matrix(V, Vx)
    for c in range(6):
        inertia_mul(theta, Vx[:, c], h)
        for r in range(6):
            K[r, c] = h[r]
    for r in range(6):
        for c in range(r, 6):
            B[r, c] = -0.5 * (K[r, c] + K[c, r])
            B[c, r] = B[r, c]
    inertia_mul(theta, V, h)
    # (h xbar) = [[0, -[f]x], [-[f]x, -[n]x]] with h = [f; n]
    f0, f1, f2, n0, n1, n2 = h[0], h[1], h[2], h[3], h[4], h[5]
    for o_r, o_c, a0, a1, a2 in ((0, 3, f0, f1, f2), (3, 0, f0, f1, f2), (3, 3, n0, n1, n2)):
        B[o_r + 0, o_c + 1] += 0.5 * a2
        B[o_r + 0, o_c + 2] -= 0.5 * a1
        B[o_r + 1, o_c + 0] -= 0.5 * a2
        B[o_r + 1, o_c + 2] += 0.5 * a0
        B[o_r + 2, o_c + 0] += 0.5 * a1
        B[o_r + 2, o_c + 1] -= 0.5 * a0


@core
def coriolis_one(ints, body, dofs, q, v, check, C, ws):
    _, P, oS, oSd, Ic, Bc, oV, K, Vx, F1, F2, F3, h = ws
    nb = ints.shape[0]
    if not (q.shape[0] == nq_of(ints) and v.shape[0] == dofs.shape[0]):
        return WRONG_SIZE
    status = world_state(ints, body, dofs, q, v, check, P, oS, Ic)
    if status != OK:
        return status
    for i in range(nb):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        for r in range(6):
            oV[i, r] = oV[par, r] if par >= 0 else 0.0
        for k in range(iv, iv + n):
            for r in range(6):
                oV[i, r] += oS[k, r] * v[k]
        for k in range(iv, iv + n):
            motion_cross(oV[i], oS[k], oSd[k])
        body_B(Ic[i], oV[i], K, Vx, h, Bc[i])
    C[:, :] = 0.0
    for i in range(nb - 1, -1, -1):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        for k in range(iv, iv + n):
            inertia_mul(Ic[i], oSd[k], F1)
            matvec6(Bc[i], oS[k], F2)
            for r in range(6):
                F1[r] += F2[r]
            inertia_mul(Ic[i], oS[k], F2)
            matTvec6(Bc[i], oS[k], F3)
            for l in range(iv, iv + n):
                C[l, k] = dot6(oS[l], F1)
            j = par
            while j >= 0:
                for l in range(ints[j, IV], ints[j, IV] + ints[j, NDOF]):
                    C[l, k] = dot6(oS[l], F1)
                    C[k, l] = dot6(oSd[l], F2) + dot6(oS[l], F3)
                j = ints[j, PARENT]
        if par >= 0:
            for r in range(10):
                Ic[par, r] += Ic[i, r]
            for r in range(6):
                for c in range(6):
                    Bc[par, r, c] += Bc[i, r, c]
    return result_status(check, finite2(C))


@inline
def coriolis_at(args, s, ws):
    """The Coriolis matrix of state ``s`` of a batch."""
    ints, body, dofs, Q, V, check, CC = args
    return coriolis_one(ints, body, dofs, Q[s], V[s], check, CC[s], ws)


_coriolis_batch = batch_kernel(coriolis_at, workspace)


@fast(MODEL_INTS, MODEL_PACKED, VEC, VEC, boolean, MAT)
def _coriolis_packed(ints, packed, q, v, check, C):
    """One state, the model in one array (the fast path; like the RNEA's, it calls
    :func:`coriolis_one` directly rather than the batch's code: a call passing the batch's
    arguments cost 5 % of this one)."""
    body, dofs, _, _ = unpack(ints, packed)
    if not fits(C, dofs.shape[0], q, v, v):
        return WRONG_SIZE
    return coriolis_one(ints, body, dofs, q, v, check, C, workspace(ints.shape[0], dofs.shape[0]))


def _run(model, batch, x, check, what, out=None):
    """The Coriolis matrices of the checked states ``x`` into ``out`` (see ``_inputs.output``):
    returns ``(C, result)``, the kernel's flat array and the one to return."""
    k = model.kernel
    C, result = _inputs.output(out, batch, (model.nv, model.nv), x)
    Q, V, CC = _inputs.batched(batch, x["q"], x["v"], C)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args, sizes = (k.ints, k.body, k.dofs[(False, False)], Q, V, check, CC), (model.nbodies, model.nv)
    _coriolis_batch.run(args, sizes, status, batch)
    raise_for_status(model, status, x, what)
    return C, result


def coriolis_matrix(model, q, v, *, check_finite: bool = True, out: np.ndarray | None = None) -> np.ndarray:
    """Coriolis matrix ``C(q, v)``: (..., nv, nv) for q (..., nq), v (..., nv).

    ``C v`` is the Coriolis/centrifugal vector ``nonlinear_effects(q, v) - gravity(q)``,
    ``Mdot - 2C`` is skew-symmetric and ``C_ij = sum_k Gamma_ijk v_k`` with the Christoffel
    symbols of :func:`christoffel_symbols`. ``out``: an optional (..., nv, nv) C-contiguous
    float64 array to write into and return (see :func:`robodyn.rnea`). Reference: Echeandia
    and Wensing (2021).
    """
    C = _inputs.fast_out(out, (model.nv, model.nv))  # fast path for one state: the kernel checks sizes and values
    try:
        k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
        if _coriolis_packed(k.ints, k.packed[False, False], q, v, check_finite, C) == OK:
            return C
    except (TypeError, AttributeError):  # not contiguous float64 arrays
        pass
    if any_lazy(q, v):
        return deferred(coriolis_matrix, locals())
    if is_coupled(model):  # G^T C_full(E(q), G v) G
        C = coriolis_matrix(model.full, expand_q(model, q), expand_v(model, v), check_finite=check_finite)
        return into(out, reduce_matrix(model, C))
    batch, x = _inputs.states(model, q=q, v=v)
    return _run(model, batch, x, check_finite, "coriolis_matrix", out)[1]


def christoffel_symbols(model, q, *, check_finite: bool = True) -> np.ndarray:
    """Christoffel symbols of the first kind, ``Gamma[..., i, j, k]`` (..., nv, nv, nv).

    ``Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2``, symmetric in ``j, k``, and
    ``coriolis_matrix(q, v)[i, j] == sum_k Gamma[i, j, k] v[k]``. Since ``C`` is linear in
    ``v``, ``Gamma[..., :, :, k] = C(q, e_k)``. For a floating base the base velocity is a
    quasi-velocity (not the derivative of ``q``), as is the angular velocity of a spherical
    joint; ``Gamma`` is then still defined by ``C(q, e_k)`` and satisfies ``C = Gamma v``, but
    it is not symmetric in ``j, k`` for those directions.
    """
    if any_lazy(q):
        return deferred(christoffel_symbols, locals())
    if is_coupled(model):  # Gamma_ijk = sum G_ai G_bj G_ck Gamma_full_abc
        G = model.G
        return np.einsum("...abc,ai,bj,ck->...ijk", christoffel_symbols(model.full, expand_q(model, q),
                                                                          check_finite=check_finite), G, G, G)
    batch, x = _inputs.states(model, q=q)
    nv = model.nv
    Q = np.repeat(_inputs.as_batch(x["q"]), nv, axis=0)
    V = np.tile(np.eye(nv), (Q.shape[0] // nv, 1))
    CC = _run(model, (Q.shape[0],), {"q": Q, "v": V}, check_finite, "christoffel_symbols")[0].reshape(-1, nv, nv, nv)
    G = np.ascontiguousarray(CC.transpose(0, 2, 3, 1))  # (B, k, i, j) -> (B, i, j, k)
    return G[0] if batch == () else G.reshape(batch + (nv, nv, nv))
