"""robodyn.interop: ``to_pinocchio`` and ``from_pinocchio`` against Pinocchio.

On the example-robot-data subset of ``urdf_subset.py`` (Panda, UR5, Talos, Solo12, Baxter,
ANYmal with a Kinova arm, a continuous double pendulum), fixed and floating base:

(a) robodyn -> ``to_pinocchio`` -> Pinocchio's rnea, aba and crba equal robodyn's;
(b) ``pin.buildModelFromUrdf`` -> ``from_pinocchio`` -> robodyn's rnea, aba and crba equal
    Pinocchio's, and the converted model has what ``rd.load_urdf`` reads from the same file;
(c) robodyn -> Pinocchio -> robodyn gives the same model and the same dynamics;

plus a hand-built Pinocchio tree with every joint type robodyn converts, and the errors
(joint types robodyn lacks, Pinocchio missing), and mimic joints as couplings. Seeded random states; relative
error (max abs difference / max(1, max abs of the reference)) below 1e-9. Pinocchio's
dynamics leave joint friction out, so robodyn runs with ``friction=False`` against it.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import example_robot_data_dir
from helpers import assert_rel, random_state, rng_for, with_friction_and_armature
from urdf_subset import SUBSET

import robodyn as rd
from robodyn import joints as J
from robodyn.interop import (
    configuration_from_pinocchio,
    configuration_to_pinocchio,
    from_pinocchio,
    to_pinocchio,
)
from robodyn.random import random_inertia

TOL = 1e-9
N_STATES = 3
CASES = [pytest.param(path, fb, id=f"{path.split('/')[-1]}-{'floating' if fb else 'fixed'}")
         for path in SUBSET for fb in (False, True)]


def load_robodyn(path: str, floating_base: bool) -> rd.Model:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)  # ignored URDF elements
        return rd.load_urdf(example_robot_data_dir() / path, floating_base=floating_base, mimic="independent")


def load_pinocchio(path: str, floating_base: bool) -> pin.Model:
    full = str(example_robot_data_dir() / path)
    return pin.buildModelFromUrdf(full, pin.JointModelFreeFlyer()) if floating_base else pin.buildModelFromUrdf(full)


def assert_same_dynamics(model: rd.Model, pm: pin.Model, rng: np.random.Generator, what: str) -> None:
    """rnea, aba and crba of robodyn (``model``) and Pinocchio (``pm``) at random states."""
    data = pm.createData()
    for _ in range(N_STATES):
        q, v, a = random_state(model, rng)
        tau = rng.standard_normal(model.nv)
        qp = configuration_to_pinocchio(pm, q)
        assert_rel(rd.rnea(model, q, v, a, friction=False), pin.rnea(pm, data, qp, v, a), TOL, f"{what} rnea")
        assert_rel(rd.aba(model, q, v, tau, friction=False), pin.aba(pm, data, qp, v, tau), TOL, f"{what} aba")
        M = pin.crba(pm, data, qp)  # upper triangle
        assert_rel(rd.crba(model, q), np.triu(M) + np.triu(M, 1).T, TOL, f"{what} crba")


def assert_same_model(mine: rd.Model, ref: rd.Model, exact_inertia: bool = False) -> None:
    """Topology, names, frames, placements, inertias and per-dof data agree."""
    for key in ("link_names", "body_joint_names", "joint_names", "frame_names", "name"):
        assert getattr(mine, key) == getattr(ref, key), key
    for key in ("parent", "joint_type", "idx_q", "idx_v", "frame_body", "lower", "upper", "velocity_limit",
                "effort_limit", "damping", "coulomb", "armature", "gravity"):
        np.testing.assert_array_equal(getattr(mine, key), getattr(ref, key), err_msg=key)
    for key in ("joint_axis", "X_tree_R", "X_tree_p", "frame_R", "frame_p", "theta"):
        np.testing.assert_allclose(getattr(mine, key), getattr(ref, key), rtol=1e-12, atol=1e-14, err_msg=key)


# (a) robodyn -> Pinocchio ------------------------------------------------------------------
@pytest.mark.parametrize("path, floating_base", CASES)
def test_to_pinocchio_has_the_same_dynamics(path, floating_base):
    model = load_robodyn(path, floating_base)
    pm = to_pinocchio(model)
    assert (pm.nq, pm.nv, pm.njoints) == (model.nq, model.nv, model.nbodies + 1)  # same q: no (cos, sin)
    assert list(pm.names[1:]) == list(model.body_joint_names)
    assert [pm.joints[i + 1].idx_v for i in range(model.nbodies)] == model.idx_v.tolist()
    for name in model.link_names + model.frame_names:  # every link and frame is a Pinocchio frame
        body, R, p = model.frame_index(name)
        f = pm.frames[pm.getFrameId(name, pin.FrameType.BODY)]
        assert f.parentJoint == body + 1
        np.testing.assert_allclose(f.placement.homogeneous[:3], np.c_[R, p], atol=1e-15)
    np.testing.assert_array_equal(pm.gravity.linear, model.gravity)
    assert_same_dynamics(model, pm, rng_for("to_pinocchio", path, floating_base), path)


def test_to_pinocchio_carries_armature_and_limits():
    """Armature enters Pinocchio's dynamics; limits, damping and friction are carried over
    (robodyn's +-inf as Pinocchio's +-max double)."""
    rng = rng_for("armature")
    model = with_friction_and_armature(load_robodyn("panda_description/urdf/panda.urdf", True), rng)
    pm = to_pinocchio(model)
    np.testing.assert_array_equal(pm.armature, model.armature)
    np.testing.assert_array_equal(pm.damping, model.damping)
    np.testing.assert_array_equal(pm.friction, model.coulomb)
    np.testing.assert_array_equal(pm.effortLimit[6:], model.effort_limit[6:])
    np.testing.assert_array_equal(pm.lowerPositionLimit[7:], model.lower[6:])
    assert np.all(pm.upperPositionLimit[:7] == np.finfo(float).max)  # the free flyer: unbounded
    assert_same_dynamics(model, pm, rng, "panda with armature")


# (b) Pinocchio -> robodyn ------------------------------------------------------------------
@pytest.mark.parametrize("path, floating_base", CASES)
def test_from_pinocchio_has_the_same_dynamics(path, floating_base):
    pm = load_pinocchio(path, floating_base)
    model = from_pinocchio(pm)
    assert model.nv == pm.nv
    assert [model.idx_v[j - 1] for j in range(1, pm.njoints)] == [pm.joints[j].idx_v for j in range(1, pm.njoints)]
    # what load_urdf reads from the same file: continuous joints as one unbounded angle, the
    # same names, frames, limits, friction and inertias
    assert_same_model(model, load_robodyn(path, floating_base))
    assert_same_dynamics(model, pm, rng_for("from_pinocchio", path, floating_base), path)


def test_continuous_joints_are_one_angle():
    """Pinocchio's (cos, sin) of a continuous joint is one unbounded angle in robodyn."""
    pm = load_pinocchio("double_pendulum_description/urdf/double_pendulum_continuous.urdf", True)
    model = from_pinocchio(pm)
    assert all(pm.joints[j].shortname().startswith("JointModelRUB") for j in range(2, pm.njoints))
    assert (pm.nq, model.nq) == (11, 9)
    assert np.all(np.isinf(model.upper)) and np.all(np.isinf(model.lower))
    rng = rng_for("continuous")
    q = random_state(model, rng, (4, 5))[0]
    qp = configuration_to_pinocchio(pm, q)
    assert qp.shape == (4, 5, 11)
    np.testing.assert_allclose(qp[..., 7:9], np.stack([np.cos(q[..., 7]), np.sin(q[..., 7])], -1), atol=1e-15)
    np.testing.assert_array_equal(qp[..., :7], q[..., :7])  # free flyer: the same [x y z qx qy qz qw]
    q_back = configuration_from_pinocchio(pm, qp)
    np.testing.assert_allclose(np.cos(q_back - q), 1.0, atol=1e-15)
    np.testing.assert_allclose(configuration_from_pinocchio(pm, pin.neutral(pm)), np.r_[np.zeros(6), 1, 0, 0])
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 9\), got \(11,\)"):
        configuration_to_pinocchio(pm, np.zeros(11))
    with pytest.raises(ValueError, match=r"q_pin: expected shape \(\.\.\., 11\), got \(9,\)"):
        configuration_from_pinocchio(pm, np.zeros(9))


def every_joint_type() -> pin.Model:
    """A hand-built Pinocchio tree with every joint type robodyn converts: a free flyer at a
    non-identity placement, aligned and unaligned revolute and prismatic joints, continuous
    (RUB) joints, branches, random placements and inertias, gravity not along z, armature."""
    pin.seed(7)  # placements
    rng = np.random.default_rng(7)
    pm = pin.Model()
    pm.name = "every-joint"
    pm.gravity = pin.Motion(np.array([1.0, -2.0, -9.0]), np.zeros(3))
    joints = [  # (parent joint, joint model, name)
        (0, pin.JointModelFreeFlyer(), "base"),
        (1, pin.JointModelRX(), "rx"), (2, pin.JointModelRY(), "ry"), (3, pin.JointModelRZ(), "rz"),
        (1, pin.JointModelRevoluteUnaligned(0.0, 0.6, -0.8), "r_unaligned"),
        (5, pin.JointModelRUBX(), "rubx"), (6, pin.JointModelRUBY(), "ruby"), (7, pin.JointModelRUBZ(), "rubz"),
        (5, pin.JointModelRevoluteUnboundedUnaligned(), "rub_unaligned"),
        (1, pin.JointModelPX(), "px"), (10, pin.JointModelPY(), "py"), (11, pin.JointModelPZ(), "pz"),
        (12, pin.JointModelPrismaticUnaligned(-0.48, 0.6, 0.64), "p_unaligned"),
    ]
    for parent, jm, name in joints:
        j = pm.addJoint(parent, jm, pin.SE3.Random(), name)
        pm.appendBodyToJoint(j, pin.Inertia.FromDynamicParameters(random_inertia(rng)), pin.SE3.Identity())
    pm.addFrame(pin.Frame("tool", 4, 0, pin.SE3.Random(), pin.FrameType.OP_FRAME), False)
    pm.armature = rng.uniform(0.0, 0.1, pm.nv)
    return pm


def test_every_joint_type_from_pinocchio():
    pm = every_joint_type()
    model = from_pinocchio(pm)
    assert [rd.joints.NAMES[t] for t in model.joint_type] == ["free"] + ["revolute"] * 8 + ["prismatic"] * 4
    np.testing.assert_allclose(model.joint_axis[4], [0.0, 0.6, -0.8])
    np.testing.assert_allclose(model.joint_axis[12], [-0.48, 0.6, 0.64])
    assert model.link_names == model.body_joint_names == tuple(pm.names[1:])  # no BODY frames: joint names
    assert model.frame_names == ("tool",) and model.frame_body.tolist() == [3]
    np.testing.assert_array_equal(model.gravity, [1.0, -2.0, -9.0])
    np.testing.assert_array_equal(model.armature, pm.armature)
    assert_same_dynamics(model, pm, rng_for("every joint"), "every joint type")
    # and back: Pinocchio's continuous joints come back as revolute joints with one angle
    back = to_pinocchio(model)
    assert back.nq == model.nq == pm.nq - 4
    assert_same_dynamics(model, back, rng_for("every joint", "back"), "every joint type, back")
    assert_same_model(from_pinocchio(back), model)


# (c) robodyn -> Pinocchio -> robodyn -------------------------------------------------------
@pytest.mark.parametrize("path, floating_base", CASES)
def test_round_trip(path, floating_base):
    rng = rng_for("round trip", path, floating_base)
    model = with_friction_and_armature(load_robodyn(path, floating_base), rng)
    back = from_pinocchio(to_pinocchio(model))
    assert_same_model(back, model)
    for _ in range(N_STATES):
        q, v, a = random_state(model, rng)
        assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), TOL, "rnea")
        assert_rel(rd.aba(back, q, v, a), rd.aba(model, q, v, a), TOL, "aba")
        assert_rel(rd.crba(back, q), rd.crba(model, q), TOL, "crba")


def test_round_trip_of_a_builtin_model_with_a_massless_body():
    """A body without mass keeps its (zero) inertia both ways."""
    b = rd.ModelBuilder("massless")
    b.add_link("base")
    b.add_link("a", mass=1.0, com=(0.1, 0, 0), inertia=np.diag([0.01, 0.02, 0.02]))
    b.add_link("ghost")
    b.add_joint("j1", "revolute", "base", "a", axis=(0, 0, -1), lower=-1, upper=2, velocity=3, effort=4)
    b.add_joint("j2", "prismatic", "a", "ghost", xyz=(0.2, 0, 0), axis=(1, 1, 0))
    model = b.build()
    assert model.theta[1].tolist() == [0.0] * 10
    assert_same_model(from_pinocchio(to_pinocchio(model)), model)


# (d) errors ----------------------------------------------------------------------------
def test_aligned_helical_joints_come_in_as_helical_joints():
    pm = pin.Model()
    j = pm.addJoint(0, pin.JointModelHZ(0.1), pin.SE3.Identity(), "screw")
    pm.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    model = from_pinocchio(pm)
    assert model.joint_type.tolist() == [J.HELICAL] and model.joint_pitch.tolist() == [0.1]
    np.testing.assert_allclose(model.joint_axis[0], [0, 0, 1])
    q, v, a = np.array([0.4]), np.array([1.2]), np.array([-0.3])
    np.testing.assert_allclose(rd.rnea(model, q, v, a), pin.rnea(pm, pm.createData(), q, v, a), rtol=1e-12)


@pytest.mark.parametrize("seed", [7, 8, 12])  # 8 and 12 met the axes read from an unfilled joint data
def test_universal_joints_come_in_as_two_revolute_joints_on_a_cross_link(seed):
    pin.seed(seed)  # SE3.Random
    pm = pin.Model()
    rng = np.random.default_rng(seed)

    def box():  # a physical body (a random pin.Inertia may violate the triangle inequality)
        return pin.SE3.Random().act(pin.Inertia.FromBox(rng.uniform(0.5, 2.0), *rng.uniform(0.1, 0.5, 3)))

    j = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    pm.appendBodyToJoint(j, box(), pin.SE3.Identity())
    j = pm.addJoint(j, pin.JointModelRZ(), pin.SE3.Random(), "shoulder")
    pm.appendBodyToJoint(j, box(), pin.SE3.Identity())
    a1, a2 = rng.normal(size=3), rng.normal(size=3)
    u = pm.addJoint(j, pin.JointModelUniversal(a1 / np.linalg.norm(a1), a2 / np.linalg.norm(a2)), pin.SE3.Random(),
                    "wrist")
    pm.appendBodyToJoint(u, box(), pin.SE3.Identity())
    j = pm.addJoint(u, pin.JointModelRY(), pin.SE3.Random(), "finger")
    pm.appendBodyToJoint(j, box(), pin.SE3.Identity())
    pm.addFrame(pin.Frame("tool", u, pin.SE3.Random(), pin.FrameType.OP_FRAME))
    pm.lowerPositionLimit[8:10], pm.upperPositionLimit[8:10] = [-1.0, -0.5], [1.0, 0.5]
    model = from_pinocchio(pm)
    assert model.nq == pm.nq and model.nv == pm.nv and model.nbodies == 5
    assert model.body_joint_names == ("root", "shoulder", "wrist[1]", "wrist[2]", "finger")
    assert model.parent.tolist() == [-1, 0, 1, 2, 3] and np.all(model.theta[2] == 0)  # the massless cross link
    np.testing.assert_array_equal(model.lower[7:9], [-1.0, -0.5])
    data = pm.createData()
    q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    v, a = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
    np.testing.assert_allclose(rd.rnea(model, q, v, a), pin.rnea(pm, data, q, v, a), rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(rd.crba(model, q), pin.crba(pm, data, q), rtol=1e-11, atol=1e-11)
    pin.framesForwardKinematics(pm, data, q)
    np.testing.assert_allclose(rd.frame_pose(model, q, "tool"), data.oMf[pm.getFrameId("tool")].homogeneous,
                               atol=1e-12)


@pytest.mark.parametrize("joint, kind", [
    (pin.JointModelSphericalZYX(), "JointModelSphericalZYX"),
    (pin.JointModelTranslation(), "JointModelTranslation"),
])
def test_unsupported_joint_types_are_named(joint, kind):
    pm = pin.Model()
    j = pm.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "shoulder")
    pm.addJoint(j, joint, pin.SE3.Identity(), "wrist")
    with pytest.raises(rd.ModelError, match=rf"joint 'wrist' is a {kind} \(\d q, \d v\), which robodyn cannot "
                                            "represent; supported Pinocchio joints: JointModelRX"):
        from_pinocchio(pm)


def test_free_flyer_below_the_root_is_an_error():
    pm = pin.Model()
    j = pm.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "shoulder")
    pm.addJoint(j, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "loose")
    with pytest.raises(rd.ModelError, match="joint 'loose' is a JointModelFreeFlyer below joint 'shoulder'"):
        from_pinocchio(pm)


MIMIC_URDF = """<robot name="gripper">
  <link name="palm"/>
  <link name="left"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="right"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="left_finger" type="prismatic"><parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
  <joint name="right_finger" type="prismatic"><parent link="palm"/><child link="right"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/><mimic joint="left_finger"/></joint>
</robot>"""


def test_mimic_joints_become_couplings():
    """A JointModelMimic is a mimic coupling (both ways; more in test_mimic_interop.py)."""
    from test_mimic_interop import assert_same_dynamics as assert_same_coupled

    pm = pin.buildModelFromXML(MIMIC_URDF, mimic=True)
    model = from_pinocchio(pm)
    assert isinstance(model, rd.CoupledModel) and model.mimic == (("right_finger", "left_finger", 1.0, 0.0),)
    assert model.joint_names == ("left_finger",) and model.full.joint_names == ("left_finger", "right_finger")
    assert_same_coupled(model, pm, "gripper")  # Pinocchio's aba does not take mimic joints
    model = from_pinocchio(pin.buildModelFromXML(MIMIC_URDF))  # without mimic: two independent joints
    assert model.joint_names == ("left_finger", "right_finger")


def test_missing_pinocchio_names_the_package(monkeypatch):
    model = rd.models.load("double_pendulum")
    pm = pin.Model()
    monkeypatch.setitem(sys.modules, "pinocchio", None)  # `import pinocchio` now raises ImportError
    with pytest.raises(ImportError, match="to_pinocchio needs Pinocchio.*pip install pin"):
        to_pinocchio(model)
    with pytest.raises(ImportError, match="from_pinocchio needs Pinocchio.*pip install pin"):
        from_pinocchio(pm)


def test_bad_inputs():
    with pytest.raises(TypeError, match="expected a pinocchio.Model, got Model"):
        from_pinocchio(rd.models.load("double_pendulum"))
    with pytest.raises(ValueError, match="physical must be 'error', 'warn' or 'repair'"):
        from_pinocchio(pin.Model(), physical="ignore")
    with pytest.raises(ValueError, match="depth-first"):  # parents [-1, 0, 0, 0, 3, 1, 5]
        to_pinocchio(rd.random.random_model(6, seed=5, floating_base=True))


def test_unphysical_inertia_and_rotor_inertia():
    """An inertia no rigid body has is an error unless physical="warn"; a rotor inertia,
    which Pinocchio's dynamics do not use, is reported."""
    pm = pin.Model()
    j = pm.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    pm.appendBodyToJoint(j, pin.Inertia(1.0, np.zeros(3), np.diag([1.0, 1.0, 3.0])), pin.SE3.Identity())
    with pytest.raises(rd.ModelError, match=r"from_pinocchio\(model ''\): body 0 \('j', joint 'j'\): .*"
                                            r"triangle inequality.*physical='warn'"):
        from_pinocchio(pm)
    with pytest.warns(rd.RobodynWarning, match=r"body 0 \('j', joint 'j'\).*triangle inequality.*kept as given"):
        model = from_pinocchio(pm, physical="warn")
    assert model.theta[0, 9] == 3.0
    with pytest.warns(rd.RobodynWarning, match=r"body 0 \('j', joint 'j'\).*triangle inequality.*\[1, 1, 3\] "
                                               r"repaired to \[1.66667, 1.66667, 1.66667\]"):
        model = from_pinocchio(pm, physical="repair")
    np.testing.assert_allclose(model.theta[0, [4, 6, 9]], 5.0 / 3.0, rtol=1e-14)
    assert model.physical == "error"
    pm.inertias[j] = pin.Inertia(1.0, np.zeros(3), np.eye(3))
    pm.rotorInertia = np.array([0.5])
    with pytest.warns(rd.RobodynWarning, match=r"rotorInertia \[0.5\] not converted"):
        from_pinocchio(pm)
