"""ModelBuilder: graph errors, body order, fixed-joint merging, physical checks, long chains."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
from conftest import small_tree_builder
from helpers import assert_rel
from robodyn import joints as J
from robodyn.builder import rpy_to_matrix
from robodyn.model import inertial_parameters_from

I3 = np.eye(3) * 0.01


def _builder(*links, source="arm.src"):
    b = rd.ModelBuilder("arm", source=source)
    for name in links:
        b.add_link(name, mass=1.0, inertia=I3)
    return b


# ----------------------------------------------------------------------------------------
# graph errors: each names the source and the offending element
# ----------------------------------------------------------------------------------------


def test_duplicate_link():
    b = _builder("a")
    with pytest.raises(rd.ModelError, match=r"arm.src: link 'a': duplicate link name 'a' \(first defined at arm.src: link 'a'\)"):
        b.add_link("a")


def test_unknown_joint_type():
    b = _builder("a", "b")
    with pytest.raises(rd.ModelError, match=r"arm.src: joint 'j': unknown joint type 'ball'"):
        b.add_joint("j", "ball", "a", "b")


def test_custom_where_is_used():
    b = _builder("a", "b")
    with pytest.raises(rd.ModelError, match=r"^file.urdf: <joint name='j'> \(line 7\): unknown joint type"):
        b.add_joint("j", "cardan", "a", "b", where="file.urdf: <joint name='j'> (line 7)")


@pytest.mark.parametrize("parent, child, what", [
    ("ghost", "b", "parent link 'ghost' does not exist"),
    ("a", "ghost", "child link 'ghost' does not exist"),
    ("a", "a", "joint connects link 'a' to itself"),
])
def test_joint_with_missing_or_same_links(parent, child, what):
    b = _builder("a", "b")
    b.add_joint("j", "revolute", parent, child)
    with pytest.raises(rd.ModelError, match=f"arm.src: joint 'j': {what}"):
        b.build()


def test_duplicate_joint():
    b = _builder("a", "b", "c")
    b.add_joint("j", "revolute", "a", "b")
    b.add_joint("j", "revolute", "b", "c")
    with pytest.raises(rd.ModelError, match="arm.src: joint 'j': duplicate joint name 'j'"):
        b.build()


def test_two_parents():
    b = _builder("a", "b", "c")
    b.add_joint("j1", "revolute", "a", "c")
    b.add_joint("j2", "revolute", "b", "c")
    with pytest.raises(rd.ModelError, match=r"arm.src: joint 'j2': link 'c' has two parents \(joints 'j1' and 'j2'\)"):
        b.build()


def test_several_roots():
    b = _builder("a", "b", "c")
    b.add_joint("j1", "revolute", "a", "b")
    with pytest.raises(rd.ModelError, match="several root links") as err:
        b.build()
    msg = str(err.value)
    assert "arm.src: link 'a'" in msg and "arm.src: link 'c'" in msg


def test_no_links():
    with pytest.raises(rd.ModelError, match="arm.src: no links"):
        _builder().build()


@pytest.mark.parametrize("with_root", [False, True])
def test_cycle(with_root):
    b = _builder("root", "a", "b", "c") if with_root else _builder("a", "b", "c")
    b.add_joint("ab", "revolute", "a", "b")
    b.add_joint("bc", "fixed", "b", "c")
    b.add_joint("ca", "revolute", "c", "a")
    with pytest.raises(rd.ModelError, match="cycle") as err:
        b.build()
    msg = str(err.value)
    for jname in ("ab", "bc", "ca"):
        assert f"arm.src: joint {jname!r}" in msg


def test_cycle_below_a_branch_names_only_the_cycle():
    b = _builder("root", "a", "b", "c", "tail")
    b.add_joint("ab", "revolute", "a", "b")
    b.add_joint("ba", "revolute", "b", "a")
    b.add_joint("btail", "revolute", "b", "tail")  # hangs from the cycle, not on it
    b.add_joint("rc", "revolute", "root", "c")
    with pytest.raises(rd.ModelError, match="cycle through links") as err:
        b.build()
    msg = str(err.value)
    assert "joint 'ab'" in msg and "joint 'ba'" in msg and "btail" not in msg and "'rc'" not in msg


def test_physical_argument():
    with pytest.raises(ValueError, match="physical must be 'error', 'warn' or 'repair'"):
        rd.ModelBuilder(physical="maybe")


def test_physical_repair_of_merged_bodies():
    """A body merged from links by fixed joints is judged and repaired as one: the warning
    names the body and its links; the model's other bodies are untouched and it checks them
    as physical="error" does."""
    def build(physical):
        b = rd.ModelBuilder("r", source="s", physical=physical)
        b.add_link("base")
        b.add_link("arm", mass=1.0, inertia=np.diag([0.1, 0.1, 0.5]))
        b.add_link("tip", mass=1e-3)
        b.add_link("hand", mass=1.0, com=(0.1, 0, 0), inertia=np.diag([0.01, 0.02, 0.025]))
        b.add_joint("j1", "revolute", "base", "arm", axis=(0, 0, 1))
        b.add_joint("f", "fixed", "arm", "tip", xyz=(0.5, 0, 0))
        b.add_joint("j2", "revolute", "arm", "hand", xyz=(1, 0, 0), axis=(0, 1, 0))
        return b.build()

    with pytest.raises(rd.ModelError, match="body 'arm' \\(links 'arm', 'tip' merged by fixed joints\\).*"
                                            "physical='repair' to repair it"):
        build("error")
    with pytest.warns(rd.RobodynWarning, match="s: body 'arm' \\(links 'arm', 'tip' merged by fixed joints\\): "
                                               "principal moments of inertia .* repaired to .*; it was: principal "
                                               "moments"):
        model = build("repair")
    assert model.physical == "error"
    m, c, I = rd.model.mass_com_inertia(model.theta[0])
    assert m == pytest.approx(1.001) and c == pytest.approx([0.5e-3 / 1.001, 0, 0])
    eig = np.linalg.eigvalsh(I)
    np.testing.assert_allclose(eig, eig.mean(), rtol=1e-13)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        np.testing.assert_array_equal(model.theta[1], build("warn").theta[1])
        assert_rel(eig.sum(), np.trace(rd.model.mass_com_inertia(build("warn").theta[0])[2]), 1e-13)


# ----------------------------------------------------------------------------------------
# link and joint input
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("kw, what", [
    (dict(mass=np.nan), "must be finite"),
    (dict(mass=1.0, com=(0, np.inf, 0)), "must be finite"),
    (dict(mass=1.0, inertia=np.full((3, 3), np.nan)), "must be finite"),
    (dict(mass=1.0, inertia=np.array([[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])), "not symmetric"),
    (dict(mass=-1.0), "negative mass"),
])
def test_bad_link(kw, what):
    """What no merge can repair is refused when the link is added."""
    b = rd.ModelBuilder(source="s")
    with pytest.raises(rd.ModelError, match=f"s: link 'x': .*{what}"):
        b.add_link("x", **kw)


@pytest.mark.parametrize("kw, what", [
    (dict(mass=0.0, inertia=I3), "zero mass with non-zero"),
    (dict(mass=1.0, inertia=np.diag([0.1, 0.1, 0.3])), "triangle inequality"),
    (dict(mass=1.0, inertia=np.diag([1.0, 1.0, -0.1])), "not positive semi-definite"),
])
def test_unphysical_body_refused_at_build(kw, what):
    """A moving body that is not a rigid body is refused, naming the body and the link."""
    b = rd.ModelBuilder(source="s")
    b.add_link("base")
    b.add_link("x", **kw)
    b.add_joint("j", "revolute", "base", "x")
    with pytest.raises(rd.ModelError, match=f"s: body 'x': .*{what}.*physical='warn'"):
        b.build()


def test_placeholder_links_merged_into_consistent_bodies_load():
    """As in ANYmal, HyQ, Go1: a massless base link with a tiny inertia welded to the trunk, and a
    massless foot with an inertia welded to a shank. Each merged body is consistent, so the
    model loads, with the placeholders' inertias included."""
    b = rd.ModelBuilder(source="s")
    b.add_link("base", mass=0.0, inertia=np.diag([0.0, 0.0, 3e-6]))
    b.add_link("trunk", mass=5.0, inertia=np.diag([0.1, 0.2, 0.25]))
    b.add_link("shank", mass=0.5, com=(0, 0, -0.1), inertia=np.diag([1e-3, 1e-3, 1e-4]))
    b.add_link("foot", mass=0.0, inertia=np.diag([1e-6, 1e-6, 1e-6]))
    b.add_link("world_marker", mass=0.0, inertia=I3)  # the root: welded to the world, never moves
    b.add_joint("b", "fixed", "base", "trunk")
    b.add_joint("knee", "revolute", "trunk", "shank")
    b.add_joint("f", "fixed", "shank", "foot", xyz=(0, 0, -0.2))
    b.add_joint("w", "fixed", "world_marker", "base")
    model = b.build()
    assert model.link_names == ("shank",)
    floating = b.build(floating_base=True)  # the root link moves now, merged with trunk and base
    assert floating.link_names == ("world_marker", "shank")
    np.testing.assert_allclose(floating.theta[0, 4:], [0.11, 0.0, 0.21, 0.0, 0.0, 0.260003])  # trunk + base + marker
    assert floating.theta[1, 9] == pytest.approx(1e-4 + 1e-6)


def test_merged_body_failure_names_every_link():
    b = rd.ModelBuilder(source="robot.urdf")
    b.add_link("base")
    b.add_link("thigh", mass=1.0, inertia=np.diag([0.01, 0.01, 0.01]))
    b.add_link("pad", mass=0.0, inertia=np.diag([0.0, 0.0, 1.0]))  # far too large to merge away
    b.add_joint("hip", "revolute", "base", "thigh")
    b.add_joint("p", "fixed", "thigh", "pad")
    with pytest.raises(rd.ModelError) as e:
        b.build()
    message = str(e.value)
    assert "robot.urdf: body 'thigh' (links 'thigh', 'pad' merged by fixed joints)" in message
    assert "triangle inequality" in message
    assert "'thigh': mass 1" in message and "'pad': mass 0" in message
    assert "zero mass with non-zero first moment or inertia" in message  # what the pad carries alone


@pytest.mark.parametrize("kw, what", [
    (dict(xyz=(0, np.nan, 0)), "origin is not finite"),
    (dict(rpy=(np.inf, 0, 0)), "origin is not finite"),
    (dict(axis=(0, 0, np.nan)), "axis is not finite"),
    (dict(axis=(0, 0, 0)), "joint axis is zero"),
    (dict(lower=1.0, upper=0.0), "lower limit 1.0 exceeds upper limit 0.0"),
    (dict(lower=np.nan), "lower is NaN"),
    (dict(velocity=-1.0), "velocity must be finite and >= 0"),
    (dict(effort=-1.0), "effort must be finite and >= 0"),
    (dict(damping=np.inf), "damping must be finite and >= 0"),
    (dict(friction=-0.1), "friction must be finite and >= 0"),
    (dict(armature=np.nan), "armature is NaN"),
])
def test_bad_joint(kw, what):
    b = _builder("a", "b", source="s")
    with pytest.raises(rd.ModelError, match=f"s: joint 'j': {what}"):
        b.add_joint("j", "revolute", "a", "b", **kw)


def test_fixed_joint_axis_is_not_checked():
    b = _builder("a", "b")
    b.add_joint("weld", "fixed", "a", "b", axis=(0, 0, 0))
    assert b.build().nbodies == 0


# ----------------------------------------------------------------------------------------
# body order and merging
# ----------------------------------------------------------------------------------------


def test_depth_first_order_with_children_in_insertion_order():
    b = _builder("r", "a", "a1", "a2", "b", "b1")
    b.add_joint("jb", "revolute", "r", "b")
    b.add_joint("ja2", "revolute", "a", "a2")
    b.add_joint("ja", "revolute", "r", "a")
    b.add_joint("jb1", "prismatic", "b", "b1")
    b.add_joint("ja1", "revolute", "a", "a1")
    model = b.build()
    assert model.link_names == ("b", "b1", "a", "a2", "a1")
    np.testing.assert_array_equal(model.parent, [-1, 0, -1, 2, 2])


def test_random_trees_have_parent_before_child():
    rng = np.random.default_rng(7)
    for _ in range(20):
        n = int(rng.integers(1, 40))
        parent_of = {i: int(rng.integers(0, i)) for i in range(1, n)}
        b = rd.ModelBuilder()
        for i in rng.permutation(n):
            b.add_link(f"l{i}", mass=1.0, inertia=I3)
        for i in rng.permutation(np.arange(1, n)):
            jtype = ("revolute", "prismatic", "fixed")[int(rng.integers(0, 3))]
            b.add_joint(f"j{i}", jtype, f"l{parent_of[i]}", f"l{i}", xyz=rng.normal(size=3), rpy=rng.normal(size=3),
                        axis=rng.normal(size=3))
        model = b.build(floating_base=bool(rng.integers(0, 2)))
        assert all(model.parent[i] < i for i in range(model.nbodies))
        # every link is a body or a frame, attached below its tree parent
        names = set(model.link_names) | set(model.frame_names)
        assert names == {f"l{i}" for i in range(n)}
        for i in range(1, n):
            child_body = model.body_index(f"l{i}")
            parent_body = model.frame_index(f"l{parent_of[i]}")[0]
            if f"l{i}" in model.link_names:
                assert model.parent[child_body] == parent_body
            else:
                assert child_body == parent_body


def test_fixed_merge_with_rotation_argument():
    R = Rotation.from_euler("xyz", [0.4, -0.3, 1.2]).as_matrix()
    p = np.array([0.1, 0.2, -0.3])
    c2, I2 = np.array([0.05, 0.0, 0.02]), np.diag([0.01, 0.02, 0.025])
    b = rd.ModelBuilder()
    b.add_link("base")
    b.add_link("arm", mass=1.0, com=(0, 0, 0.1), inertia=I3)
    b.add_link("tool", mass=0.3, com=c2, inertia=I2)
    b.add_joint("j", "revolute", "base", "arm")
    b.add_joint("weld", "fixed", "arm", "tool", xyz=p, rotation=R)
    model = b.build()
    expected = inertial_parameters_from(1.0, (0, 0, 0.1), I3) + inertial_parameters_from(0.3, p + R @ c2, R @ I2 @ R.T)
    np.testing.assert_allclose(model.theta[0], expected, rtol=1e-13, atol=1e-16)
    body, Rf, pf = model.frame_index("tool")
    assert body == 0
    np.testing.assert_allclose(Rf, R, atol=1e-15)
    np.testing.assert_allclose(pf, p, atol=1e-15)


def test_joint_placement_composes_through_fixed_joints():
    b = _builder("base", "mid", "arm")
    b.add_joint("weld", "fixed", "base", "mid", xyz=(1, 0, 0), rpy=(0, 0, np.pi / 2))
    b.add_joint("j", "revolute", "mid", "arm", xyz=(1, 0, 0))
    model = b.build()
    np.testing.assert_allclose(model.X_tree_p[0], [1, 1, 0], atol=1e-15)
    np.testing.assert_allclose(model.X_tree_R[0], rpy_to_matrix((0, 0, np.pi / 2)), atol=1e-15)


def test_rpy_to_matrix_is_extrinsic_xyz():
    rpy = (0.3, -1.1, 2.0)
    np.testing.assert_allclose(rpy_to_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-15)


def test_floating_base_from_builder():
    model = small_tree_builder().build(floating_base=True)
    assert model.body_joint_names[0] == "root_joint" and model.link_names[0] == "base"
    assert J.NAMES[model.joint_type[0]] == "free"
    assert (model.nq, model.nv) == (7 + 3, 6 + 3)
    np.testing.assert_array_equal(model.parent, [-1, 0, 1, 0])
    assert model.frame_index("base")[0] == 0  # the root link is now body 0, not the world


def test_continuous_joint_is_unbounded_revolute():
    b = _builder("a", "b")
    b.add_joint("j", "continuous", "a", "b", lower=-1, upper=1)
    model = b.build()
    assert J.NAMES[model.joint_type[0]] == "revolute"
    assert (model.lower[0], model.upper[0]) == (-np.inf, np.inf)


# ----------------------------------------------------------------------------------------
# long chains: no recursion anywhere
# ----------------------------------------------------------------------------------------


def test_long_chain_and_long_cycle():
    n = 5000
    b = rd.ModelBuilder()
    for i in range(n + 1):
        b.add_link(f"l{i}")
    for i in range(1, n + 1):
        b.add_joint(f"j{i}", "revolute", f"l{i - 1}", f"l{i}", axis=(0, 0, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = b.build()
    assert model.nv == n
    np.testing.assert_array_equal(model.parent, np.arange(-1, n - 1))

    b = rd.ModelBuilder()
    b.add_link("root")
    for i in range(n):
        b.add_link(f"c{i}")
    for i in range(n):
        b.add_joint(f"k{i}", "fixed", f"c{i}", f"c{(i + 1) % n}")
    with pytest.raises(rd.ModelError, match="cycle through links"):
        b.build()


def test_the_world_is_implicit():
    """A joint whose parent is "world" needs no add_link("world"): the root is the fixed,
    massless world, and the model equals the one with the root link added by hand."""
    def build(explicit):
        b = rd.ModelBuilder("arm")
        if explicit:
            b.add_link("world")
        b.add_link("link1", mass=1.0, com=(0.5, 0, 0), inertia=np.diag([0.01, 0.1, 0.1]))
        b.add_joint("j1", "revolute", "world", "link1", axis=(0, 0, 1))
        return b.build()

    implicit, explicit = build(False), build(True)
    assert implicit.frame_names == explicit.frame_names == ("world",)
    q = np.array([0.4])
    np.testing.assert_array_equal(rd.crba(implicit, q), rd.crba(explicit, q))
    b = rd.ModelBuilder("two roots")
    b.add_link("base")
    b.add_link("link1", mass=1.0, inertia=np.eye(3) * 0.1)
    b.add_joint("j1", "revolute", "world", "link1")
    with pytest.raises(rd.ModelError, match=r"several root links \['base', 'world'\]"):
        b.build()
    b = rd.ModelBuilder("typo")
    b.add_link("link1", mass=1.0, inertia=np.eye(3) * 0.1)
    b.add_joint("j1", "revolute", "wrold", "link1")
    with pytest.raises(rd.ModelError, match="parent link 'wrold' does not exist"):
        b.build()
