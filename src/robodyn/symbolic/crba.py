"""The composite-rigid-body algorithm on symbols: the mass matrix as a recursion.

    Ic_i = I_i + sum_{c child of i} X_c* Ic_c           (leaves to root, body frames)
    F = Ic_i S_i,           M_ii = S_i . F + armature_i
    F <- X_j* F,  j <- parent(j),   M_ij = M_ji = S_j . F   (from i up to the root)

``X_c* Ic_c`` is the composite inertia of body ``c`` expressed in its parent's frame
(:func:`._spatial.inertia_act`) and ``X_j* F`` a force moved to the parent of ``j``
(:func:`._spatial.force_act`). Run on :class:`._ring.TrigRing` polynomials it gives the
expanded ``M`` (equal to the Lagrange route's); run on an :class:`._emit.Emitter` it gives
straight-line code with one assignment per intermediate scalar, the "customised" algorithm
of Khalil and Kleinfinger, whose cost grows with the number of joints as ``n^2`` instead of
with the number of monomials of ``M``. Reference: R. Featherstone, *Rigid Body Dynamics
Algorithms*, Springer 2008, table 6.2; W. Khalil, E. Dombre, *Modeling, Identification and
Control of Robots*, Hermes 2002, sections 9.4 and 9.6.
"""

from __future__ import annotations

from ._spatial import force_act, inertia_act, inertia_mul, joint_placement, motion_subspace


def mass_matrix(rg) -> list:
    """``M(q)`` (n x n lists of scalars of ``rg``), armature on the diagonal; with mimic
    joints ``G^T M_joints G`` (:mod:`.mimic`)."""
    m = rg.model
    X = [joint_placement(rg, i) for i in range(m.nbodies)]
    S = [motion_subspace(rg, i) for i in range(m.nbodies)]
    Ic = [rg.vec(th) for th in m.theta]
    M = [[rg.zero] * m.nbodies for _ in range(m.nbodies)]
    for i in reversed(range(m.nbodies)):
        F = inertia_mul(rg, Ic[i], S[i])
        M[i][i] = rg.reduce(rg.dot(S[i], F) + rg.const(m.armature[i]))
        j = i
        while m.parent[j] >= 0:
            F = force_act(rg, *X[j], F)
            j = m.parent[j]
            M[i][j] = M[j][i] = rg.dot(S[j], F)
        par = m.parent[i]
        if par >= 0:
            Ic[par] = [rg.reduce(a + b) for a, b in zip(Ic[par], inertia_act(rg, *X[i], Ic[i]))]
    return rg.coordinate_matrix(M)
