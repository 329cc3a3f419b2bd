"""A high-precision reference for the dynamics of fixed-base trees (mpmath, 40 digits).

Written independently of the compiled kernels, in the classical 3-vector form of the
Newton-Euler equations (Craig, "Introduction to Robotics", 3rd ed., section 6.5, extended to
trees): body velocities, accelerations of the frame origins, Newton and Euler equations about
each body origin, and the forces summed from the leaves. The mass matrix is assembled column by
column (``M e_k = rnea(q, 0, e_k) - rnea(q, 0, 0)`` without gravity) and the forward dynamics
solves ``M a = tau - h`` by LU in the same precision. Revolute and prismatic joints only.
"""

from __future__ import annotations

import mpmath as mp
import numpy as np

from robodyn.joints import PRISMATIC, REVOLUTE

DPS = 40


def _vec(x):
    return mp.matrix([mp.mpf(float(v)) for v in x])


def _mat(X):
    return mp.matrix([[mp.mpf(float(v)) for v in row] for row in X])


def _cross(a, b):
    return mp.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _rot(axis, angle):
    """Rodrigues: rotation by ``angle`` about the unit vector ``axis``."""
    x, y, z = axis
    c, s = mp.cos(angle), mp.sin(angle)
    t = 1 - c
    return mp.matrix([[c + x * x * t, x * y * t - z * s, x * z * t + y * s],
                      [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
                      [z * x * t - y * s, z * y * t + x * s, c + z * z * t]])


def rnea(model, q, v, a, gravity=True):
    """Joint forces (list of mpf, nv) of a fixed-base revolute/prismatic tree."""
    if np.any((model.joint_type != REVOLUTE) & (model.joint_type != PRISMATIC)):
        raise ValueError("the mpmath reference handles revolute and prismatic joints only")
    with mp.workdps(DPS):
        nb = model.nbodies
        q, v, a = [mp.mpf(float(x)) for x in q], [mp.mpf(float(x)) for x in v], [mp.mpf(float(x)) for x in a]
        g = _vec(model.gravity) if gravity else mp.matrix(3, 1)
        E, r, w, dw, acc, F, N = ([None] * nb for _ in range(7))
        for i in range(nb):
            axis = _vec(model.joint_axis[i])
            k = int(model.idx_v[i])
            Rt, pt = _mat(model.X_tree_R[i]), _vec(model.X_tree_p[i])
            p = int(model.parent[i])
            wp, dwp, ap = (mp.matrix(3, 1), mp.matrix(3, 1), -g) if p < 0 else (w[p], dw[p], acc[p])
            if model.joint_type[i] == REVOLUTE:
                E[i], r[i] = Rt * _rot(axis, q[k]), pt
            else:
                E[i], r[i] = Rt, pt + Rt * axis * q[k]
            Et = E[i].T
            a_origin = Et * (ap + _cross(dwp, r[i]) + _cross(wp, _cross(wp, r[i])))
            if model.joint_type[i] == REVOLUTE:
                w[i] = Et * wp + axis * v[k]
                dw[i] = Et * dwp + _cross(Et * wp, axis * v[k]) + axis * a[k]
                acc[i] = a_origin
            else:
                w[i] = Et * wp
                dw[i] = Et * dwp
                acc[i] = a_origin + 2 * _cross(w[i], axis * v[k]) + axis * a[k]
            th = [mp.mpf(float(x)) for x in model.theta[i]]
            m, h = th[0], mp.matrix(th[1:4])
            Io = mp.matrix([[th[4], th[5], th[7]], [th[5], th[6], th[8]], [th[7], th[8], th[9]]])
            F[i] = m * acc[i] + _cross(dw[i], h) + _cross(w[i], _cross(w[i], h))
            N[i] = Io * dw[i] + _cross(w[i], Io * w[i]) + _cross(h, acc[i])
        tau = [None] * model.nv
        for i in range(nb - 1, -1, -1):
            axis = _vec(model.joint_axis[i])
            k = int(model.idx_v[i])
            tau[k] = (axis.T * (N[i] if model.joint_type[i] == REVOLUTE else F[i]))[0]
            p = int(model.parent[i])
            if p >= 0:
                F[p] = F[p] + E[i] * F[i]
                N[p] = N[p] + E[i] * N[i] + _cross(r[i], E[i] * F[i])
        return tau


def mass_matrix(model, q):
    """``M(q)`` as an mpmath matrix, column ``k`` from ``rnea(q, 0, e_k)`` without gravity."""
    with mp.workdps(DPS):
        n = model.nv
        M = mp.matrix(n, n)
        zero = np.zeros(n)
        for k in range(n):
            col = rnea(model, q, zero, np.eye(n)[k], gravity=False)
            for r in range(n):
                M[r, k] = col[r]
        return M


def aba(model, q, v, tau):
    """Forward dynamics ``M^-1 (tau - h)`` solved in 40-digit precision (list of mpf)."""
    with mp.workdps(DPS):
        h = rnea(model, q, v, np.zeros(model.nv))
        rhs = mp.matrix([mp.mpf(float(t)) - hk for t, hk in zip(tau, h)])
        return list(mp.lu_solve(mass_matrix(model, q), rhs))


def to_float(x) -> np.ndarray:
    if isinstance(x, mp.matrix):
        return np.array([[float(x[r, c]) for c in range(x.cols)] for r in range(x.rows)])
    return np.array([float(e) for e in x])
