"""Hybrid dynamics by the articulated-body method (RBDA section 9.2), O(n).

Some joints have a known (prescribed) acceleration and an unknown force, the others a known
force and an unknown acceleration. A joint with a known acceleration moves as if rigid for
the articulated-body recursion: its body passes its full inertia ``IA_i`` to the parent,
and its known motion enters the velocity-product term ``c_i``.

Pass 1 (root to leaves): ``v_i = iX_p v_p + S_i qd_i``, ``c_i = v_i x S_i qd_i``
(``+ S_i qdd_i`` when the joint's acceleration is known), ``IA_i = I_i``,
``pA_i = v_i x* I_i v_i - f_ext_i``.

Pass 2 (leaves to root), a joint with unknown acceleration as in the ABA
(``U_i = IA_i S_i``, ``D_i = S_i^T U_i (+ armature)``, ``u_i = tau_i - S_i^T pA_i (- friction)``,
``Ia = IA_i - U_i D_i^-1 U_i^T``, ``pa = pA_i + Ia c_i + U_i D_i^-1 u_i``); a joint with
known acceleration passes ``Ia = IA_i`` and ``pa = pA_i + IA_i c_i``. Then
``IA_p += iX_p^T Ia iX_p``, ``pA_p += iX_p^T pa``.

Pass 3 (root to leaves), with ``a_0 = -g``: ``a_i = iX_p a_p + c_i``; unknown acceleration:
``qdd_i = D_i^-1 (u_i - U_i^T a_i)``, ``a_i += S_i qdd_i``; known acceleration:
``tau_i = S_i^T (IA_i a_i + pA_i) (+ armature qdd_i + friction)``, the force transmitted by
the joint to the articulated subtree beyond it.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._deprecated import renamed_keyword
from .._jit import BOOLS, MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, fast, inline
from .. import joints as J
from ..coupling import is_coupled
from . import coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import NO_WRENCH, OK, WRONG_SIZE, first_failure, raise_for_status
from ._inputs import fits, unpack
from ._workspace import row
from .aba import hybrid_one, workspace
from .driver import batch_kernel


@inline
def hybrid_at(args, s, ws):
    """Hybrid dynamics of state ``s`` of a batch (``F`` has one row per state, or one row for all)."""
    ints, body, dofs, params, Q, V, A, T, known, F, fcode, check, QDD, TAU = args
    return hybrid_one(ints, body, dofs, params, Q[s], V[s], A[s], T[s], known, F[s if F.shape[0] > 1 else 0],
                      fcode, check, QDD[s], TAU[s], ws)


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, MAT, MAT, MAT, MAT, BOOLS, TENSOR, int64, boolean, MAT, MAT), (int64, int64))
_hybrid_batch = batch_kernel(hybrid_at, workspace, one_state=ONE_STATE)
_hybrid_call_one = _hybrid_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, VEC, VEC, VEC, BOOLS, boolean, VEC, VEC)
def _hybrid_packed(address, ints, packed, q, v, a_known, tau_known, known, check, qdd, tau):
    """One state without external wrenches, the model in one array (the fast path): the
    batch's code at ``address`` (``_hybrid_batch.one_address``) for a batch of one."""
    body, dofs, params, zero = unpack(ints, packed)
    nv = dofs.shape[0]
    if not (fits(qdd, nv, q, v, a_known) and fits(tau, nv, q, v, tau_known) and fits(qdd, nv, tau, tau, tau)
            and known.shape[0] == nv):
        return WRONG_SIZE
    args = (ints, body, dofs, params, row(q), row(v), row(a_known), row(tau_known), known, row(zero),
            int64(NO_WRENCH), check, row(qdd), row(tau))
    return _hybrid_call_one(address, args, workspace(ints.shape[0], nv))


def known_dofs(model, known_mask) -> np.ndarray:
    """``known_mask`` checked: a boolean (nv,) array in which the entries of a joint of several
    dofs (free, spherical) are all True or all False."""
    mask = np.asarray(known_mask)
    if mask.shape != (model.nv,):
        raise ValueError(f"known_mask: expected shape ({model.nv},), got {mask.shape}")
    if mask.dtype != bool:
        if not (np.issubdtype(mask.dtype, np.integer) and np.all((mask == 0) | (mask == 1))):
            raise ValueError(f"known_mask: expected booleans (or 0/1), got {mask.dtype} values {mask.tolist()}")
        mask = mask.astype(bool)
    try:
        multi = model.kernel.multi_dof_bodies
    except AttributeError:  # a CoupledModel: its joints of several dofs are independent joints of its tree
        full = np.zeros(model.full.nv, dtype=bool)
        full[model.independent_v] = mask
        known_dofs(model.full, full)
        return np.ascontiguousarray(mask)
    for i in multi:
        k, n = model.idx_v[i], int(J.NV[model.joint_type[i]])
        block = mask[k:k + n]
        if block.any() != block.all():
            kind = J.NAMES[model.joint_type[i]]
            raise ValueError(
                f"known_mask: the {n} entries {k}..{k + n - 1} of {kind} joint {model.body_joint_names[i]!r} must be "
                f"all True (joint acceleration given) or all False (joint force given), got {block.tolist()}")
    return np.ascontiguousarray(mask)


def _coupled(model, q, v, a_known, tau_known, known, f_ext, frame, friction, armature, check_finite):
    """Hybrid dynamics of a coupled model (mimic joints) from its reduced ``M`` and ``h``
    (``algorithms.coupled``): ``M_uu a_u = tau_u - h_u - M_uk a_k``, then ``tau = M a + h``."""
    batch, x = _inputs.states(model, q=q, v=v, a_known=a_known, tau_known=tau_known)
    u = ~known
    a = np.where(known, x["a_known"], 0.0)
    tau_given = np.where(known, 0.0, x["tau_known"])
    if check_finite and not (np.isfinite(a).all() and np.isfinite(tau_given).all()):
        raise ValueError("hybrid_dynamics: a_known (where known) or tau_known (where not) contains NaN or Inf")
    M = coupled.mass_matrix(model, x["q"], armature, check_finite)
    h = coupled.bias_forces(model, x["q"], x["v"], f_ext, frame, friction, armature, check_finite)
    if u.any():
        rhs = (tau_given - h - np.einsum("...ij,...j->...i", M, a))[..., u]
        L = coupled.cholesky(M[..., u, :][..., :, u], model, "hybrid_dynamics")
        a[..., u] = coupled.solve(np.broadcast_to(L, rhs.shape[:-1] + L.shape[-2:]), rhs)
    tau = np.einsum("...ij,...j->...i", M, a) + h
    tau[..., u] = tau_given[..., u]
    return _inputs.unflatten(a, batch), _inputs.unflatten(tau, batch)


def hybrid_dynamics(model, q, v, a_known, tau_known, known_mask, f_ext=None, frame: str = "local", *,
                    friction: bool = True, armature: bool = True,
                    check_finite: bool = True, f_ext_frame=None) -> tuple[np.ndarray, np.ndarray]:
    """Hybrid dynamics: given the accelerations of some joints and the forces of the others,
    the missing forces and accelerations.

    Solves ``M(q) a + C(q, v) v + g(q) - sum_i J_i^T f_ext_i (+ armature a + friction) = tau``
    for ``tau[known]`` and ``a[~known]`` given ``a[known]`` and ``tau[~known]``, in O(n).

    Args:
        q: (..., nq). v: (..., nv).
        a_known: (..., nv) accelerations; only the entries where ``known_mask`` is True are read.
        tau_known: (..., nv) joint forces; only the entries where ``known_mask`` is False are read.
        known_mask: (nv,) booleans, one per entry of ``v``, the same for every state of a batch:
            True where the acceleration is given. A free joint (floating base) has either all
            six entries True (its acceleration ``[a_lin; alpha]`` in the base frame is given,
            its wrench computed) or all six False (its wrench ``[force; torque]`` in the base
            frame is given, usually zero, and its acceleration computed).
        f_ext, frame, friction, armature, check_finite: as in :func:`robodyn.rnea`.
            Entries that are not read may be NaN.

    Returns:
        ``(a, tau)``, both (..., nv) and complete: ``a[known] == a_known[known]`` and
        ``tau[~known] == tau_known[~known]``, so that ``rnea(q, v, a) == tau``.

    Equivalences: with every entry known, ``tau == rnea(q, v, a_known)``; with none known,
    ``a == aba(q, v, tau_known)``. Raises ValueError when the articulated inertia of a body
    whose acceleration is unknown is singular. Reference: Featherstone, RBDA (2008),
    section 9.2.
    """
    if f_ext_frame is not None:  # the old spelling of ``frame``
        frame = renamed_keyword("f_ext_frame", f_ext_frame, "frame", frame, "hybrid_dynamics()")
    known = known_dofs(model, known_mask)
    if f_ext is None and frame in _inputs.WRENCH_FRAMES:
        a, tau = np.empty(model.nv), np.empty(model.nv)  # fast path for one state: the kernel checks
        try:
            k = model.kernel  # a CoupledModel (mimic joints) has none: its path below
            if _hybrid_packed(_hybrid_batch.one_address, k.ints, k.packed[friction, armature], q, v, a_known,
                              tau_known, known, check_finite, a, tau) == OK:
                return a, tau
        except (TypeError, KeyError, AttributeError):  # not contiguous float64 vectors (or options not bool)
            pass
    if any_lazy(q, v, a_known, tau_known, f_ext):
        return deferred(hybrid_dynamics, locals())
    if is_coupled(model):
        return _coupled(model, q, v, a_known, tau_known, known, f_ext, frame, friction, armature, check_finite)
    k = model.kernel
    dofs, params = k.dofs[(bool(friction), bool(armature))], k.params[True]
    batch, x = _inputs.states(model, q=q, v=v, a_known=a_known, tau_known=tau_known)
    F, fcode = _inputs.body_wrenches(model, f_ext, batch, frame)
    (a, ra), (tau, rtau) = (_inputs.output(None, batch, (model.nv,), x) for _ in range(2))
    Q, V, A, T, F, QDD, TAU = _inputs.batched(batch, x["q"], x["v"], x["a_known"], x["tau_known"], F, a, tau)
    status = np.empty(Q.shape[0], dtype=np.int64)
    _hybrid_batch.run((k.ints, k.body, dofs, params, Q, V, A, T, known, F, fcode, check_finite, QDD, TAU),
                      (model.nbodies, model.nv), status, batch)
    if first_failure(status) != OK:
        report = {"q": x["q"], "v": x["v"], "a_known": np.where(known, x["a_known"], 0.0),
                  "tau_known": np.where(known, 0.0, x["tau_known"])}
        bad = raise_for_status(model, status, report, "hybrid_dynamics")
        i = bad - 1
        raise ValueError(
            f"hybrid_dynamics: the articulated inertia of body {i} ({model.link_names[i]!r}, joint "
            f"{model.body_joint_names[i]!r}) is singular, so its acceleration is undefined; prescribe the "
            "acceleration of that joint, or give the bodies beyond it mass and inertia (or armature)")
    return ra, rtau
