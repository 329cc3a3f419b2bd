"""The textbooks' robots (robodyn.symbolic.textbook): their mass matrices equal the books'
closed forms exactly (sympy), and the numbers agree with the numeric kernels on the same
robot built numerically."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.symbolic import textbook

from helpers import assert_rel


def _syms(names):
    return sp.symbols(names, positive=True)


def test_planar_2r_mls_is_eq_4_11():
    eom = rd.symbolic.equations_of_motion(textbook.planar_2r_mls())
    l1, r1, r2, m1, m2, Iz1, Iz2 = _syms("l1 r1 r2 m1 m2 Iz1 Iz2")
    c2 = sp.cos(eom.q[1])
    a, b, d = Iz1 + Iz2 + m1 * r1**2 + m2 * (l1**2 + r2**2), m2 * l1 * r2, Iz2 + m2 * r2**2
    assert sp.simplify(eom.M - sp.Matrix([[a + 2 * b * c2, d + b * c2], [d + b * c2, d]])) == sp.zeros(2)


def test_elbow_mls():
    eom = rd.symbolic.equations_of_motion(textbook.elbow_mls())
    l1, r1, r2, m2, m3 = _syms("l1 r1 r2 m2 m3")
    Iz1, Ix2, Iy2, Iz2, Ix3, Iy3, Iz3 = _syms("Iz1 Ix2 Iy2 Iz2 Ix3 Iy3 Iz3")
    q2, q3 = eom.q[1], eom.q[2]
    s2, c2, s23, c23, c3 = sp.sin(q2), sp.cos(q2), sp.sin(q2 + q3), sp.cos(q2 + q3), sp.cos(q3)
    M = sp.zeros(3)
    M[0, 0] = Iy2 * s2**2 + Iy3 * s23**2 + Iz1 + Iz2 * c2**2 + Iz3 * c23**2 + m2 * r1**2 * c2**2 \
        + m3 * (l1 * c2 + r2 * c23)**2
    M[1, 1] = Ix2 + Ix3 + m3 * l1**2 + m2 * r1**2 + m3 * r2**2 + 2 * m3 * l1 * r2 * c3
    M[1, 2] = M[2, 1] = Ix3 + m3 * r2**2 + m3 * l1 * r2 * c3
    M[2, 2] = Ix3 + m3 * r2**2
    assert sp.simplify(eom.M - M) == sp.zeros(3)


def test_scara_mls_is_example_4_4():
    model = textbook.scara_mls()
    assert model.joint_type == ("revolute", "revolute", "revolute", "prismatic")
    eom = rd.symbolic.equations_of_motion(model)
    l1, l2, r1, r2, m1, m2, m3, m4, Iz1, Iz2, Iz3, Iz4 = _syms("l1 l2 r1 r2 m1 m2 m3 m4 Iz1 Iz2 Iz3 Iz4")
    c2 = sp.cos(eom.q[1])
    a = Iz1 + r1**2 * m1 + l1**2 * (m2 + m3 + m4)
    b = Iz2 + Iz3 + Iz4 + l2**2 * (m3 + m4) + m2 * r2**2
    c = l1 * l2 * (m3 + m4) + l1 * m2 * r2
    d = Iz3 + Iz4
    expected = sp.Matrix([[a + b + 2 * c * c2, b + c * c2, d, 0], [b + c * c2, b, d, 0], [d, d, d, 0], [0, 0, 0, m4]])
    assert sp.simplify(eom.M - expected) == sp.zeros(4)
    # gravity acts on the prismatic joint only: g = dU/dq = (0, 0, 0, m4 g), the quill moving along +z
    g = sp.Symbol("g", positive=True)
    assert sp.simplify(eom.g - sp.Matrix([0, 0, 0, m4 * g])) == sp.zeros(4, 1)


def test_the_numbers_agree_with_the_numeric_kernels():
    """The elbow with numbers: the symbolic M at a state equals crba of the numeric model
    built from the same twists (rd.from_poe)."""
    sm = textbook.elbow_mls()
    values = dict(zip(_syms("l0 l1 r0 r1 r2 m1 m2 m3"), (0.5, 0.4, 0.25, 0.2, 0.15, 3.0, 2.0, 1.0)))
    values.update({s: v for s, v in zip(_syms("Ix1 Iy1 Iz1 Ix2 Iy2 Iz2 Ix3 Iy3 Iz3"),
                                        (0.02, 0.02, 0.01, 0.03, 0.005, 0.03, 0.01, 0.002, 0.01))})
    eom = rd.symbolic.equations_of_motion(sm)
    q = np.array([0.3, -0.8, 1.2])
    M = np.array(eom.M.subs(values).subs(dict(zip(eom.q, q))), dtype=float)
    l0, l1, r0, r1, r2 = (values[s] for s in _syms("l0 l1 r0 r1 r2"))
    at = lambda p: np.block([[np.eye(3), np.array(p)[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])  # noqa: E731
    twists = [[0, 0, 0, 0, 0, 1], [0, -l0, 0, -1, 0, 0], [0, -l0, l1, -1, 0, 0]]
    links = [(values[sp.Symbol(f"m{i}", positive=True)], (0, 0, 0),
              np.diag([values[sp.Symbol(f"{k}{i}", positive=True)] for k in ("Ix", "Iy", "Iz")])) for i in (1, 2, 3)]
    numeric = rd.from_poe(twists, [at((0, 0, r0)), at((0, r1, l0)), at((0, l1 + r2, l0))], links)
    assert_rel(rd.crba(numeric, q), M, 1e-12)


def test_symbolic_builder_two_rods():
    """The lecture's arm with symbols, one line per link (rd.inertia with symbols): Spong's
    closed form of M(q), exactly; a fixed joint merges a tool mass into link 2 as the numeric
    builder does."""
    m1, m2, l1, l2, mt, g = sp.symbols("m1 m2 l1 l2 mt g", positive=True)
    b = rd.symbolic.ModelBuilder("arm", gravity=(0, -g, 0))
    b.add_link("link1", mass=m1, com=(l1 / 2, 0, 0), inertia=rd.inertia.rod(m1, l1, "x"))
    b.add_link("link2", mass=m2, com=(l2 / 2, 0, 0), inertia=rd.inertia.rod(m2, l2, "x"))
    b.add_joint("joint1", "revolute", "world", "link1", axis=(0, 0, 1))
    b.add_joint("joint2", "revolute", "link1", "link2", xyz=(l1, 0, 0), axis=(0, 0, 1))
    model = b.build()
    assert model.link_names == ("link1", "link2") and model.joint_names == ("joint1", "joint2")
    eom = rd.symbolic.equations_of_motion(model)
    c2 = sp.cos(eom.q[1])
    r1, r2, I1, I2 = l1 / 2, l2 / 2, m1 * l1**2 / 12, m2 * l2**2 / 12
    a, bb, d = I1 + I2 + m1 * r1**2 + m2 * (l1**2 + r2**2), m2 * l1 * r2, I2 + m2 * r2**2
    assert sp.simplify(eom.M - sp.Matrix([[a + 2 * bb * c2, d + bb * c2], [d + bb * c2, d]])) == sp.zeros(2)
    # a point mass on a fixed joint at the tip, turned: merged into link 2 exactly
    b.add_link("tool", mass=mt)
    b.add_joint("tool_fixed", "fixed", "link2", "tool", xyz=(l2, 0, 0), rotation=sp.Matrix([[0, -1, 0], [1, 0, 0],
                                                                                          [0, 0, 1]]))
    with_tool = b.build()
    values = {m1: 2.0, m2: 1.5, l1: 0.7, l2: 0.5, mt: 0.3, g: 9.81}
    nb = rd.ModelBuilder("arm", gravity=(0, -9.81, 0))
    nb.add_link("link1", mass=2.0, com=(0.35, 0, 0), inertia=rd.inertia.rod(2.0, 0.7, "x"))
    nb.add_link("link2", mass=1.5, com=(0.25, 0, 0), inertia=rd.inertia.rod(1.5, 0.5, "x"))
    nb.add_link("tool", mass=0.3)
    nb.add_joint("joint1", "revolute", "world", "link1", axis=(0, 0, 1))
    nb.add_joint("joint2", "revolute", "link1", "link2", xyz=(0.7, 0, 0), axis=(0, 0, 1))
    nb.add_joint("tool_fixed", "fixed", "link2", "tool", xyz=(0.5, 0, 0), rpy=(0, 0, np.pi / 2))
    numeric = nb.build()
    theta = np.array([[float(sp.sympify(x).subs(values)) for x in th] for th in with_tool.theta])
    assert_rel(theta, numeric.theta, 1e-12)
    with pytest.raises(rd.ModelError, match="a symbolic model has"):
        b.add_joint("ball", "spherical", "link2", "tool")
    with pytest.raises(rd.ModelError, match="axis must be a unit vector"):
        b.add_joint("j3", "revolute", "link2", "tool", axis=(0, 0, 2))
