"""Spatial algebra on ring polynomials, with the numeric core's conventions.

Motion vectors ``[v; w]`` (linear first), force vectors ``[f; n]``, placements ``(R, p)`` of
a child frame in its parent, inertias as the 10 parameters ``[m, h, I_o]`` about the frame
origin (``h = m c``), exactly as in :mod:`robodyn.spatial`. Reference: R. Featherstone,
*Rigid Body Dynamics Algorithms*, Springer 2008, chapter 2 (halves of the vectors swapped).
"""

from __future__ import annotations

from ._ring import TrigRing


def joint_placement(rg: TrigRing, i: int):
    """``(R, p)`` of body ``i`` in its parent: ``X_tree * X_J(q_i)``.

    Revolute about the unit axis ``a``: ``R = X_tree_R (a a^T + c (1 - a a^T) + s [a]x)``
    (Rodrigues), ``p = X_tree_p``; prismatic: ``R = X_tree_R``, ``p = X_tree_p + X_tree_R a x``,
    with the joint's ``s, c`` or ``x`` (``rg.joint_pos``, ``rg.joint_cos``: a mimic joint's are
    those of its source's coordinate, :mod:`.mimic`).
    """
    m = rg.model
    Rt, pt, a = rg.mat(m.X_tree_R[i]), rg.vec(m.X_tree_p[i]), rg.vec(m.joint_axis[i])
    if not rg.joint_revolute[i]:
        d = rg.matvec(Rt, a)
        return Rt, [pt[r] + d[r] * rg.joint_pos[i] for r in range(3)]
    s, c = rg.joint_pos[i], rg.joint_cos[i]
    ax = [[rg.zero, -a[2], a[1]], [a[2], rg.zero, -a[0]], [-a[1], a[0], rg.zero]]
    rot = [[a[r] * a[k] * (1 - c) + (c if r == k else rg.zero) + s * ax[r][k] for k in range(3)] for r in range(3)]
    return rg.matmul(Rt, rot), pt


def motion_subspace(rg: TrigRing, i: int) -> list:
    """``S_i`` (6,) in body ``i``'s frame."""
    a = rg.vec(rg.model.joint_axis[i])
    z = [rg.zero] * 3
    return z + a if rg.joint_revolute[i] else a + z


def motion_act_inv(rg: TrigRing, R, p, m) -> list:
    """Motion vector from parent to child coordinates: ``[R^T (v - p x w); R^T w]``."""
    w = m[3:]
    u = [m[r] - x for r, x in enumerate(rg.cross(p, w))]
    return rg.matTvec(R, u) + rg.matTvec(R, w)


def force_act(rg: TrigRing, R, p, f) -> list:
    """Force vector from child to parent coordinates: ``[R f; R n + p x R f]``."""
    Rf = rg.matvec(R, f[:3])
    Rn = rg.matvec(R, f[3:])
    return Rf + [rg.reduce(Rn[r] + x) for r, x in enumerate(rg.cross(p, Rf))]


def motion_cross(rg: TrigRing, V, m) -> list:
    """``V x m`` for motion vectors ``V = [v; w]``, ``m = [u; o]``: ``[w x u + v x o; w x o]``."""
    v, w, u, o = V[:3], V[3:], m[:3], m[3:]
    a, b, c = rg.cross(w, u), rg.cross(v, o), rg.cross(w, o)
    return [rg.reduce(a[r] + b[r]) for r in range(3)] + [rg.reduce(x) for x in c]


def force_cross(rg: TrigRing, V, f) -> list:
    """``V x* f`` for a motion ``V = [v; w]`` and a force ``f = [g; n]``: ``[w x g; w x n + v x g]``."""
    v, w, g, n = V[:3], V[3:], f[:3], f[3:]
    a, b, c = rg.cross(w, g), rg.cross(w, n), rg.cross(v, g)
    return [rg.reduce(x) for x in a] + [rg.reduce(b[r] + c[r]) for r in range(3)]


def inertia_mul(rg: TrigRing, theta, V) -> list:
    """``I V`` for the inertia ``theta = [m, h, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the origin:
    ``[m v + w x h; I_o w + h x v]``."""
    m, h = theta[0], theta[1:4]
    Io = [[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]]
    v, w = V[:3], V[3:]
    wh, hv = rg.cross(w, h), rg.cross(h, v)
    f = [rg.reduce(m * v[r] + wh[r]) for r in range(3)]
    n = [rg.reduce(Io[r][0] * w[0] + Io[r][1] * w[1] + Io[r][2] * w[2] + hv[r]) for r in range(3)]
    return f + n


def inertia_act(rg: TrigRing, R, p, theta) -> list:
    """Inertial parameters of a body in the parent frame of its placement ``(R, p)``:
    ``[m, R h + m p, R I_o R^T - p y^T - y p^T + (2 p . y + m p . p) 1 - m p p^T]``
    with ``y = R h`` (parallel-axis theorem about the parent origin, as
    :func:`robodyn.spatial.inertia_act`)."""
    m, h = theta[0], theta[1:4]
    Io = [[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]]
    y = rg.matvec(R, h)
    A = rg.matmul(R, Io)
    py = 2 * rg.dot(p, y) + m * rg.dot(p, p)
    out = [m] + [rg.reduce(y[r] + m * p[r]) for r in range(3)]
    for r, c in ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)):  # Ixx, Ixy, Iyy, Ixz, Iyz, Izz
        RIR = sum((A[r][k] * R[c][k] for k in range(3)), rg.zero)
        out.append(rg.reduce(RIR - p[r] * y[c] - y[r] * p[c] - m * p[r] * p[c] + (py if r == c else rg.zero)))
    return out


def world_poses(rg: TrigRing) -> list:
    """``(oR_i, op_i)`` of every body in the world frame."""
    out = []
    for i in range(rg.model.nbodies):
        R, p = joint_placement(rg, i)
        par = rg.model.parent[i]
        if par < 0:
            out.append((R, p))
        else:
            oR, op = out[par]
            q = rg.matvec(oR, p)
            out.append((rg.matmul(oR, R), [op[r] + q[r] for r in range(3)]))
    return out


def potential_energy(rg: TrigRing, poses) -> "PolyElement":  # noqa: F821
    """``U = -sum_i g . (m_i op_i + oR_i h_i)``: gravity ``g`` in the world frame."""
    g = rg.vec(rg.model.gravity)
    U = rg.zero
    for i, (oR, op) in enumerate(poses):
        th = [rg.const(t) for t in rg.model.theta[i]]
        Rh = rg.matvec(oR, th[1:4])
        U = U - sum((g[r] * (th[0] * op[r] + Rh[r]) for r in range(3)), rg.zero)
    return rg.reduce(U)
