"""The energy route: Euler-Lagrange equations of the kinetic and potential energies.

    M(q)     = sum_i J_i^T I_i J_i + diag(armature)       (J_i: body Jacobian in body frame i)
    T(q, qd) = qd^T M(q) qd / 2,     U(q) = -sum_i m_i g . p_ci,     L = T - U
    tau_k    = d/dt dL/dqd_k - dL/dq_k
             = sum_j M_kj qdd_j + sum_ij (dM_ki/dq_j - dM_ij/dq_k / 2) qd_i qd_j + dU/dq_k

The body Jacobians follow the tree outwards (``J_i = X_i^-1 J_parent + S_i``), so each step
multiplies by the trigonometric terms of one joint only. The time derivative is
``d/dt = sum_j qd_j d/dq_j + qdd_j d/dqd_j``. ``M`` and ``g`` are read off ``tau`` (its
``qdd`` coefficients and its part without ``qd`` and ``qdd``); ``C`` is the Christoffel
matrix of ``M``. With mimic joints (:mod:`.mimic`) ``M = G^T M_joints G`` and ``U`` is that
of the joints' placements in the coordinates, so that ``tau`` is the Euler-Lagrange equations
of the independent coordinates, ``G^T tau_joints``. Reference: M. W. Spong, S. Hutchinson,
M. Vidyasagar, *Robot Modeling and Control*, Wiley 2006, sections 7.1-7.3; R. M. Murray,
Z. Li, S. S. Sastry, *A Mathematical Introduction to Robotic Manipulation*, CRC 1994,
section 4.2.
"""

from __future__ import annotations

from ._ring import TrigRing
from ._spatial import inertia_mul, joint_placement, motion_act_inv, motion_subspace, potential_energy, world_poses


def mass_matrix(rg: TrigRing) -> list:
    """``M = G^T (sum_i J_i^T I_i J_i + diag(armature)) G`` (n x n lists of ring polynomials;
    ``J_i`` over the joints, ``G`` the identity without mimic joints)."""
    m, nb = rg.model, rg.model.nbodies
    M = [[rg.zero] * nb for _ in range(nb)]
    J = []
    for i in range(m.nbodies):
        R, p = joint_placement(rg, i)
        par = m.parent[i]
        cols = {} if par < 0 else {k: motion_act_inv(rg, R, p, col) for k, col in J[par].items()}
        cols[i] = motion_subspace(rg, i)
        J.append(cols)
        theta = rg.vec(m.theta[i])
        for a, Ja in cols.items():
            f = inertia_mul(rg, theta, Ja)
            for b, Jb in cols.items():
                if b <= a:
                    M[a][b] = M[a][b] + rg.dot(Jb, f)
    for a in range(nb):
        M[a][a] = M[a][a] + rg.const(m.armature[a])
        for b in range(a):
            M[b][a] = M[a][b]
    return rg.coordinate_matrix(M)


def derive(rg: TrigRing) -> dict:
    """``tau``, ``T``, ``U`` (ring polynomials) by the Euler-Lagrange equations."""
    n = rg.model.nv
    M = mass_matrix(rg)
    T = sum((M[i][j] * rg.qd[i] * rg.qd[j] for i in range(n) for j in range(n)), rg.zero) / 2
    U = potential_energy(rg, world_poses(rg))
    L = T - U
    tau = [rg.ddt(L.diff(rg.qd[k])) - rg.dq(L, k) for k in range(n)]
    return dict(tau=tau, T=T, U=U)
