"""URDF writer (robodyn.write_urdf): load_urdf(write_urdf(model)) reproduces the dynamics, the
limits, friction and frames, for built-in robots and random trees (fixed and floating base);
what URDF cannot hold is reported."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from helpers import assert_rel, random_model, rng_for, states


def _reload(model, **kw):
    return rd.load_urdf(rd.write_urdf(model), floating_base=model.floating_base, **kw)


def _permutations(model, other):
    """Index maps of ``other``'s q and v into ``model``'s (bodies matched by joint name)."""
    pq, pv = [], []
    for j in range(other.nbodies):
        i = model.body_joint_names.index(other.body_joint_names[j])
        nq, nv = J.NQ[model.joint_type[i]], J.NV[model.joint_type[i]]
        pq += list(range(model.idx_q[i], model.idx_q[i] + nq))
        pv += list(range(model.idx_v[i], model.idx_v[i] + nv))
    return np.array(pq), np.array(pv)


@pytest.mark.parametrize("name", rd.models.names())
def test_builtin_round_trip(name):
    """Everything comes back, the armature too (as Drake's rotor inertia)."""
    model = rd.models.load(name)
    back = _reload(model)
    assert back.joint_names == model.joint_names and back.link_names == model.link_names
    q, v, a = states(model, "urdf", size=3)
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-12)
    assert_rel(back.inertial_parameters(), model.inertial_parameters(), 1e-12)
    for key in ("lower", "upper", "velocity_limit", "effort_limit", "damping", "coulomb", "armature"):
        assert np.array_equal(getattr(back, key), getattr(model, key)), key
    assert sorted(back.frame_names) == sorted(model.frame_names)
    for f in model.frame_names:
        assert_rel(rd.frame_pose(back, q, f), rd.frame_pose(model, q, f), 1e-12, f)


@pytest.mark.parametrize("floating_base", [False, True])
@pytest.mark.parametrize("seed", [1, 2])
def test_random_tree_round_trip(seed, floating_base):
    """Branching trees: the reloaded bodies come in URDF order (children by joint name), so
    states are compared through the joint names."""
    model = random_model(9, seed=seed, floating_base=floating_base, branching=0.6)
    rng = rng_for("writer", seed, floating_base)
    nv = model.nv
    one = model.joint_type != 2
    lower = np.where(np.repeat(one, np.where(one, 1, 6)), -rng.uniform(0.5, 2, nv), -np.inf)
    model = model.replace(lower=lower, upper=-lower, damping=rng.uniform(0, 1, nv) * np.isfinite(lower),
                          coulomb=rng.uniform(0, 1, nv) * np.isfinite(lower))
    back = _reload(model)
    pq, pv = _permutations(model, back)
    q, v, a = states(model, "tree", size=2)
    assert_rel(rd.rnea(back, q[:, pq], v[:, pv], a[:, pv]), rd.rnea(model, q, v, a)[:, pv], 1e-12)
    assert np.array_equal(back.lower, model.lower[pv]) and np.array_equal(back.damping, model.damping[pv])


def test_written_file_and_unbounded_joints(tmp_path):
    """A file path; revolute joints without limits are continuous (no <limit>), prismatic ones
    have a <limit> of +-the largest double, which reads back as no limit."""
    model = random_model(4, seed=5)
    path = tmp_path / "robot.urdf"
    text = rd.write_urdf(model, path)
    assert path.read_text() == text
    prismatic = text.count('type="prismatic"')
    assert text.count('type="continuous"') + prismatic == 4 and prismatic > 0
    assert text.count('<limit lower="-1.7976931348623157e+308" upper="1.7976931348623157e+308" '
                      'velocity="1.7976931348623157e+308" effort="1.7976931348623157e+308"/>') == prismatic
    back = rd.load_urdf(path)
    for key in ("lower", "upper", "velocity_limit", "effort_limit"):
        np.testing.assert_array_equal(getattr(back, key), getattr(model, key), err_msg=key)
    q, v, a = states(model, "file")
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-12)


def test_what_urdf_cannot_hold():
    model = rd.models.load("puma560")  # has armature
    slider = rd.ModelBuilder()
    slider.add_link("root")
    slider.add_link("a", mass=1.0, inertia=0.01 * np.eye(3))
    slider.add_joint("j", "planar", "root", "a", armature=0.1)
    with pytest.warns(rd.RobodynWarning, match="armature of multi-dof joints"):
        rd.write_urdf(slider.build())
    with pytest.warns(rd.RobodynWarning, match="gravity"):
        rd.write_urdf(model.replace(armature=np.zeros(6), gravity=(0, -9.81, 0)))
    lower = np.array(model.lower)
    lower[2] = -np.inf
    with pytest.raises(ValueError, match="one-sided position limit"):
        rd.write_urdf(model.replace(armature=np.zeros(6), lower=lower))


def test_free_bodies_beside_a_fixed_base_round_trip_as_floating_joints():
    """Bodies on free joints beside a fixed tree (a MuJoCo scene, say) become URDF floating
    joints under the root link and load back as free joints; beside a floating base, and for
    spherical joints, URDF has no way: ValueError."""
    b = rd.ModelBuilder("scene")
    b.add_link("world")
    b.add_link("arm", mass=1.0, com=(0.1, 0, 0), inertia=np.diag([0.01, 0.02, 0.02]))
    b.add_joint("shoulder", "revolute", "world", "arm", axis=(0, 0, 1), xyz=(0, 0, 0.5))
    b.add_link("box", mass=2.0, com=(0, 0.1, 0), inertia=np.diag([0.03, 0.02, 0.04]))
    b.add_joint("box_free", "free", "world", "box", xyz=(1, 0, 0), rpy=(0.1, 0.2, 0.3))
    model = b.build()
    text = rd.write_urdf(model)
    assert 'type="floating"' in text
    back = rd.load_urdf(text)
    pq, pv = _permutations(model, back)
    q, v, a = states(model, "scene", size=2)
    assert_rel(rd.rnea(back, q[:, pq], v[:, pv], a[:, pv]), rd.rnea(model, q, v, a)[:, pv], 1e-12)
    b2 = rd.ModelBuilder("two")
    b2.add_link("a", mass=1.0, inertia=np.eye(3) * 0.01)
    b2.add_link("world")
    b2.add_link("b", mass=1.0, inertia=np.eye(3) * 0.01)
    b2.add_joint("fa", "free", "world", "a")
    b2.add_joint("fb", "free", "world", "b")
    two = b2.build()
    assert two.floating_base and two.nv == 12
    with pytest.raises(ValueError, match="free joint 'fb' beside a floating base"):
        rd.write_urdf(two)


def test_planar_joints_round_trip():
    model = random_model(5, seed=3, branching=0.5, joint_types=(J.REVOLUTE, J.PLANAR))
    assert J.PLANAR in model.joint_type
    back = rd.load_urdf(rd.write_urdf(model))
    q, v, a = states(model, "planar", size=2)
    pq, pv = _permutations(model, back)
    assert_rel(rd.rnea(back, q[:, pq], v[:, pv], a[:, pv]), rd.rnea(model, q, v, a)[:, pv], 1e-12)


def _pinocchio_reads(model):
    """Pinocchio's model of ``write_urdf(model)`` (free flyer for a floating base), a function
    mapping ``model``'s configuration to Pinocchio's (a continuous joint is ``(cos, sin)``
    there), and the map of Pinocchio's v entries into ``model``'s (joints matched by name)."""
    import pinocchio as pin

    text = rd.write_urdf(model)
    pm = pin.buildModelFromXML(text, pin.JointModelFreeFlyer()) if model.floating_base else pin.buildModelFromXML(text)
    parts, pv = [], []
    for j in range(1, pm.njoints):
        name = pm.names[j]
        i = 0 if (model.floating_base and name == "root_joint") else model.body_joint_names.index(name)
        nq, nv = J.NQ[model.joint_type[i]], J.NV[model.joint_type[i]]
        assert pm.joints[j].nv == nv, name
        first = model.idx_q[i]
        if pm.joints[j].nq == nq:
            parts.append(lambda q, s=slice(first, first + nq): q[s])
        else:  # continuous: Pinocchio's (cos, sin) of robodyn's angle
            assert (pm.joints[j].nq, nq) == (2, 1), name
            parts.append(lambda q, k=first: np.array([np.cos(q[k]), np.sin(q[k])]))
        pv += list(range(model.idx_v[i], model.idx_v[i] + nv))
    return pm, (lambda q: np.concatenate([f(q) for f in parts])), np.array(pv, dtype=int)


@pytest.mark.parametrize("model", [rd.models.load("panda"), rd.models.load("puma560"), rd.models.load("scara"),
                                   random_model(9, seed=3, floating_base=False, branching=0.6),
                                   random_model(9, seed=4, floating_base=True, branching=0.6)],
                         ids=["panda", "puma560", "scara", "tree", "floating-tree"])
def test_pinocchio_reads_what_it_writes(model):
    """Another library reads the written file to the same dynamics: Pinocchio's rnea and mass
    matrix of ``write_urdf(model)`` equal robodyn's of the model (friction and armature, which
    Pinocchio's rnea leaves out, off; the armature is in Drake's extension, which Pinocchio
    skips)."""
    import pinocchio as pin

    pm, to_pin, pv = _pinocchio_reads(model)
    data = pm.createData()
    q, v, a = states(model, "pin-writer", size=3)
    expected = rd.rnea(model, q, v, a, friction=False, armature=False)
    M = rd.crba(model, q, armature=False)
    for k in range(3):
        assert_rel(pin.rnea(pm, data, to_pin(q[k]), v[k, pv], a[k, pv]), expected[k, pv], 1e-10, f"rnea {k}")
        Mp = pin.crba(pm, data, to_pin(q[k]))
        assert_rel(np.triu(Mp) + np.triu(Mp, 1).T, M[k][np.ix_(pv, pv)], 1e-10, f"crba {k}")


def test_drake_rotor_inertia(tmp_path):
    """Drake's armature extension, as Drake writes it (gear ratio, a prefix declared or not),
    and its errors."""
    arm = """<robot name="r"{decl}><link name="a"/><link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
    <transmission name="t"><type>SimpleTransmission</type><joint name="{joint}"/>
    <actuator name="m"><drake:rotor_inertia value="0.002"/><drake:gear_ratio value="10"/></actuator>
    </transmission></robot>"""
    for decl in (' xmlns:drake="http://drake.mit.edu"', ""):
        model = rd.load_urdf(arm.format(decl=decl, joint="j"))
        assert model.armature.tolist() == [pytest.approx(0.2)]  # 0.002 * 10^2
        assert_rel(rd.crba(model, np.zeros(1)), np.array([[0.2 + 0.1]]), 1e-15)
    with pytest.raises(rd.ModelError, match=r"drake:rotor_inertia of joints that do not exist: \['k'\]"):
        rd.load_urdf(arm.format(decl="", joint="k"))
    with pytest.raises(rd.ModelError, match="armature"):
        rd.load_urdf(arm.format(decl="", joint="j").replace('value="0.002"', 'value="-1"'))


def test_every_example_robot_written_loads_in_pinocchio():
    """Every example-robot-data URDF robodyn loads, written back: Pinocchio reads the file to
    robodyn's dynamics (rnea and the mass matrix at a random state, fixed base)."""
    import warnings

    import pinocchio as pin
    from conftest import example_robot_urdfs

    checked = 0
    for path in example_robot_urdfs():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rd.RobodynWarning)
            try:
                model = rd.load_urdf(path, mimic="independent")  # as Pinocchio reads the written file
            except rd.ModelError:
                continue  # refused files are checked in test_urdf.py
            if model.nv == 0:
                continue
            pm, to_pin, pv = _pinocchio_reads(model)
        data = pm.createData()
        q, v, a = (x[0] for x in states(model, "erd-writer", size=1))
        assert_rel(pin.rnea(pm, data, to_pin(q), v[pv], a[pv]), rd.rnea(model, q, v, a, friction=False,
                   armature=False)[pv], 1e-9, str(path))
        Mp = pin.crba(pm, data, to_pin(q))
        assert_rel(np.triu(Mp) + np.triu(Mp, 1).T, rd.crba(model, q, armature=False)[np.ix_(pv, pv)], 1e-9, str(path))
        checked += 1
    assert checked >= 50, checked


def test_friction_on_a_free_joint_is_reported_as_not_written():
    model = random_model(3, seed=6, floating_base=True)
    damped = model.replace(damping=np.r_[np.full(6, 0.5), np.zeros(model.nv - 6)])
    with pytest.warns(rd.RobodynWarning, match="damping and friction of the free joint 'root_joint'; not written"):
        rd.write_urdf(damped)
