"""The recursive Newton-Euler route: RNEA evaluated on symbols.

    V_i = X_i^-1 V_parent + S_i qd_i                           (V_0 = 0)
    A_i = X_i^-1 A_parent + S_i qdd_i + V_i x S_i qd_i          (A_0 = -gravity)
    F_i = I_i A_i + V_i x* I_i V_i
    tau_i = S_i . F_i + armature_i qdd_i,     F_parent += X_i F_i   (leaves to root)

in body frames, with ``q``, ``qd`` and ``qdd`` symbolic; with mimic joints (:mod:`.mimic`)
the joints move as ``qd_i = r qd_k``, ``qdd_i = r qdd_k`` and ``tau = G^T tau_joints``
(``tau_i`` times the multiplier, on its source's coordinate). ``tau`` is linear in ``qdd`` and
quadratic in ``qd``: its ``qdd`` coefficients are ``M``, its part free of ``qd`` and
``qdd`` is ``g``, and its quadratic part ``sum_jk Gamma_ijk qd_j qd_k``, with ``Gamma_ijk``
symmetric in ``j, k``, gives the Christoffel symbols directly (the symmetric form of a
quadratic form is unique), so ``C_ij = sum_k Gamma_ijk qd_k``. ``T = sum_i V_i . I_i V_i / 2``
(plus the rotors' ``armature qd^2 / 2``). Reference: R. Featherstone, *Rigid Body Dynamics
Algorithms*, Springer 2008, table 5.1; J. Y. S. Luh, M. W. Walker, R. P. C. Paul,
"On-line computational scheme for mechanical manipulators", ASME J. Dyn. Syst. Meas.
Control 102, 1980.
"""

from __future__ import annotations

from ._ring import TrigRing
from ._spatial import (force_act, force_cross, inertia_mul, joint_placement, motion_act_inv, motion_cross,
                       motion_subspace, potential_energy, world_poses)


def derive(rg: TrigRing) -> dict:
    """``tau``, ``T``, ``U`` (ring polynomials) by the recursive Newton-Euler algorithm."""
    tau, T = recursion(rg)
    return dict(tau=tau, T=rg.reduce(T), U=potential_energy(rg, world_poses(rg)))


def recursion(rg) -> tuple[list, object]:
    """``(tau, T)``: the forces on the coordinates (n scalars of ``rg``: :class:`.TrigRing`
    polynomials, or :class:`._emit.Emitter` intermediates; ``G^T`` of the joint forces) and the
    kinetic energy."""
    m = rg.model
    zero6 = [rg.zero] * 6
    a0 = [-x for x in rg.vec(m.gravity)] + [rg.zero] * 3
    V, A, F, X, S = [], [], [], [], []
    T = rg.zero
    # Pass 1: velocities, accelerations and body forces, root to leaves
    for i in range(m.nbodies):
        R, p = joint_placement(rg, i)
        Si = motion_subspace(rg, i)
        par = m.parent[i]
        vJ = [x * rg.joint_qd[i] for x in Si]
        Vp, Ap = (zero6, a0) if par < 0 else (V[par], A[par])
        Vi = [a + b for a, b in zip(motion_act_inv(rg, R, p, Vp), vJ)]
        c = motion_cross(rg, Vi, vJ)
        Ai = [a + x * rg.joint_qdd[i] + b for a, x, b in zip(motion_act_inv(rg, R, p, Ap), Si, c)]
        theta = rg.vec(m.theta[i])
        IV = inertia_mul(rg, theta, Vi)
        Fi = [a + b for a, b in zip(inertia_mul(rg, theta, Ai), force_cross(rg, Vi, IV))]
        T = T + rg.dot(Vi, IV) / 2 + rg.const(m.armature[i]) * rg.joint_qd[i] ** 2 / 2
        V.append(Vi), A.append(Ai), F.append(Fi), X.append((R, p)), S.append(Si)
    # Pass 2: joint forces, leaves to root
    tau = [rg.zero] * m.nbodies
    for i in reversed(range(m.nbodies)):
        tau[i] = rg.dot(S[i], F[i]) + rg.const(m.armature[i]) * rg.joint_qdd[i]
        par = m.parent[i]
        if par >= 0:
            F[par] = [a + b for a, b in zip(F[par], force_act(rg, *X[i], F[i]))]
    return rg.coordinate_forces(tau), T
