"""Analytical first derivatives of forward dynamics: ``dqdd/dq``, ``dqdd/dv`` and ``dqdd/dtau = M^-1``.

Forward dynamics inverts inverse dynamics: ``rnea(q, v, aba(q, v, tau)) = tau`` for every
``(q, v, tau)``. Differentiating this identity at ``qdd = aba(q, v, tau)``::

    dtau/dq + M dqdd/dq = 0,   dtau/dv + M dqdd/dv = 0,   M dqdd/dtau = 1

so ``dqdd/dq = -M^-1 dtau/dq``, ``dqdd/dv = -M^-1 dtau/dv`` and ``dqdd/dtau = M^-1``, with the
partial derivatives of the RNEA (``rnea_derivatives.py``) taken at ``(q, v, qdd)`` and ``M^-1``
from the O(n^2) recursion of ``minv.py`` (``M`` includes the armature when it is on; friction
and external wrenches enter through ``dtau/dq`` and ``dtau/dv``). With ``M^-1`` at hand, the
acceleration is ``qdd = M^-1 (tau - h)``, ``h = rnea(q, v, 0)`` (cheaper than a second
articulated-body pass; both carry the rounding of a solve with ``M``). Derivatives with respect to
``q`` are in the tangent space of :func:`robodyn.integrate`, as Pinocchio's
``computeABADerivatives``.

Reference: J. Carpentier and N. Mansard, "Analytical derivatives of rigid body dynamics
algorithms", Robotics: Science and Systems, 2018, section IV.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._deprecated import renamed_keyword
from .._jit import MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, by_address, core, fast, inline, scratch
from ..coupling import is_coupled
from . import coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from . import rnea as _rnea
from . import minv as _minv
from . import rnea_derivatives as _rd
from ._inputs import fits, unpack
from ._workspace import row
from .driver import batch_kernel
from .status import (NO_WRENCH, NONFINITE, OK, WRONG_SIZE, finite, finite2, raise_for_status, raise_singular,
                     result_status)


@scratch
def workspace(nb, nv):
    """Scratch of :func:`derivatives_one`: the workspaces of the RNEA, its derivatives and
    ``M^-1``, then ``(qdd, h, dtau_dq, dtau_dv, an empty M)``."""
    return (_rnea.workspace(nb), _rd.workspace(nb, nv), _minv.workspace(nb, nv),
            (np.empty(nv), np.empty(nv), np.empty((nv, nv)), np.empty((nv, nv)), np.empty((0, 0))))


@inline
def transpose(B):
    """Transposes the square matrix ``B`` in place."""
    n = B.shape[0]
    for i in range(n):
        for j in range(i):
            B[i, j], B[j, i] = B[j, i], B[i, j]


@inline
def nonzero_length(B, i):
    """The length of row ``i`` of ``B`` without its trailing zeros."""
    m = B.shape[1]
    while m > 0 and B[i, m - 1] == 0.0:
        m -= 1
    return m


@inline
def dot_rows(A, i, B, j, m):
    """``A[i, :m] . B[j, :m]``, the dot product of the first ``m`` entries of two rows."""
    s = 0.0
    for k in range(m):
        s += A[i, k] * B[j, k]
    return s


@inline
def neg_product_t(A, BT, out):
    """``out = -A BT^T`` for square (n, n) matrices: each entry is minus the dot product of a
    row of ``A`` and a row of ``BT`` (both contiguous), up to the last nonzero of the row of
    ``BT`` (a column of ``dtau/dq`` or ``dtau/dv`` is zero past the subtree of its dof, in the
    depth-first order of the dofs: on Talos, a third of the terms). Two rows of ``BT`` by four
    rows of ``A`` at a time: one pass over ``k`` sums eight products (the compiler vectorizes
    it; each loaded element serves two or four of them); single dot products at the edges."""
    n = A.shape[0]
    n4, n2 = n - n % 4, n - n % 2
    for c in range(0, n2, 2):
        m = max(nonzero_length(BT, c), nonzero_length(BT, c + 1))
        for r in range(0, n4, 4):
            s00 = s01 = s10 = s11 = s20 = s21 = s30 = s31 = 0.0
            for k in range(m):
                b0, b1 = BT[c, k], BT[c + 1, k]
                a0, a1, a2, a3 = A[r, k], A[r + 1, k], A[r + 2, k], A[r + 3, k]
                s00 += a0 * b0
                s01 += a0 * b1
                s10 += a1 * b0
                s11 += a1 * b1
                s20 += a2 * b0
                s21 += a2 * b1
                s30 += a3 * b0
                s31 += a3 * b1
            out[r, c], out[r, c + 1], out[r + 1, c], out[r + 1, c + 1] = -s00, -s01, -s10, -s11
            out[r + 2, c], out[r + 2, c + 1], out[r + 3, c], out[r + 3, c + 1] = -s20, -s21, -s30, -s31
        for r in range(n4, n):
            out[r, c] = -dot_rows(A, r, BT, c, m)
            out[r, c + 1] = -dot_rows(A, r, BT, c + 1, m)
    for c in range(n2, n):
        m = nonzero_length(BT, c)
        for r in range(n):
            out[r, c] = -dot_rows(A, r, BT, c, m)


# M^-1, the RNEA and its derivatives: called at their compiled code's address, not copied (``_jit``).
_minv_one, _rnea_one = by_address(_minv.minv_one), by_address(_rnea.rnea_one)
_rnea_derivatives_one = by_address(_rd.derivatives_one)


@core
def derivatives_one(ints, body, dofs, params, q, v, tau, fext, fcode, check, da_dq, da_dv, Minv, ws):
    """``da_dq``, ``da_dv`` and ``Minv = da_dtau`` (nv, nv) at one state; returns a status (see
    ``_inputs``), ``i + 1`` when the articulated inertia of body ``i`` is singular."""
    rnea_ws, rd_ws, minv_ws, (qdd, b, dq, dv, M0) = ws
    nv = dofs.shape[0]
    if tau.shape[0] != nv:
        return WRONG_SIZE
    if check and not finite(tau):
        return NONFINITE
    status = _minv_one(ints, body, dofs, q, check, Minv, minv_ws)
    if status != OK:
        return status
    for k in range(nv):
        qdd[k] = 0.0
    status = _rnea_one(ints, body, dofs, params, q, v, qdd, fext, fcode, check, b, rnea_ws)
    if status != OK:
        return status
    for r in range(nv):  # qdd = M^-1 (tau - h)
        s = 0.0
        for k in range(nv):
            s += Minv[r, k] * (tau[k] - b[k])
        qdd[r] = s
    status = _rnea_derivatives_one(ints, body, dofs, params, q, v, qdd, fext, fcode, False, dq, dv, M0, rd_ws)
    if status != OK:
        return status
    transpose(dq)  # dq and dv are scratch: the products read their columns as rows
    transpose(dv)
    neg_product_t(Minv, dq, da_dq)
    neg_product_t(Minv, dv, da_dv)
    return result_status(check, finite2(da_dq) and finite2(da_dv))


@inline
def derivatives_at(args, s, ws):
    """:func:`derivatives_one` of state ``s`` of a batch."""
    ints, body, dofs, params, Q, V, T, F, fcode, check, DQ, DV, MI = args
    return derivatives_one(ints, body, dofs, params, Q[s], V[s], T[s], F[s if F.shape[0] > 1 else 0], fcode, check,
                           DQ[s], DV[s], MI[s], ws)


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, MAT, MAT, MAT, TENSOR, int64, boolean, TENSOR, TENSOR, TENSOR),
             (int64, int64))
_derivatives_batch = batch_kernel(derivatives_at, workspace, one_state=ONE_STATE)
_derivatives_call_one = _derivatives_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, boolean, MAT, MAT, MAT)
def _derivatives_packed(address, ints, packed, q, v, tau, check, da_dq, da_dv, Minv):
    """One state without external wrenches, the model in one array (the fast path): the
    batch's code at ``address`` (``_derivatives_batch.one_address``) for a batch of one."""
    body, dofs, params, zero = unpack(ints, packed)
    nv = dofs.shape[0]
    if not (fits(da_dq, nv, q, v, tau) and fits(da_dv, nv, q, v, tau) and fits(Minv, nv, q, v, tau)):
        return WRONG_SIZE
    args = (ints, body, dofs, params, row(q), row(v), row(tau), row(zero), int64(NO_WRENCH), check, row(da_dq),
            row(da_dv), row(Minv))
    return _derivatives_call_one(address, args, workspace(ints.shape[0], nv))


def aba_derivatives(model, q, v, tau, f_ext=None, frame: str = "local", *, friction: bool = True,
                    armature: bool = True, check_finite: bool = True,
                    f_ext_frame=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of forward dynamics, ``qdd = aba(q, v, tau, f_ext)``, analytical.

    ``dqdd_dq = -M^-1 dtau_dq``, ``dqdd_dv = -M^-1 dtau_dv`` (the derivatives of
    :func:`robodyn.rnea_derivatives` at ``qdd``) and ``dqdd_dtau = M^-1``; derivatives with
    respect to ``q`` are in the tangent space of :func:`robodyn.integrate`, as Pinocchio's
    ``computeABADerivatives``.

    Args:
        q: (..., nq). v, tau: (..., nv). f_ext, frame, friction, armature, check_finite:
            as in :func:`robodyn.aba`.

    Returns:
        ``(dqdd_dq, dqdd_dv, dqdd_dtau)``, each (..., nv, nv).

    Raises ValueError when a body's articulated inertia is singular, as :func:`robodyn.aba`.
    Reference: Carpentier and Mansard, RSS 2018.
    """
    if any_lazy(q, v, tau, f_ext):
        return deferred(aba_derivatives, locals())
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "aba_derivatives()")
    if f_ext is None and frame in _inputs.WRENCH_FRAMES:
        out = _rd.fast_path(_derivatives_packed, _derivatives_batch, model, q, v, tau, friction, armature,
                            check_finite)
        if out is not None:
            return out
    if is_coupled(model):  # mimic joints: -M^-1 G^T (dtau_full) G at qdd, and M^-1
        qdd, L = coupled.forward_dynamics(model, q, v, tau, f_ext, frame, friction, armature, check_finite,
                                          "aba_derivatives")
        dq, dv, _ = _rd.rnea_derivatives(model, q, v, qdd, f_ext, frame, friction=friction, armature=armature,
                                         check_finite=check_finite)
        Minv = coupled.solve(L, np.broadcast_to(np.eye(model.nv), L.shape))
        return -Minv @ dq, -Minv @ dv, Minv
    k, nv = model.kernel, model.nv
    batch, x = _inputs.states(model, q=q, v=v, tau=tau)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    dofs, params = k.dofs[(bool(friction), bool(armature))], k.params[True]
    (dq, rq), (dv, rv), (Mi, rM) = (_inputs.output(None, batch, (nv, nv), x) for _ in range(3))
    Q, V, T, F, DQ, DV, MI = _inputs.batched(batch, x["q"], x["v"], x["tau"], F, dq, dv, Mi)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args = (k.ints, k.body, dofs, params, Q, V, T, F, fcode, check_finite, DQ, DV, MI)
    _derivatives_batch.run(args, (model.nbodies, nv), status, batch)
    raise_singular(model, raise_for_status(model, status, x, "aba_derivatives"), "aba_derivatives")
    return rq, rv, rM
