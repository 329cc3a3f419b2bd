"""The compiled spatial-algebra helpers against their 6 x 6 matrix definitions: the shifts
used by the ABA (world axes at each body's origin) are the rotation-free cases of the general
transforms, and motion and force shifts are dual (they preserve power)."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from robodyn import spatial as sp

rng = np.random.default_rng(11)


def skew(p):
    return np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def motion_transform(R, p):
    """6 x 6 child-to-parent motion transform of the placement (R, p), ``[v; w]`` order."""
    X = np.zeros((6, 6))
    X[:3, :3], X[:3, 3:], X[3:, 3:] = R, skew(p) @ R, R
    return X


def random_rotation():
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    return Q * np.sign(np.linalg.det(Q))


def random_symmetric6():
    A = rng.standard_normal((6, 6))
    return A + A.T


def into(helper, shape, nargs=2):
    """A compiled ``f(x, y[, z])`` returning ``helper(x, y[, z], out)``'s output ``out``."""
    if nargs == 2:
        @njit
        def call(x, y):
            out = np.zeros(shape)
            helper(x, y, out)
            return out
    else:
        @njit
        def call(x, y, z):
            out = np.zeros(shape)
            helper(x, y, z, out)
            return out
    return call


@njit
def _congruence_shift(d, A, lower=True):
    out = np.zeros((6, 6))
    sp.congruence_shift(d, sp.upper_triangle(A), out, lower)
    return out


_shift_motion, _unshift_force, _rotate6 = (into(h, 6) for h in (sp.shift_motion, sp.unshift_force, sp.rotate6))
_inertia_act = into(sp.inertia_act, 10, nargs=3)


@njit
def _inertia_matrix(theta, lower=True):
    out = np.zeros((6, 6))
    sp.inertia_matrix(theta, out, lower)
    return out


@njit
def _congruence_to_parent(R, p, A):
    out = np.zeros((6, 6))
    sp.congruence_to_parent(R, p, A, np.empty((3, 3, 3)), np.empty((3, 3)), out)
    return out


@pytest.mark.parametrize("trial", range(5))
def test_congruence_shift_is_the_transform_without_rotation(trial):
    A, d = random_symmetric6(), rng.standard_normal(3)
    X = np.linalg.inv(motion_transform(np.eye(3), d))  # parent-to-child: the shift by d
    expected = X.T @ A @ X
    np.testing.assert_allclose(_congruence_shift(d, A), expected, rtol=1e-13, atol=1e-13 * np.abs(expected).max())
    upper = _congruence_shift(d, A, False)  # the lower triangle of out left alone
    np.testing.assert_allclose(upper, np.triu(expected), rtol=1e-13, atol=1e-13 * np.abs(expected).max())
    np.testing.assert_allclose(_congruence_to_parent(np.eye(3), d, A), expected, rtol=1e-13,
                               atol=1e-13 * np.abs(expected).max())


@pytest.mark.parametrize("trial", range(5))
def test_shifts_are_the_inverse_transforms_and_dual(trial):
    d, m, f = rng.standard_normal(3), rng.standard_normal(6), rng.standard_normal(6)
    X = motion_transform(np.eye(3), d)
    np.testing.assert_allclose(_shift_motion(d, m), np.linalg.solve(X, m), rtol=1e-13, atol=1e-14)
    # the force at the point d, moved back: X^-T f; the power m . f is the same at both points
    np.testing.assert_allclose(_unshift_force(d, f), np.linalg.inv(X).T @ f, rtol=1e-13, atol=1e-14)
    assert np.isclose(_shift_motion(d, m) @ f, m @ _unshift_force(d, f), rtol=1e-13, atol=1e-14)


@njit
def _inertia_rotated(R, theta):
    return sp.inertia_rotated(R, theta)


@pytest.mark.parametrize("trial", range(5))
def test_inertia_act_and_rotation(trial):
    R, p = random_rotation(), rng.standard_normal(3)
    theta = np.concatenate([[2.0], rng.standard_normal(3), rng.standard_normal(6)])
    X_inv = np.linalg.inv(motion_transform(R, p))
    expected = X_inv.T @ _inertia_matrix(theta) @ X_inv  # the inertia expressed in the parent
    np.testing.assert_array_equal(_inertia_matrix(theta, False), np.triu(_inertia_matrix(theta)))
    np.testing.assert_allclose(_inertia_matrix(_inertia_act(R, p, theta)), expected, rtol=1e-12, atol=1e-12)
    rotated = _inertia_act(R, np.zeros(3), theta)
    np.testing.assert_allclose(_inertia_matrix(np.array(_inertia_rotated(R, theta))),
                               _inertia_matrix(rotated), rtol=1e-14, atol=1e-14)
    x = rng.standard_normal(6)
    np.testing.assert_allclose(_rotate6(R, x), np.concatenate([R @ x[:3], R @ x[3:]]), rtol=1e-14, atol=1e-15)
