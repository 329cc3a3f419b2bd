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
    model = rd.models.load(name).replace(armature=np.zeros(rd.models.load(name).nv))
    back = _reload(model)
    assert back.joint_names == model.joint_names and back.link_names == model.link_names
    q, v, a = states(model, "urdf", size=3)
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-12)
    assert_rel(back.inertial_parameters(), model.inertial_parameters(), 1e-12)
    for key in ("lower", "upper", "velocity_limit", "effort_limit", "damping", "coulomb"):
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
    """A file path; revolute joints without limits are continuous, prismatic ones have no <limit>."""
    model = random_model(4, seed=5)
    path = tmp_path / "robot.urdf"
    text = rd.write_urdf(model, path)
    assert path.read_text() == text
    assert text.count('type="continuous"') + text.count('type="prismatic"') == 4
    assert "<limit" not in text
    back = rd.load_urdf(path)
    q, v, a = states(model, "file")
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-12)


def test_what_urdf_cannot_hold():
    model = rd.models.load("puma560")  # has armature
    with pytest.warns(rd.RobodynWarning, match="armature"):
        rd.write_urdf(model)
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
