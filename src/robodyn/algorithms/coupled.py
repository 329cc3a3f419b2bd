"""Forward dynamics of a model with mimic couplings (``robodyn.coupling.CoupledModel``).

The independent coordinates obey ``M a + h = tau`` with the reduced terms of the full tree
(``q_full = E(q)``, ``v_full = G v``)::

    M = G^T M_full(E(q)) G,     h = G^T rnea_full(E(q), G v, 0)

(``h`` with friction, springs and external wrenches when they are on). The articulated-body
recursion does not apply to a coupled tree (a mimic joint moves with a joint elsewhere in the
tree), so the forward dynamics factorises ``M`` (Cholesky; ``M`` is positive definite when
the full tree's is). Reference: Featherstone, RBDA (2008), section 8.3 (constraints that
remove degrees of freedom: ``G`` there), Pinocchio's mimic joints.

:func:`run_aba` is the compiled forward dynamics (``robodyn.aba`` of a coupled model, per
state: the full tree's CRBA and RNEA, the reduction, a dense Cholesky); the NumPy functions
below give the factor ``L`` to the derivatives, the inverse mass matrix and the hybrid dynamics.
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64

from .._jit import INTS, MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, fast, inline, scratch
from ..coupling import expand_q, expand_v, reduce_force, reduce_matrix
from ..coupling_kernels import expand_positions, expand_velocity, reduce_square, reduce_vector
from ..joint_kernels import nq_of
from . import _inputs
from ._inputs import coupled_one_state
from ._workspace import view
from .crba import crba, crba_one
from .crba import workspace as crba_workspace
from .dense import backward, cholesky as factorise, forward
from .driver import batch_kernel
from .rnea import rnea, rnea_one
from .rnea import workspace as rnea_workspace
from .status import (NONFINITE, NOT_POSITIVE_DEFINITE, OK, WRONG_SIZE, finite, raise_not_positive_definite,
                     result_status)


@scratch
def aba_workspace(nb, nqf, nvf, nv):
    """Scratch of :func:`aba_coupled_state`: the CRBA's, the RNEA's, and a buffer for the full
    tree's ``q, v, 0, h, M`` and the reduced ``M`` (nq_full + 3 nv_full + nv_full^2 + nv^2)."""
    return crba_workspace(nb, nvf), rnea_workspace(nb), np.empty(nqf + 3 * nvf + nvf * nvf + nv * nv)


@inline
def aba_coupled_state(ints, body, dofs, params, cints, cfloats, q, v, tau, fext, fcode, check, qdd, ws):
    """Forward dynamics of a model with mimic couplings, one state: ``qdd = M^-1 (tau - h)``
    (nv,) with ``M = G^T M_full G = L L^T`` and ``h = G^T rnea_full(P q + o, G v, 0)`` (the
    full tree in ``ints, body, dofs, params``, the coupling in ``cints, cfloats``). Returns a
    status (``NOT_POSITIVE_DEFINITE`` when ``M`` is not)."""
    cws, rws, buf = ws
    nqf, nvf, nv = nq_of(ints), dofs.shape[0], cints[1]
    qf, vf, zero = view(buf, 0, (nqf,)), view(buf, nqf, (nvf,)), view(buf, nqf + nvf, (nvf,))
    hf, Mf = view(buf, nqf + 2 * nvf, (nvf,)), view(buf, nqf + 3 * nvf, (nvf, nvf))
    M = view(buf, nqf + 3 * nvf + nvf * nvf, (nv, nv))
    if not (q.shape[0] == cints[0] and v.shape[0] == nv and tau.shape[0] == nv):
        return WRONG_SIZE
    if check and not (finite(q) and finite(v) and finite(tau)):
        return NONFINITE
    expand_positions(cints, cfloats, q, qf)
    expand_velocity(cints, cfloats, v, vf)
    for k in range(nvf):
        zero[k] = 0.0
    status = crba_one(ints, body, dofs, qf, check, Mf, cws)
    if status == OK:
        status = rnea_one(ints, body, dofs, params, qf, vf, zero, fext, fcode, check, hf, rws)
    if status != OK:
        return status
    reduce_square(cints, cfloats, Mf, M)
    reduce_vector(cints, cfloats, hf, qdd)
    for i in range(nv):
        qdd[i] = tau[i] - qdd[i]
    if not factorise(M):
        return NOT_POSITIVE_DEFINITE
    forward(M, qdd)
    backward(M, qdd)
    return result_status(check, finite(qdd))


@inline
def aba_coupled_at(args, s, ws):
    """:func:`aba_coupled_state` of state ``s`` of a batch (``F``: one row per state, or one for all)."""
    ints, body, dofs, params, cints, cfloats, Q, V, TAU, F, fcode, check, QDD = args
    return aba_coupled_state(ints, body, dofs, params, cints, cfloats, Q[s], V[s], TAU[s],
                             F[s if F.shape[0] > 1 else 0], fcode, check, QDD[s], ws)


ONE_STATE = ((MODEL_INTS, MAT, MAT, VEC, INTS, VEC, MAT, MAT, MAT, TENSOR, int64, boolean, MAT),
             (int64, int64, int64, int64))
_aba_coupled_batch = batch_kernel(aba_coupled_at, aba_workspace, one_state=ONE_STATE)
_aba_coupled_call_one = _aba_coupled_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, INTS, VEC, VEC, VEC, VEC, boolean, VEC)
def _aba_coupled_one(address, ints, packed, cints, cfloats, q, v, tau, check, qdd):
    """One state of a coupled model without external wrenches: the batch's code at ``address``
    (``_aba_coupled_batch.one_address``) for a batch of one."""
    ok, args = coupled_one_state(ints, packed, cints, cfloats, q, v, tau, check, qdd)
    return (_aba_coupled_call_one(address, args, aba_workspace(ints.shape[0], nq_of(ints), args[2].shape[0], cints[1]))
            if ok else WRONG_SIZE)


def run_aba(model, q, v, tau, f_ext, frame: str, friction: bool, armature: bool, check: bool, out=None):
    """:func:`robodyn.aba` of a :class:`~robodyn.coupling.CoupledModel` (compiled, per state)."""
    sizes = (model.nbodies, model.full.nq, model.full.nv, model.nv)
    return _inputs.coupled_call(model, _aba_coupled_one, _aba_coupled_batch, sizes, "tau", q, v, tau, f_ext, frame,
                                friction, armature, check, out, "aba")


def mass_matrix(model, q, armature: bool, check_finite: bool) -> np.ndarray:
    """``M = G^T M_full(E(q)) G`` (..., nv, nv)."""
    return reduce_matrix(model, crba(model.full, expand_q(model, q), armature=armature, check_finite=check_finite))


def bias_forces(model, q, v, f_ext, frame: str, friction: bool, armature: bool, check_finite: bool) -> np.ndarray:
    """``h = G^T rnea_full(E(q), G v, 0)`` (..., nv), with the options of :func:`robodyn.rnea`."""
    vf = expand_v(model, v)
    return reduce_force(model, rnea(model.full, expand_q(model, q), vf, np.zeros(vf.shape), f_ext, frame,
                                    friction=friction, armature=armature, check_finite=check_finite))


def cholesky(M: np.ndarray, model, what: str) -> np.ndarray:
    """The lower Cholesky factor of the reduced mass matrix, or a ``ValueError`` that says it is
    singular (a mimic joint that moves no mass, say)."""
    try:
        return np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise_not_positive_definite(model, what)


def solve(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``M^-1 b`` (..., nv) or (..., nv, k) from the Cholesky factor ``L`` of ``M``."""
    vector = b.ndim == L.ndim - 1
    x = b[..., None] if vector else b
    y = np.linalg.solve(L, x)
    x = np.linalg.solve(np.swapaxes(L, -1, -2), y)
    return x[..., 0] if vector else x


def forward_dynamics(model, q, v, tau, f_ext, frame: str, friction: bool, armature: bool,
                     check_finite: bool, what: str = "aba") -> tuple[np.ndarray, np.ndarray]:
    """``(a, L)``: the accelerations ``M^-1 (tau - h)`` (..., nv) and the Cholesky factor of ``M``."""
    tau = np.asarray(tau, dtype=float)
    if tau.ndim == 0 or tau.shape[-1] != model.nv:
        raise ValueError(f"tau: expected shape (..., {model.nv}), got {tau.shape}")
    if check_finite and not np.all(np.isfinite(tau)):
        raise ValueError(f"{what}: tau contains NaN or Inf")
    L = cholesky(mass_matrix(model, q, armature, check_finite), model, what)
    h = bias_forces(model, q, v, f_ext, frame, friction, armature, check_finite)
    rhs = tau - h
    L = np.broadcast_to(L, rhs.shape[:-1] + L.shape[-2:])
    return solve(L, rhs), L
