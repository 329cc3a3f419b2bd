"""The mass matrix as a sum over the bodies: ``M(q) = sum_i J_i(q)^T M_i J_i(q)``.

Murray, Li & Sastry (1994), Proposition 4.3 (eq. 4.19): ``J_i`` is the body Jacobian of body
``i``'s frame (rows ``[linear; angular]``, :func:`robodyn.jacobian` with ``frame="local"``)
and ``M_i`` its generalized (spatial) inertia in that frame,

    M_i = [[m 1, -m [c]x], [m [c]x, I_o]]     (6 x 6, linear first)

with ``c`` the centre of mass and ``I_o`` the inertia about the frame's origin. The same
``M`` as :func:`robodyn.crba` (the composite-rigid-body algorithm, O(n d)), computed the way
the book derives it, for checking it and for teaching; it costs ``nbodies`` Jacobians.
"""

from __future__ import annotations

import numpy as np

from ..model import inertia_about_origin
from ..coupling import expand_q, is_coupled, reduce_matrix
from ._lazy import any_lazy, deferred
from .jacobian import jacobian


def spatial_inertia(theta) -> np.ndarray:
    """The 6 x 6 generalized inertia ``[[m 1, -m [c]x], [m [c]x, I_o]]`` of 10 inertial
    parameters (robodyn order; linear rows first)."""
    theta = np.asarray(theta, dtype=float)
    m, h = theta[0], theta[1:4]
    hx = np.array([[0.0, -h[2], h[1]], [h[2], 0.0, -h[0]], [-h[1], h[0], 0.0]])
    return np.block([[m * np.eye(3), -hx], [hx, inertia_about_origin(theta)]])


def mass_matrix_from_jacobians(model, q, *, armature: bool = True, check_finite: bool = True) -> np.ndarray:
    """``sum_i J_i^T M_i J_i`` (..., nv, nv) over the bodies (module docstring), plus the
    joints' ``armature`` on the diagonal (as :func:`robodyn.crba`)."""
    if any_lazy(q):
        return deferred(mass_matrix_from_jacobians, locals())
    if is_coupled(model):  # G^T M_full G (the mimic joints' armature included)
        return reduce_matrix(model, mass_matrix_from_jacobians(model.full, expand_q(model, q), armature=armature,
                                                               check_finite=check_finite))
    q = np.asarray(q, dtype=float)
    M = 0.0
    for i in range(model.nbodies):
        J = jacobian(model, q, i, "local", check_finite=check_finite)
        M = M + np.einsum("...ki,kl,...lj->...ij", J, spatial_inertia(model.theta[i]), J)
    M = np.broadcast_to(M, q.shape[:-1] + (model.nv, model.nv)).copy()
    if armature:
        M[..., np.arange(model.nv), np.arange(model.nv)] += model.armature
    return M
