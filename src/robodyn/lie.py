"""Rotations and rigid motions on NumPy arrays (batched over leading dimensions).

Conventions as in ``spatial.py``: a twist ``xi = [v_lin, omega]`` (linear part first), a
quaternion ``(x, y, z, w)`` (scalar last), ``[w]x`` the cross-product matrix. ``exp_se3`` maps
a twist to the pose ``(quaternion, p)`` with ``p = V(omega) v_lin``; ``log_se3`` inverts it; the
right Jacobians give ``exp(xi + d) = exp(xi) exp(Jr(xi) d)`` to first order.

References: Lynch and Park, *Modern Robotics* (2017), sections 3.2.3 and 3.3.3; Barfoot,
*State Estimation for Robotics* (2017), section 7.1; Sola, Deray and Atchuthan, "A micro Lie
theory for state estimation in robotics" (2018).
"""

from __future__ import annotations

import numpy as np

# Below this angle the series expansions of the exponential's coefficients are used.
_SMALL = 1e-4


def skew(w: np.ndarray) -> np.ndarray:
    """``[w]x`` (..., 3, 3)."""
    z = np.zeros(w.shape[:-1])
    return np.stack([np.stack([z, -w[..., 2], w[..., 1]], -1),
                     np.stack([w[..., 2], z, -w[..., 0]], -1),
                     np.stack([-w[..., 1], w[..., 0], z], -1)], -2)


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions ``(x, y, z, w)`` (..., 4)."""
    av, aw, bv, bw = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    return np.concatenate([aw * bv + bw * av + np.cross(av, bv), aw * bw - np.sum(av * bv, -1, keepdims=True)], -1)


def quat_matrix(quat: np.ndarray) -> np.ndarray:
    x, y, z, w = np.moveaxis(quat / np.linalg.norm(quat, axis=-1, keepdims=True), -1, 0)
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                     np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                     np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], -2)


def coefficients(t: np.ndarray):
    """``(1 - cos t) / t^2`` and ``(t - sin t) / t^3`` (series below ``_SMALL``)."""
    small = t < _SMALL
    ts = np.where(small, 1.0, t)
    a = np.where(small, 0.5 - t * t / 24.0, (1.0 - np.cos(ts)) / ts ** 2)
    b = np.where(small, 1.0 / 6.0 - t * t / 120.0, (ts - np.sin(ts)) / ts ** 3)
    return a, b


def exp_se3(xi: np.ndarray):
    """Quaternion (..., 4) and translation (..., 3) of ``exp(xi)``, ``xi = [v_lin, omega]``."""
    v, w = xi[..., :3], xi[..., 3:]
    t = np.linalg.norm(w, axis=-1)
    half = 0.5 * t
    small = t < _SMALL
    sinc_half = np.where(small, 0.5 - t * t / 48.0, np.sin(half) / np.where(small, 1.0, t))
    quat = np.concatenate([sinc_half[..., None] * w, np.cos(half)[..., None]], -1)
    a, b = coefficients(t)
    wx = np.cross(w, v)
    p = v + a[..., None] * wx + b[..., None] * np.cross(w, wx)
    return quat, p


def inverse_jacobian_coefficients(t):
    """``c(t) = (1 - (t / 2) cot(t / 2)) / t^2`` and ``c'(t) / t`` (series below 1e-2, where the
    closed forms cancel): ``Jr(w)^-1 = 1 + [w]x / 2 + c [w]x^2`` (and ``Jl^-1``, ``V^-1`` with
    ``-[w]x / 2``), ``t = |w|``."""
    small = t < 1e-2
    ts = np.where(small, 1.0, t)
    g = 1.0 - 0.5 * ts / np.tan(0.5 * ts)
    dg = -0.5 / np.tan(0.5 * ts) + 0.25 * ts / np.sin(0.5 * ts) ** 2
    c = np.where(small, 1 / 12 + t * t / 720, g / ts ** 2)
    dc = np.where(small, 1 / 360 + t * t / 7560, dg / ts ** 3 - 2 * g / ts ** 4)
    return c, dc


def log_se3(quat: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``[v_lin, omega]`` (..., 6) with ``exp_se3`` giving the pose ``(quat, p)``, ``|omega| <= pi``."""
    quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    quat = np.where(quat[..., 3:] < 0, -quat, quat)  # the shorter rotation
    s = np.linalg.norm(quat[..., :3], axis=-1)
    t = 2.0 * np.arctan2(s, quat[..., 3])
    small = t < _SMALL
    w = quat[..., :3] * np.where(small, 2.0 + t * t / 12.0, t / np.where(small, 1.0, s))[..., None]
    # V(w)^-1 = I - [w]x / 2 + c [w]x^2
    c, _ = inverse_jacobian_coefficients(t)
    wp = np.cross(w, p)
    v = p - 0.5 * wp + c[..., None] * np.cross(w, wp)
    return np.concatenate([v, w], -1)


def _series(t, f, *terms):
    """``f(ts)`` where ``t >= _SMALL``, else the series ``c0 + c1 t^2 + ...`` (``t`` (...,))."""
    small = t < _SMALL
    ts = np.where(small, 1.0, t)
    return np.where(small, sum(c * t ** (2 * k) for k, c in enumerate(terms)), f(ts))


def exp_so3(w):
    """Rotation matrices ``exp([w]x) = 1 + sin t / t [w]x + (1 - cos t) / t^2 [w]x^2`` (..., 3, 3),
    ``t = |w|`` (Rodrigues' formula)."""
    t = np.linalg.norm(w, axis=-1)
    s = _series(t, lambda x: np.sin(x) / x, 1.0, -1 / 6)
    a, _ = coefficients(t)
    W = skew(w)
    return np.eye(3) + s[..., None, None] * W + a[..., None, None] * (W @ W)


def right_jacobian_so3(w):
    """``Jr(w) = 1 - (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2`` (..., 3, 3): the right
    Jacobian of SO(3), ``exp(w + d) = exp(w) exp(Jr(w) d)`` to first order."""
    a, b = coefficients(np.linalg.norm(w, axis=-1))
    W = skew(w)
    return np.eye(3) - a[..., None, None] * W + b[..., None, None] * (W @ W)


def right_jacobian_se3(xi):
    """``Jr(xi)`` (..., 6, 6) of SE(3), ``exp(xi + d) = exp(xi) exp(Jr(xi) d)`` to first order,
    for ``xi = [v_lin, omega]``: ``[[Jr3(w), Q(-v, -w)], [0, Jr3(w)]]`` with Barfoot's ``Q``
    (*State Estimation for Robotics*, 2017, eq. 7.86; ``Jr(xi) = Jl(-xi)``)."""
    rho, phi = -xi[..., :3], -xi[..., 3:]
    t = np.linalg.norm(phi, axis=-1)
    c1 = _series(t, lambda x: (x - np.sin(x)) / x ** 3, 1 / 6, -1 / 120)
    c2 = _series(t, lambda x: (x * x + 2 * np.cos(x) - 2) / (2 * x ** 4), 1 / 24, -1 / 720)
    c3 = _series(t, lambda x: (2 * x - 3 * np.sin(x) + x * np.cos(x)) / (2 * x ** 5), 1 / 120, -1 / 2520)
    P, R = skew(phi), skew(rho)
    PR, RP, PRP = P @ R, R @ P, P @ R @ P
    Q = (0.5 * R + c1[..., None, None] * (PR + RP + PRP) + c2[..., None, None] * (P @ PR + RP @ P - 3 * PRP)
         + c3[..., None, None] * (PRP @ P + P @ PRP))
    J3 = right_jacobian_so3(xi[..., 3:])
    out = np.zeros(xi.shape[:-1] + (6, 6))
    out[..., :3, :3], out[..., :3, 3:], out[..., 3:, 3:] = J3, Q, J3
    return out


def inverse_adjoint(quat, p):
    """``Ad((R, p))^-1 = [[R^T, -R^T [p]x], [0, R^T]]`` (..., 6, 6) on motions ``[v; w]``."""
    Rt = np.swapaxes(quat_matrix(quat), -1, -2)
    out = np.zeros(quat.shape[:-1] + (6, 6))
    out[..., :3, :3], out[..., :3, 3:], out[..., 3:, 3:] = Rt, -Rt @ skew(p), Rt
    return out
