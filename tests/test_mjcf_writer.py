"""MJCF writer (robodyn.write_mjcf): MuJoCo compiles what it writes to the same dynamics (mass
matrix, bias, inverse dynamics, site poses), for built-in robots, random trees of every joint
type and every MuJoCo model the loader reads (whose bodies with several joints come back as
one MuJoCo body); load_mjcf reads it back; what MJCF cannot hold is refused or reported."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

import robodyn as rd
from helpers import assert_rel, rng_for, states
from robodyn import joints as J
from robodyn.random import random_model
from test_mjcf import BOTH_REFUSE, CORPUS, REFUSED, compare_with_mujoco


def exact(model, site):
    return site


def round_trip(model) -> rd.Model:
    """``model`` written, compiled by MuJoCo and compared with it, and read back."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        text = rd.write_mjcf(model)
        compare_with_mujoco(model, mujoco.MjModel.from_xml_string(text), label=exact)
        back = rd.load_mjcf(text)
    assert (back.nq, back.nv) == (model.nq, model.nv)
    assert back.body_joint_names == model.body_joint_names
    q, v, a = states(model, "mjcf-writer", size=2)
    # 1e-11: a point mass comes back with principal inertias of 1e-12 of the largest (see write_mjcf)
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-11)
    assert_rel(rd.crba(back, q), rd.crba(model, q), 1e-11)
    for key in ("lower", "upper", "damping", "coulomb", "armature", "stiffness", "spring_reference"):
        np.testing.assert_array_equal(getattr(back, key), getattr(model, key), err_msg=key)
    return back


@pytest.mark.parametrize("name", [n for n in rd.models.names() if n != "puma560"])
def test_builtin_robots(name):
    round_trip(rd.models.load(name))


def test_a_massless_moving_body_is_refused():
    """Corke's Puma 560 gives link 1 an inertia but no mass: MuJoCo refuses such a body."""
    with pytest.raises(ValueError, match="body 'link1' moves without mass, which MuJoCo refuses"):
        rd.write_mjcf(rd.models.load("puma560"))


@pytest.mark.parametrize("seed, floating_base", [(0, False), (1, True), (4, False), (2, True)])
def test_random_trees_of_every_joint_type(seed, floating_base):
    model = random_model(7, seed=seed, floating_base=floating_base, branching=0.4,
                         joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL))
    rng = rng_for("mjcf-writer", seed)
    per_joint = np.concatenate([np.full(J.NV[t], rng.uniform(0.1, 1.0)) for t in model.joint_type])
    one = np.concatenate([np.full(J.NV[t], t in (J.REVOLUTE, J.PRISMATIC)) for t in model.joint_type])
    lower = np.where(one & (rng.random(model.nv) < 0.5), -rng.uniform(0.5, 2, model.nv), -np.inf)
    free = np.concatenate([np.full(J.NV[t], t == J.FREE) for t in model.joint_type])
    model = model.replace(damping=per_joint * ~free, armature=0.1 * per_joint * ~free, coulomb=0.5 * per_joint * ~free,
                          lower=lower, upper=-lower, stiffness=20 * per_joint * one, spring_reference=0.3 * one)
    round_trip(model)


def _moving_models() -> list[str]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return sorted(r for r in CORPUS if r not in REFUSED and r not in BOTH_REFUSE and rd.load_mjcf(CORPUS[r]).nv)


@pytest.mark.parametrize("rel", _moving_models())
def test_mujoco_models_come_back(rel):
    """Every model with moving bodies the loader reads: MuJoCo compiles the written file to the
    same dynamics, with as many moving bodies as the original (bodies with several joints, which
    the loader splits into chains, merged back into one)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        model = rd.load_mjcf(CORPUS[rel])
        text = rd.write_mjcf(model)
    back = round_trip(model)
    assert back.link_names == model.link_names
    original = mujoco.MjModel.from_xml_path(str(CORPUS[rel]))
    assert text.count("<body ") == np.sum(original.body_jntnum > 0)


def test_what_mjcf_cannot_hold():
    model = rd.models.load("panda")
    with pytest.warns(rd.RobodynWarning, match=r"MJCF cannot hold velocity limits \(not written\); effort limits"):
        rd.write_mjcf(model)
    with pytest.warns(rd.RobodynWarning, match=r"principal inertias below .* of bodies \['link1'\]: written raised"):
        rd.write_mjcf(rd.models.load("pendulum"))
    one_sided = model.replace(upper=np.full(model.nv, np.inf))
    with pytest.raises(ValueError, match="joint 'joint1' has a one-sided position limit"):
        rd.write_mjcf(one_sided)
    b = rd.ModelBuilder("placed")
    b.add_link("world")
    b.add_link("box", mass=1.0, inertia=np.eye(3) * 0.01)
    b.add_joint("free", "free", "world", "box", xyz=(0, 0, 1))
    with pytest.raises(ValueError, match="free joint 'free' has a placement in the world"):
        rd.write_mjcf(b.build())
    b = rd.ModelBuilder("massless base")
    b.add_link("world")
    b.add_link("base")
    b.add_link("arm", mass=1.0, com=(0.1, 0, 0), inertia=np.eye(3) * 0.01)
    b.add_joint("free", "free", "world", "base")
    b.add_joint("hinge", "revolute", "base", "arm")
    with pytest.raises(ValueError, match="body 'base' moves without mass"):  # a free body merges no joint
        rd.write_mjcf(b.build())
    ball = rd.ModelBuilder("ball")
    ball.add_link("world")
    ball.add_link("bob", mass=1.0, com=(0, 0, -1), inertia=np.eye(3) * 0.01)
    ball.add_joint("ball", "spherical", "world", "bob")
    m = ball.build()
    with pytest.raises(ValueError, match=r"joint 'ball' has damping \[0.1, 0.2, 0.3\] differing between its dofs"):
        rd.write_mjcf(m.replace(damping=[0.1, 0.2, 0.3]))


def test_written_file(tmp_path):
    path = tmp_path / "panda.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        text = rd.write_mjcf(rd.models.load("panda"), path)
    assert path.read_text() == text
    assert mujoco.MjModel.from_xml_path(str(path)).nv == 7
