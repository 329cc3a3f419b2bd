"""Forward dynamics of a model with mimic couplings (``robodyn.coupling.CoupledModel``).

The independent coordinates obey ``M a + h = tau`` with the reduced terms of the full tree
(``q_full = E(q)``, ``v_full = G v``)::

    M = G^T M_full(E(q)) G,     h = G^T rnea_full(E(q), G v, 0)

(``h`` with friction, springs and external wrenches when they are on). The articulated-body
recursion does not apply to a coupled tree (a mimic joint moves with a joint elsewhere in the
tree), so the forward dynamics factorises ``M`` (Cholesky; ``M`` is positive definite when
the full tree's is). Reference: Featherstone, RBDA (2008), section 8.3 (constraints that
remove degrees of freedom: ``G`` there), Pinocchio's mimic joints.
"""

from __future__ import annotations

import numpy as np

from ..coupling import expand_q, expand_v, reduce_force, reduce_matrix
from .crba import crba
from .rnea import rnea


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
        raise ValueError(f"{what}: the mass matrix of {model.name!r} in its independent coordinates is not "
                         "positive definite, so the forward dynamics is undefined; give the bodies the joints "
                         "move mass and inertia (or armature)") from None


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
