"""DH loader, kinematic structure: bodies, joints, stored placements and offsets, bad tables.

(Forward kinematics at q != 0 through ``rd.frame_pose`` is checked elsewhere.)
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from conftest import rot
from robodyn import joints as J
from robodyn.model import inertial_parameters_from

A1, ALPHA1, D1, OFF1 = 0.4, np.pi / 2, 0.1, 0.3
A2, ALPHA2, THETA2, OFF2 = 0.2, -0.5, 0.7, 0.05


def _table(**extra1):
    """Link 1 revolute with an angle offset, link 2 prismatic with a fixed angle and a
    displacement offset."""
    return [
        rd.DHLink(a=A1, alpha=ALPHA1, d=D1, offset=OFF1, **extra1),
        rd.DHLink(a=A2, alpha=ALPHA2, d=0.0, offset=OFF2, joint="prismatic", theta=THETA2),
    ]


def _assert_placement(R, p, R_expected, p_expected):
    np.testing.assert_allclose(R, R_expected, atol=1e-15)
    np.testing.assert_allclose(p, p_expected, atol=1e-15)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_two_link_structure(convention):
    model = rd.from_dh(_table(), convention=convention)
    assert (model.nq, model.nv, model.nbodies) == (2, 2, 2)
    assert model.joint_names == ("joint1", "joint2") and model.link_names == ("link1", "link2")
    assert [J.NAMES[t] for t in model.joint_type] == ["revolute", "prismatic"]
    np.testing.assert_array_equal(model.parent, [-1, 0])
    np.testing.assert_array_equal(model.joint_axis, [[0, 0, 1], [0, 0, 1]])  # about / along z
    assert [model.frame_index(f"frame{i}")[0] for i in range(3)] == [-1, 0, 1]
    assert model.total_mass == 0.0


def test_standard_offsets_and_placements():
    model = rd.from_dh(_table(), convention="standard")
    # T_01 = Rz(q1 + offset1) Tz(d1) Tx(a1) Rx(alpha1): the offset rotates the joint frame,
    # d, a and alpha place frame 1 on body 1
    _assert_placement(model.X_tree_R[0], model.X_tree_p[0], rot("z", OFF1), [0, 0, 0])
    _, R1, p1 = model.frame_index("frame1")
    _assert_placement(R1, p1, rot("x", ALPHA1), [A1, 0, D1])
    # T_12 = Rz(theta2) Tz(q2 + offset2) Tx(a2) Rx(alpha2), joint 2 placed in body 1's frame
    _assert_placement(model.X_tree_R[1], model.X_tree_p[1], rot("x", ALPHA1) @ rot("z", THETA2),
                      np.array([A1, 0, D1]) + rot("x", ALPHA1) @ [0, 0, OFF2])
    _, R2, p2 = model.frame_index("frame2")
    _assert_placement(R2, p2, rot("x", ALPHA2), [A2, 0, 0])


def test_modified_offsets_and_placements():
    model = rd.from_dh(_table(), convention="modified")
    # T_01 = Rx(alpha0) Tx(a0) Rz(q1 + offset1) Tz(d1): frame 1 is the joint frame
    _assert_placement(model.X_tree_R[0], model.X_tree_p[0], rot("x", ALPHA1) @ rot("z", OFF1),
                      np.array([A1, 0, 0]) + rot("x", ALPHA1) @ [0, 0, D1])
    _, R1, p1 = model.frame_index("frame1")
    _assert_placement(R1, p1, np.eye(3), [0, 0, 0])
    # T_12 = Rx(alpha1) Tx(a1) Rz(theta2) Tz(q2 + offset2)
    _assert_placement(model.X_tree_R[1], model.X_tree_p[1], rot("x", ALPHA2) @ rot("z", THETA2),
                      np.array([A2, 0, 0]) + rot("x", ALPHA2) @ [0, 0, OFF2])


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_placements_at_zero_compose_to_dh_product(convention):
    """At q = 0 every joint transform is the identity, so frame i sits at the product of the
    stored placements, which must be the DH product T_01 ... T_{i-1,i} at q = 0."""
    links = _table()
    model = rd.from_dh(links, convention=convention)
    T_body = np.eye(4)
    T_dh = np.eye(4)
    for i, link in enumerate(links):
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = model.X_tree_R[i], model.X_tree_p[i]
        T_body = T_body @ X
        _, Rf, pf = model.frame_index(f"frame{i + 1}")
        F = np.eye(4)
        F[:3, :3], F[:3, 3] = Rf, pf
        T_dh = T_dh @ rd.dh_transform(link, 0.0, convention)
        np.testing.assert_allclose(T_body @ F, T_dh, atol=1e-14)  # T_body: body i's frame, not frame i


def test_base_placement():
    base = np.eye(4)
    base[:3, :3], base[:3, 3] = rot("z", 0.5), [1.0, 2.0, 3.0]
    model = rd.from_dh(_table(), base=base)
    _assert_placement(model.X_tree_R[0], model.X_tree_p[0], rot("z", 0.5) @ rot("z", OFF1), [1, 2, 3])
    _, R0, p0 = model.frame_index("frame0")
    _assert_placement(R0, p0, rot("z", 0.5), [1, 2, 3])


def test_inertia_given_in_dh_frame_is_moved_to_the_body():
    com, Ic = np.array([-0.2, 0.0, 0.01]), np.diag([0.002, 0.03, 0.03])
    model = rd.from_dh(_table(mass=2.0, com=com, inertia=Ic), convention="standard")
    # frame 1 sits at (Rx(alpha1), (a1, 0, d1)) on body 1
    R, p = rot("x", ALPHA1), np.array([A1, 0, D1])
    np.testing.assert_allclose(model.theta[0], inertial_parameters_from(2.0, p + R @ com, R @ Ic @ R.T),
                               rtol=1e-13, atol=1e-16)
    assert model.total_mass == 2.0


def test_joint_data_is_stored():
    links = [
        rd.DHLink(a=0.3, alpha=0.0, d=0.0, lower=-1.0, upper=2.0, armature=0.05, damping=0.3, coulomb=0.4,
                  effort=80.0, velocity=2.5),
        rd.DHLink(a=0.2, alpha=0.0, d=0.0, joint="prismatic"),
    ]
    model = rd.from_dh(links, gravity=(0, -9.81, 0), name="planar")
    np.testing.assert_array_equal(model.lower, [-1.0, -np.inf])
    np.testing.assert_array_equal(model.upper, [2.0, np.inf])
    np.testing.assert_array_equal(model.armature, [0.05, 0.0])
    np.testing.assert_array_equal(model.damping, [0.3, 0.0])
    np.testing.assert_array_equal(model.coulomb, [0.4, 0.0])
    np.testing.assert_array_equal(model.effort_limit, [80.0, np.inf])
    np.testing.assert_array_equal(model.velocity_limit, [2.5, np.inf])
    np.testing.assert_array_equal(model.gravity, [0, -9.81, 0])
    assert model.name == "planar"


# ----------------------------------------------------------------------------------------
# bad tables
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("field", ["a", "alpha", "d", "offset", "theta"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_parameters(convention, field, bad):
    links = [rd.DHLink(a=0.1, alpha=0.0, d=0.0), rd.DHLink(**{"a": 0.1, "alpha": 0.0, "d": 0.0, field: bad})]
    with pytest.raises(rd.ModelError, match=rf"DH table \({convention}\): link 2: DH parameters must be finite"):
        rd.from_dh(links, convention=convention)


@pytest.mark.parametrize("joint", ["spherical", "Revolute", "fixed", ""])
def test_unknown_joint(joint):
    with pytest.raises(rd.ModelError, match=r"link 1: joint must be 'revolute' or 'prismatic', got"):
        rd.from_dh([rd.DHLink(a=0.1, alpha=0.0, d=0.0, joint=joint)])


@pytest.mark.parametrize("kw, what", [
    (dict(mass=np.nan), "must be finite"),
    (dict(mass=-1.0), "negative mass"),
    (dict(mass=1.0, inertia=np.diag([0.1, 0.1, 0.5])), "triangle inequality"),
    (dict(lower=1.0, upper=-1.0), "exceeds upper limit"),
    (dict(damping=-0.1), "damping must be finite and >= 0"),
])
def test_bad_link_data(kw, what):
    """Refused when added (link 1), or when its body is checked (naming link 1 in it)."""
    with pytest.raises(rd.ModelError, match=rf"DH table \(standard\): (link 1: .*{what}|body 'link1'.*{what}.*made of link 1)"):
        rd.from_dh([rd.DHLink(a=0.1, alpha=0.0, d=0.0, **kw)])


def test_bad_table_shape_and_arguments():
    with pytest.raises(rd.ModelError, match="empty DH table"):
        rd.from_dh([])
    with pytest.raises(rd.ModelError, match="link 1: expected a DHLink, got tuple"):
        rd.from_dh([(0.1, 0.0, 0.0)])
    with pytest.raises(ValueError, match="convention must be 'standard' or 'modified'"):
        rd.from_dh(_table(), convention="craig")
    with pytest.raises(ValueError, match=r"base: expected shape \(4, 4\), got \(3, 3\)"):
        rd.from_dh(_table(), base=np.eye(3))


# -- the same robot in both conventions ---------------------------------------------------


def _rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _standard_and_modified(seed):
    """A 5-link table (revolute and prismatic) in standard DH, and the same robot in modified DH.

    Modified frame i is standard frame i-1 moved by ``Rz(theta_i) Tz(d_i)``, and standard frame i
    is modified frame i moved by ``Tx(a_i) Rx(alpha_i)``: the modified row i takes
    ``a_{i-1}, alpha_{i-1}`` and each link's centre of mass and inertia are re-expressed with
    ``Tx(a_i) Rx(alpha_i)``.
    """
    rng = np.random.default_rng(seed)
    std, mod = [], []
    prev_a, prev_alpha = 0.0, 0.0
    for i in range(5):
        joint = "prismatic" if i == 2 else "revolute"
        a, alpha, d, offset, theta = rng.uniform(-0.5, 0.5), rng.uniform(-np.pi, np.pi), rng.uniform(-0.3, 0.3), \
            rng.uniform(-1, 1), rng.uniform(-1, 1)
        mass = rng.uniform(0.5, 3.0)
        com = rng.uniform(-0.2, 0.2, 3)
        d2 = rng.uniform(0.01, 0.1, 3)  # second moments along the axes: a valid rigid body
        inertia = np.diag([d2[1] + d2[2], d2[0] + d2[2], d2[0] + d2[1]])
        std.append(rd.DHLink(a=a, alpha=alpha, d=d, offset=offset, joint=joint, theta=theta, mass=mass, com=com,
                             inertia=inertia))
        R = _rot_x(alpha)
        mod.append(rd.DHLink(a=prev_a, alpha=prev_alpha, d=d, offset=offset, joint=joint, theta=theta, mass=mass,
                             com=R @ com + np.array([a, 0.0, 0.0]), inertia=R @ inertia @ R.T))
        prev_a, prev_alpha = a, alpha
    return std, mod


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_standard_and_modified_tables_give_the_same_dynamics(seed):
    std, mod = _standard_and_modified(seed)
    ms, mm = rd.from_dh(std, "standard"), rd.from_dh(mod, "modified")
    rng = np.random.default_rng(seed + 10)
    q, v, a = rng.uniform(-2, 2, (3, 5))
    for fn, args in ((rd.rnea, (q, v, a)), (rd.aba, (q, v, a)), (rd.crba, (q,)), (rd.gravity, (q,)),
                     (rd.coriolis_matrix, (q, v)), (rd.kinetic_energy, (q, v)), (rd.potential_energy, (q,))):
        ref = fn(ms, *args)
        np.testing.assert_allclose(fn(mm, *args), ref, rtol=1e-10, atol=1e-10 * max(1.0, np.abs(ref).max()))
    # and the frames agree: standard frame i is modified frame i moved by Tx(a_i) Rx(alpha_i)
    for i in range(1, 6):
        post = rd.dh_transform(rd.DHLink(a=std[i - 1].a, alpha=std[i - 1].alpha, d=0.0), 0.0, "modified")
        np.testing.assert_allclose(rd.frame_pose(ms, q, f"frame{i}"), rd.frame_pose(mm, q, f"frame{i}") @ post,
                                   atol=1e-12)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_frame_poses_are_the_dh_product(convention):
    std, mod = _standard_and_modified(5)
    links = std if convention == "standard" else mod
    model = rd.from_dh(links, convention)
    q = np.random.default_rng(3).uniform(-2, 2, 5)
    T = np.eye(4)
    for i, (link, qi) in enumerate(zip(links, q), start=1):
        T = T @ rd.dh_transform(link, qi, convention)
        np.testing.assert_allclose(rd.frame_pose(model, q, f"frame{i}"), T, atol=1e-12)
