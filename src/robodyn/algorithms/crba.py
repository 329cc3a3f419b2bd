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
from numba import boolean, int64

from .._jit import INTS, MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, core, fast, inline, scratch
from ..joint_kernels import nq_of
from ..layout import ARMATURE, INERTIA, INERTIA_END, IV, NDOF, PARENT
from ..spatial import dot6, inertia_act, inertia_mul
from ..coupling import is_coupled
from ..coupling_kernels import expand_positions, reduce_square
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_coupled, raise_for_status
from ._workspace import POSES_SIZE, POSES_SIZE_NB, poses, row, take, view
from ._inputs import fits, matrix_one_state, unpack
from .status import NONFINITE, OK, WRONG_SIZE, finite, finite2, result_status
from .driver import batch_kernel
from .kinematics import poses_checked, world_motion_subspace


@inline
def workspace_views(buf, nb, nv):
    """The scratch arrays of :func:`crba_state` carved from ``buf`` (see :func:`workspace`),
    after ``buf`` itself (which an ``inline`` function may not return: see ``_jit``)."""
    P, o = poses(buf, 0, nb)
    oS, o = take(buf, o, (nv, 6))
    Ic, o = take(buf, o, (nb, 10))
    F, o = take(buf, o, (6,))
    return (P, oS, Ic, F)


@scratch
def buffer(nb, nv):
    """``(buffer,)``: the memory of :func:`workspace`, the workspace of the batch code (which
    carves the views once per chunk, :func:`crba_views`)."""
    return (np.empty((POSES_SIZE_NB + 10) * nb + 6 * nv + POSES_SIZE + 6),)


@scratch
def workspace(nb, nv):
    """Scratch of :func:`crba_one`: ``(buffer, (liR, lip, oR, op, Rj, pj), oS, Ic, F)``."""
    buf = buffer(nb, nv)[0]
    return (buf,) + workspace_views(buf, nb, nv)


@inline
def world_inertias(ints, body, oR, op, Ic):
    """``Ic[i]``: inertial parameters of body ``i`` in world coordinates."""
    for i in range(ints.shape[0]):
        inertia_act(oR[i], op[i], body[i, INERTIA:INERTIA_END], Ic[i])


@inline
def world_state(ints, body, dofs, q, v, check, P, oS, Ic):
    """The set-up of the world-frame algorithms: placements ``P = (liR, lip, oR, op, Rj, pj)``
    after the value checks of ``q`` and ``v`` (see ``kinematics.poses_checked``), the world
    motion subspace columns ``oS`` and the world inertias ``Ic``; returns a status."""
    liR, lip, oR, op, Rj, pj = P
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status == OK:
        world_motion_subspace(ints, dofs, oR, op, oS)
        world_inertias(ints, body, oR, op, Ic)
    return status


@inline
def crba_state(ints, body, dofs, q, check, M, ws):
    """``M`` (nv, nv) at ``q``; returns a status (see ``_inputs``). Inlined into
    :func:`crba_one` (one state, for other kernels) and :func:`crba_at` (the batch code,
    which ``crba`` runs for a single state too, as a batch of one)."""
    _, P, oS, Ic, F = ws
    if q.shape[0] != nq_of(ints):
        return WRONG_SIZE
    status = world_state(ints, body, dofs, q, q[:0], check, P, oS, Ic)
    if status != OK:
        return status
    M[:, :] = 0.0
    for i in range(ints.shape[0] - 1, -1, -1):
        par, iv, n = ints[i, PARENT], ints[i, IV], ints[i, NDOF]
        for k in range(iv, iv + n):
            inertia_mul(Ic[i], oS[k], F)
            j = i
            while j >= 0:
                for l in range(ints[j, IV], ints[j, IV] + ints[j, NDOF]):
                    val = dot6(oS[l], F)
                    M[l, k] = val
                    M[k, l] = val
                j = ints[j, PARENT]
            M[k, k] += dofs[k, ARMATURE]
        if par >= 0:
            for r in range(10):
                Ic[par, r] += Ic[i, r]
    return result_status(check, finite(view(M, 0, (M.size,))))


@core
def crba_one(ints, body, dofs, q, check, M, ws):
    """:func:`crba_state` of one state (the compiled function other kernels call)."""
    return crba_state(ints, body, dofs, q, check, M, ws)


@inline
def crba_at(args, s, ws):
    """:func:`crba_state` of state ``s`` of a batch."""
    ints, body, dofs, Q, check, MM = args
    return crba_state(ints, body, dofs, Q[s], check, MM[s], ws)


@inline
def crba_views(args, ws):
    """The workspace views carved once per chunk from the buffer, where the compiler sees
    their shapes."""
    return (ws[0],) + workspace_views(ws[0], args[0].shape[0], args[2].shape[0])


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, MAT, boolean, TENSOR), (int64, int64))
_crba_batch = batch_kernel(crba_at, buffer, crba_views, ONE_STATE)
_crba_call_one = _crba_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, boolean, MAT)
def _crba_packed(address, ints, packed, q, check, M):
    """One state, the model in one array (the fast path): the batch's code at ``address``
    (``_crba_batch.one_address``) for a batch of one."""
    ok, args = matrix_one_state(ints, packed, q, check, M)
    return _crba_call_one(address, args, buffer(ints.shape[0], M.shape[0])) if ok else WRONG_SIZE


@scratch
def coupled_workspace(nb, nqf, nvf):
    """Scratch of :func:`crba_coupled_state`: the CRBA's, and a buffer for the full tree's
    ``q`` and ``M`` (nq_full + nv_full^2)."""
    return workspace(nb, nvf), np.empty(nqf + nvf * nvf)


@inline
def crba_coupled_state(ints, body, dofs, cints, cfloats, q, check, M, ws):
    """Mass matrix of a model with mimic couplings (``robodyn.coupling``), one state:
    ``M = G^T M_full(P q + o) G`` (nv, nv), the full tree in ``ints, body, dofs``, the
    coupling in ``cints, cfloats``. Returns a status."""
    cws, buf = ws
    nqf, nvf = nq_of(ints), dofs.shape[0]
    qf, Mf = view(buf, 0, (nqf,)), view(buf, nqf, (nvf, nvf))
    if q.shape[0] != cints[0]:
        return WRONG_SIZE
    if check and not finite(q):
        return NONFINITE
    expand_positions(cints, cfloats, q, qf)
    status = crba_one(ints, body, dofs, qf, check, Mf, cws)
    if status != OK:
        return status
    reduce_square(cints, cfloats, Mf, M)
    return result_status(check, finite2(M))


@inline
def crba_coupled_at(args, s, ws):
    """:func:`crba_coupled_state` of state ``s`` of a batch."""
    ints, body, dofs, cints, cfloats, Q, check, MM = args
    return crba_coupled_state(ints, body, dofs, cints, cfloats, Q[s], check, MM[s], ws)


COUPLED_ONE_STATE = ((MODEL_INTS, MAT, MAT, INTS, VEC, MAT, boolean, TENSOR), (int64, int64, int64))
_crba_coupled_batch = batch_kernel(crba_coupled_at, coupled_workspace, one_state=COUPLED_ONE_STATE)
_crba_coupled_call_one = _crba_coupled_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, INTS, VEC, VEC, boolean, MAT)
def _crba_coupled_one(address, ints, packed, cints, cfloats, q, check, M):
    """One state of a coupled model: the batch's code at ``address``
    (``_crba_coupled_batch.one_address``) for a batch of one."""
    body, dofs, _, _ = unpack(ints, packed)
    if not fits(M, cints[1], q, q, q):
        return WRONG_SIZE
    return _crba_coupled_call_one(address, (ints, body, dofs, cints, cfloats, row(q), check, row(M)),
                                  coupled_workspace(ints.shape[0], nq_of(ints), dofs.shape[0]))


def run_coupled(model, q, armature: bool, check: bool, out=None) -> np.ndarray:
    """:func:`crba` of a :class:`~robodyn.coupling.CoupledModel` (compiled: the full tree's
    CRBA and the congruence ``G^T M G``, per state; a single state as a batch of one)."""
    tables, k = model.tables, model.full.kernel
    M = _inputs.fast_out(out, (model.nv, model.nv))
    try:  # one state, a contiguous float64 vector (the dispatcher raises TypeError otherwise)
        if _crba_coupled_one(_crba_coupled_batch.one_address, k.ints, k.packed[False, bool(armature)], tables.ints,
                             tables.floats, q, check, M) == OK:
            return M
    except TypeError:
        pass
    batch, x = _inputs.states(model, q=q)
    M, result = _inputs.output(out, batch, (model.nv, model.nv), x)
    Q, MM = _inputs.batched(batch, x["q"], M)
    status = np.empty(Q.shape[0], dtype=np.int64)
    _crba_coupled_batch.run((k.ints, k.body, k.dofs[(False, bool(armature))], tables.ints, tables.floats, Q, check, MM),
                            (model.nbodies, model.full.nq, model.full.nv), status, batch)
    raise_for_coupled(model, status, x, "crba")
    return result


def crba(model, q, *, armature: bool = True, check_finite: bool = True, out: np.ndarray | None = None) -> np.ndarray:
    """Joint-space inertia (mass) matrix ``M(q)``, full and symmetric.

    q: (..., nq). Returns (..., nv, nv). ``armature=True`` adds the model's reflected rotor
    inertias on the diagonal (as :func:`robodyn.rnea` and :func:`robodyn.aba` do). ``out``: an
    optional (..., nv, nv) C-contiguous float64 array to write into and return (see
    :func:`robodyn.rnea`).

    Equivalence: column ``j`` equals ``rnea(q, 0, e_j) - gravity(q)``; ``v^T M v / 2`` is the
    kinetic energy. Reference: RBDA Table 6.2 (composite-rigid-body algorithm).
    """
    M = _inputs.fast_out(out, (model.nv, model.nv))  # fast path for one state: the kernel checks q, M
    try:
        k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
        if _crba_packed(_crba_batch.one_address, k.ints, k.packed[False, armature], q, check_finite, M) == OK:
            return M
    except (TypeError, KeyError, AttributeError):  # not contiguous float64 arrays (or armature not bool)
        pass
    if any_lazy(q):
        return deferred(crba, locals())
    if is_coupled(model):  # mimic joints: the compiled coupled path (after the fast path: free for a tree)
        return run_coupled(model, q, armature, check_finite, out)
    batch, x = _inputs.states(model, q=q)
    M, result = _inputs.output(out, batch, (model.nv, model.nv), x)
    Q, M = _inputs.batched(batch, x["q"], M)
    status = np.empty(Q.shape[0], dtype=np.int64)
    args, sizes = (k.ints, k.body, k.dofs[(False, bool(armature))], Q, check_finite, M), (model.nbodies, model.nv)
    _crba_batch.run(args, sizes, status, batch)
    raise_for_status(model, status, x, "crba")
    return result
