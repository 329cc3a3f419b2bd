"""Product-of-exponentials models (robodyn.from_poe, robodyn.symbolic.from_poe) and the mass
matrix as a sum over the bodies (robodyn.mass_matrix_from_jacobians, MLS Prop. 4.3).

Oracles: the same robots from DH tables and built-in descriptions (their twists read off the
world Jacobian at q = 0, MLS's definition of the spatial Jacobian), the composite-rigid-body
algorithm on random trees of every joint type, and MLS's closed form of the two-link planar
arm (eq. 4.11), symbolically."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.model import mass_com_inertia

from helpers import RANDOM_MODELS, assert_rel, states


def poe_description(model):
    """``(twists, home, inertias, tool)`` of a tree of 1-dof joints: the columns of the world
    Jacobian at q = 0 (the twists, MLS eq. 3.54), the body poses at q = 0 and the bodies'
    (mass, com, inertia); the tool is the last body's frame."""
    q0 = np.zeros(model.nq)
    poses = rd.forward_kinematics(model, q0)
    twists = [rd.jacobian(model, q0, i, "world")[:, model.idx_v[i]] for i in range(model.nbodies)]
    inertias = [mass_com_inertia(th) for th in model.theta]
    return twists, poses, inertias, poses[-1]


@pytest.mark.parametrize("name", ["panda", "puma560", "elbow_3r", "scara", "planar_2r"])
def test_the_same_robot_from_twists(name):
    """MLS's description of a DH robot gives its dynamics: rnea, M, C, g and the tool pose."""
    model = rd.models.load(name).rigid()
    twists, home, inertias, tool = poe_description(model)
    poe = rd.from_poe(twists, home, inertias, tool=tool, gravity=model.gravity)
    assert poe.nv == model.nv and poe.joint_type.tolist() == model.joint_type.tolist()
    q, v, a = states(model, "poe", name, size=4)
    assert_rel(rd.rnea(poe, q, v, a), rd.rnea(model, q, v, a), 1e-12, "rnea")
    assert_rel(rd.crba(poe, q), rd.crba(model, q), 1e-12, "M")
    assert_rel(rd.coriolis_matrix(poe, q, v), rd.coriolis_matrix(model, q, v), 1e-12, "C")
    assert_rel(rd.gravity(poe, q), rd.gravity(model, q), 1e-12, "g")
    assert_rel(rd.frame_pose(poe, q, "tool"), rd.forward_kinematics(model, q)[:, -1], 1e-12, "g_st(q)")
    for i in range(model.nbodies):  # the link frames are kept: g_sl_i(q)
        assert_rel(rd.frame_pose(poe, q, f"link{i + 1}_frame"), rd.forward_kinematics(model, q)[:, i], 1e-12)


def test_generalized_inertia_matrices_and_a_helical_joint():
    """MLS's 6 x 6 generalized inertias give the same model as (mass, com, inertia); a twist
    with a pitch is a helical joint."""
    model = rd.models.load("puma560").rigid()
    twists, home, inertias, _ = poe_description(model)
    def generalized(m, c, Ic):  # MLS: [[m 1, -m c^], [m c^, Ic - m c^ c^]] in the link frame
        cx = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
        return np.block([[m * np.eye(3), -m * cx], [m * cx, Ic - m * cx @ cx]])

    six = [generalized(*spec) for spec in inertias]
    a = rd.from_poe(twists, home, inertias)
    b = rd.from_poe(twists, home, six)
    np.testing.assert_allclose(b.theta, a.theta, rtol=1e-12, atol=1e-14)
    screw = rd.from_poe([[0.0, 0.0, 0.05, 0.0, 0.0, 1.0]], [np.eye(4)], [(1.0, (0.1, 0, 0), 0.01 * np.eye(3))])
    assert screw.joint_type.tolist() == [rd.joints.HELICAL] and screw.joint_pitch.tolist() == [pytest.approx(0.05)]
    T = rd.frame_pose(screw, np.array([np.pi / 2]), "link1")
    assert_rel(T[:3, 3], [0.0, 0.0, 0.05 * np.pi / 2], 1e-12)
    # rounding in a computed twist (w . v ~ 1e-20, far below the axis tolerance): no pitch
    noisy = rd.from_poe([[1.0, 0.0, 1e-20, 0.0, 0.0, 1.0]], [np.eye(4)], [(1.0, (0.1, 0, 0), 0.01 * np.eye(3))])
    assert noisy.joint_type.tolist() == [rd.joints.REVOLUTE] and noisy.joint_pitch.tolist() == [0.0]


def test_a_urdf_robot_from_twists():
    """A URDF tree (Panda with its two finger joints, from example-robot-data) rebuilt from its
    twists, with its parents: Pinocchio's file, the same dynamics."""
    from conftest import example_robot_data_dir

    with pytest.warns(rd.RobodynWarning, match="mimic joints loaded as independent joints"):
        model = rd.load_urdf(example_robot_data_dir() / "panda_description/urdf/panda.urdf",
                             mimic="independent").rigid()
    twists, home, inertias, _ = poe_description(model)
    poe = rd.from_poe(twists, home, inertias, parents=model.parent, gravity=model.gravity)
    q, v, a = states(model, "poe-urdf", size=3)
    assert_rel(rd.rnea(poe, q, v, a), rd.rnea(model, q, v, a), 1e-12)
    assert_rel(rd.crba(poe, q), rd.crba(model, q), 1e-12)


@pytest.mark.parametrize("model", RANDOM_MODELS[:6])
def test_proposition_4_3_on_random_trees(model):
    """sum_i J_i^T M_i J_i (body Jacobians, generalized inertias) equals the CRBA's M on trees
    of every joint type, branching and floating, with armature."""
    q = states(model, "prop-4.3", size=3)[0]
    assert_rel(rd.mass_matrix_from_jacobians(model, q), rd.crba(model, q), 1e-12)
    assert_rel(rd.mass_matrix_from_jacobians(model, q[0], armature=False), rd.crba(model, q[0], armature=False), 1e-12)


def test_two_link_planar_arm_symbolically():
    """MLS Example 4.2 (Figure 4.3): with link frames at the centres of mass, the mass matrix
    from twists is eq. 4.11, [[alpha + 2 beta c2, delta + beta c2], [delta + beta c2, delta]],
    alpha = Iz1 + Iz2 + m1 r1^2 + m2 (l1^2 + r2^2), beta = m2 l1 r2, delta = Iz2 + m2 r2^2."""
    l1, r1, r2, m1, m2 = sp.symbols("l1 r1 r2 m1 m2", positive=True)
    Ix1, Iy1, Iz1, Ix2, Iy2, Iz2 = sp.symbols("Ix1 Iy1 Iz1 Ix2 Iy2 Iz2", positive=True)
    twists = [(0, 0, 0, 0, 0, 1), (0, -l1, 0, 0, 0, 1)]  # xi_2 = (-w x q, w) with q = (l1, 0, 0)
    home = [sp.Matrix([[1, 0, 0, r1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
            sp.Matrix([[1, 0, 0, l1 + r2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])]
    inertias = [(m1, (0, 0, 0), sp.diag(Ix1, Iy1, Iz1)), (m2, (0, 0, 0), sp.diag(Ix2, Iy2, Iz2))]
    arm = rd.symbolic.from_poe(twists, home, inertias, gravity=(0, 0, 0))
    eom = rd.symbolic.equations_of_motion(arm)
    c2 = sp.cos(eom.q[1])
    alpha = Iz1 + Iz2 + m1 * r1**2 + m2 * (l1**2 + r2**2)
    beta, delta = m2 * l1 * r2, Iz2 + m2 * r2**2
    expected = sp.Matrix([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])
    assert sp.simplify(eom.M - expected) == sp.zeros(2)
    # and the numbers: the same arm built numerically
    values = {l1: 1.0, r1: 0.5, r2: 0.4, m1: 10.0, m2: 5.0, Ix1: 0.1, Iy1: 0.8, Iz1: 0.9, Ix2: 0.1, Iy2: 0.3, Iz2: 0.35}
    num = rd.from_poe([[float(sp.sympify(x).subs(values)) for x in t] for t in twists],
                      [np.array(g.subs(values), dtype=float) for g in home],
                      [(values[m], c, np.array(I.subs(values), dtype=float)) for (m, c, I) in inertias],
                      gravity=(0, 0, 0))
    q = np.array([0.2, -0.9])
    assert_rel(rd.crba(num, q), np.array(expected.subs(values).subs(eom.q[1], q[1]), dtype=float), 1e-12)


def test_bad_input():
    with pytest.raises(rd.ModelError, match="needs \\|w\\| = 1"):
        rd.from_poe([[0, 0, 0, 0, 0, 2.0]], [np.eye(4)], [(1.0, (0, 0, 0), np.eye(3))])
    with pytest.raises(rd.ModelError, match="needs \\|v\\| = 1"):
        rd.from_poe([[0, 0, 0.5, 0, 0, 0]], [np.eye(4)], [(1.0, (0, 0, 0), np.eye(3))])
    with pytest.raises(rd.ModelError, match="one twist and one home pose per joint"):
        rd.from_poe([[0, 0, 0, 0, 0, 1]], [], [(1.0, (0, 0, 0), np.eye(3))])
    with pytest.raises(rd.ModelError, match="parents must list"):
        rd.from_poe([[0, 0, 0, 0, 0, 1]], [np.eye(4)], [(1.0, (0, 0, 0), np.eye(3))], parents=[0])
    with pytest.raises(rd.ModelError, match="6 x 6 generalized inertia"):
        rd.from_poe([[0, 0, 0, 0, 0, 1]], [np.eye(4)], [np.eye(5)])
    with pytest.raises(rd.ModelError, match="triangle inequality"):
        rd.from_poe([[0, 0, 0, 0, 0, 1]], [np.eye(4)], [(1.0, (0, 0, 0), np.diag([0.1, 0.1, 0.5]))])
