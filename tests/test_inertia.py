"""Inertias of uniform bodies (robodyn.inertia): the textbook formulas (rod about its end
m L^2 / 3, disk, thin shell), an independent numerical integration over each solid, the
parallel-axis theorem and rotation against their definitions, exact sympy results, the
lecture's two-rod arm against its closed-form mass matrix, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import inertia as I

from helpers import assert_rel, rng_for


def integrated(mass, inside, lo, hi, n=60):
    """Inertia about the origin of a uniform solid ``inside(x, y, z)`` in the box
    ``[lo, hi]``, by the midpoint rule on an n^3 grid: an oracle that shares no formula."""
    axes = [lo[k] + (np.arange(n) + 0.5) * (hi[k] - lo[k]) / n for k in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    keep = inside(x, y, z)
    p = np.stack([x[keep], y[keep], z[keep]], axis=1)
    m = mass / p.shape[0]
    return m * (np.sum(p * p) * np.eye(3) - p.T @ p)


def test_textbook_formulas():
    m, L, r = 3.0, 2.0, 0.5
    assert_rel(I.shift(I.rod(m, L, "x"), m, (L / 2, 0, 0)), np.diag([0, m * L**2 / 3, m * L**2 / 3]), 1e-15)
    assert_rel(I.rod(m, L, "z"), np.diag([m * L**2 / 12, m * L**2 / 12, 0]), 1e-15)
    assert_rel(I.cylinder(m, r, 0.0, "z"), np.diag([m * r**2 / 4, m * r**2 / 4, m * r**2 / 2]), 1e-15)  # a disk
    assert_rel(I.cylinder(m, 0.0, L, "y"), I.rod(m, L, "y"), 1e-15)
    assert_rel(I.box(m, (1.0, 2.0, 3.0)), m / 12 * np.diag([13.0, 10.0, 5.0]), 1e-15)
    assert_rel(I.sphere(m, r), 0.4 * m * r**2 * np.eye(3), 1e-15)
    assert_rel(I.sphere(m, r, hollow=True), 2 / 3 * m * r**2 * np.eye(3), 1e-15)
    assert_rel(I.point(m, (1.0, 2.0, 0.0)), m * np.array([[4.0, -2, 0], [-2, 1, 0], [0, 0, 5]]), 1e-15)


@pytest.mark.parametrize("shape", ["box", "cylinder", "sphere"])
def test_against_numerical_integration(shape):
    m = 2.0
    if shape == "box":
        a, b, c = 0.4, 0.2, 0.1
        expected = integrated(m, lambda x, y, z: np.ones_like(x, bool), (-a / 2, -b / 2, -c / 2), (a / 2, b / 2, c / 2))
        got = I.box(m, (a, b, c))
    elif shape == "cylinder":
        r, L = 0.1, 0.5
        expected = integrated(m, lambda x, y, z: y * y + z * z <= r * r, (-L / 2, -r, -r), (L / 2, r, r), n=120)
        got = I.cylinder(m, r, L, "x")
    else:
        r = 0.3
        expected = integrated(m, lambda x, y, z: x * x + y * y + z * z <= r * r, (-r, -r, -r), (r, r, r), n=120)
        got = I.sphere(m, r)
    assert_rel(got, expected, 3e-3 * np.abs(expected).max(), shape)


def test_shift_and_rotate_against_their_definitions():
    rng = rng_for("inertia-shift")
    m = 1.7
    Ic = I.box(m, (0.3, 0.2, 0.1))
    from scipy.spatial.transform import Rotation

    R = Rotation.from_rotvec(rng.standard_normal(3)).as_matrix()
    d = rng.standard_normal(3)
    # the definition: I = sum m_i (|p_i|^2 1 - p_i p_i^T) over the body's points, moved by d
    pts = rng.standard_normal((4000, 3)) * [0.3, 0.2, 0.1]
    pts -= pts.mean(axis=0)
    mi = m / len(pts)
    about_com = mi * (np.sum(pts * pts) * np.eye(3) - pts.T @ pts)
    moved = pts + d
    assert_rel(I.shift(about_com, m, d), mi * (np.sum(moved * moved) * np.eye(3) - moved.T @ moved), 1e-12)
    turned = pts @ R.T
    assert_rel(I.rotate(about_com, R), mi * (np.sum(turned * turned) * np.eye(3) - turned.T @ turned), 1e-12)
    # any unit axis: the moment about it is a^T I a
    a = d / np.linalg.norm(d)
    rod = I.rod(m, 0.8, a)
    assert a @ rod @ a == pytest.approx(0.0, abs=1e-15)
    assert_rel(np.linalg.eigvalsh(rod), [0.0, m * 0.64 / 12, m * 0.64 / 12], 1e-12)
    theta = I.parameters(m, d, Ic)
    np.testing.assert_allclose(theta[:4], [m, *(m * d)])
    assert_rel(rd.model.inertia_about_origin(theta), I.shift(Ic, m, d), 1e-13)


def test_exact_with_symbols():
    m, L, r = sp.symbols("m L r", positive=True)
    end = I.shift(I.rod(m, L, "x"), m, (L / 2, 0, 0))
    assert sp.simplify(end - sp.diag(0, m * L**2 / 3, m * L**2 / 3)) == sp.zeros(3)
    assert I.sphere(m, r) == sp.eye(3) * sp.Rational(2, 5) * m * r**2
    assert sp.simplify(I.cylinder(m, r, L, "z")[2, 2] - m * r**2 / 2) == 0
    theta = I.parameters(m, (L / 2, 0, 0), I.rod(m, L, "x"))
    assert sp.simplify(theta[6] - m * L**2 / 3) == 0  # Iyy about the end


def test_two_thin_rods_give_the_textbook_mass_matrix():
    """The lecture's arm, two thin rods m1 = 10, m2 = 5 of lengths 1 and 0.8, one line per
    link: M(q) = [[a + 2 b c2, d + b c2], [d + b c2, d]] with a = I1 + I2 + m1 r1^2 + m2 (l1^2 +
    r2^2), b = m2 l1 r2, d = I2 + m2 r2^2, r = l / 2, I = m l^2 / 12 (Spong et al., 7.4.1)."""
    m1, m2, l1, l2 = 10.0, 5.0, 1.0, 0.8
    b = rd.ModelBuilder()
    b.add_link("base")
    b.add_link("link1", mass=m1, com=(l1 / 2, 0, 0), inertia=I.rod(m1, l1, "x"))
    b.add_link("link2", mass=m2, com=(l2 / 2, 0, 0), inertia=I.rod(m2, l2, "x"))
    b.add_joint("joint1", "revolute", "base", "link1", axis=(0, 0, 1))
    b.add_joint("joint2", "revolute", "link1", "link2", xyz=(l1, 0, 0), axis=(0, 0, 1))
    model = b.build()
    r1, r2, I1, I2 = l1 / 2, l2 / 2, m1 * l1**2 / 12, m2 * l2**2 / 12
    for q2 in (0.0, 0.7, -2.0):
        c2 = np.cos(q2)
        a_, b_, d_ = I1 + I2 + m1 * r1**2 + m2 * (l1**2 + r2**2), m2 * l1 * r2, I2 + m2 * r2**2
        expected = np.array([[a_ + 2 * b_ * c2, d_ + b_ * c2], [d_ + b_ * c2, d_]])
        assert_rel(rd.crba(model, np.array([0.3, q2])), expected, 1e-13)


def test_bad_input():
    with pytest.raises(ValueError, match=r"mass: expected a finite number >= 0, got -1"):
        I.rod(-1, 1.0)
    with pytest.raises(ValueError, match="axis: expected 'x', 'y', 'z' or a unit vector, got 'w'"):
        I.cylinder(1.0, 0.1, 1.0, "w")
    with pytest.raises(ValueError, match="axis: expected a unit vector"):
        I.rod(1.0, 1.0, (1.0, 1.0, 0.0))
    with pytest.raises(ValueError, match="size: expected 3 edge lengths"):
        I.box(1.0, (1.0, 2.0))
    with pytest.raises(ValueError, match="inertia_com: expected a finite 3 x 3 matrix"):
        I.shift(np.eye(2), 1.0, (0, 0, 0))
    with pytest.raises(ValueError, match="position: expected 3 finite numbers"):
        I.point(1.0, (0.0, np.nan, 0.0))
