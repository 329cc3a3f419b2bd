"""Model: immutability, inertial parameters, validation of the constructor, repr, lookups."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from conftest import small_tree_builder
from robodyn import joints as J
from robodyn.model import Model, check_inertial_parameters, consistent_inertial_parameters, inertial_parameters_from


@pytest.fixture(scope="module")
def model() -> rd.Model:
    return small_tree_builder().build()


ARRAY_FIELDS = ("parent", "joint_type", "joint_axis", "X_tree_R", "X_tree_p", "theta", "idx_q", "idx_v",
                "lower", "upper", "velocity_limit", "effort_limit", "damping", "coulomb", "armature", "gravity",
                "frame_body", "frame_R", "frame_p")


def test_layout_of_small_tree(model):
    assert model.link_names == ("upper", "lower", "side")
    assert model.joint_names == model.body_joint_names == ("shoulder", "slide", "hip")
    assert [J.NAMES[t] for t in model.joint_type] == ["revolute", "prismatic", "revolute"]
    np.testing.assert_array_equal(model.parent, [-1, 0, -1])
    assert (model.nq, model.nv, model.nbodies) == (3, 3, 3)
    assert model.frame_names == ("base", "sensor") and not model.floating_base
    assert model.total_mass == pytest.approx(3.6, rel=1e-15)


@pytest.mark.parametrize("field", ARRAY_FIELDS)
def test_arrays_are_read_only(model, field):
    a = getattr(model, field)
    assert isinstance(a, np.ndarray) and not a.flags.writeable
    if a.size:
        with pytest.raises(ValueError):
            a.reshape(-1)[0] = 1
    with pytest.raises(ValueError):
        a.flags.writeable = True


def test_attributes_cannot_be_set_or_deleted(model):
    for name, value in (("nq", 4), ("parent", np.zeros(3)), ("joint_names", ("a",)), ("new_field", 1)):
        with pytest.raises(AttributeError, match="immutable"):
            setattr(model, name, value)
    with pytest.raises(AttributeError, match="immutable"):
        del model.theta
    assert model.nq == 3 and model.theta.shape == (3, 10)
    assert isinstance(model.link_names, tuple) and isinstance(model.joint_names, tuple)


def test_inertial_parameters_round_trip(model):
    theta = model.inertial_parameters()
    assert theta.shape == (10 * model.nbodies,)
    np.testing.assert_array_equal(theta, model.theta.reshape(-1))
    theta[0] = 123.0  # a copy: the model does not change
    assert model.theta[0, 0] != 123.0
    same = model.with_inertial_parameters(model.inertial_parameters())
    assert same is not model
    for field in ARRAY_FIELDS:
        np.testing.assert_array_equal(getattr(same, field), getattr(model, field))
    assert same.link_names == model.link_names and same.frame_names == model.frame_names


def test_with_inertial_parameters_changes_only_inertia(model):
    scaled = model.with_inertial_parameters(2.0 * model.inertial_parameters())
    assert scaled.total_mass == pytest.approx(2.0 * model.total_mass)
    np.testing.assert_array_equal(scaled.theta, 2.0 * model.theta)
    np.testing.assert_array_equal(scaled.X_tree_p, model.X_tree_p)
    assert model.total_mass == pytest.approx(3.6)  # the original is untouched


@pytest.mark.parametrize("shape", [(29,), (31,), (3, 10), (10, 3), ()])
def test_with_inertial_parameters_wrong_shape(model, shape):
    with pytest.raises(ValueError) as err:
        model.with_inertial_parameters(np.ones(shape))
    msg = str(err.value)
    assert not isinstance(err.value, rd.ModelError)
    assert "theta" in msg and "(30,)" in msg and str(shape) in msg


def _theta_with(model, body, **changes):
    theta = model.theta.copy()
    names = dict(m=0, hx=1, hy=2, hz=3, ixx=4, ixy=5, iyy=6, ixz=7, iyz=8, izz=9)
    for k, v in changes.items():
        theta[body, names[k]] = v
    return theta.reshape(-1)


@pytest.mark.parametrize("changes, what", [
    (dict(m=-1.0), "negative mass"),
    (dict(m=np.nan), "not finite"),
    (dict(izz=np.inf), "not finite"),
    (dict(ixy=1.0), "positive semi-definite"),
    (dict(izz=10.0), "triangle inequality"),
])
def test_with_inertial_parameters_refuses_unphysical(model, changes, what):
    with pytest.raises(rd.ModelError, match=what) as err:
        model.with_inertial_parameters(_theta_with(model, 1, **changes))
    assert "body 1 ('lower')" in str(err.value)


def test_zero_mass_with_first_moment_refused(model):
    theta = _theta_with(model, 2, m=0.0, ixx=0.0, iyy=0.0, izz=0.0)
    with pytest.raises(rd.ModelError, match="zero mass"):
        model.with_inertial_parameters(theta)


def test_physical_warn_model_keeps_unphysical_but_not_non_finite():
    model = small_tree_builder(physical="warn").build()
    kept = model.with_inertial_parameters(_theta_with(model, 1, izz=10.0))
    assert kept.theta[1, 9] == 10.0
    for bad in (dict(m=-1.0), dict(m=np.nan)):
        with pytest.raises(rd.ModelError, match="finite with mass >= 0"):
            model.with_inertial_parameters(_theta_with(model, 1, **bad))


def test_repr_shows_joint_table(model):
    text = repr(model)
    assert "nq=3" in text and "nv=3" in text and "3 bodies" in text and "fixed base" in text
    lines = text.splitlines()
    header = lines[1]
    for col in ("body", "joint", "type", "parent", "axis", "mass"):
        assert col in header
    rows = lines[2:5]
    for row, body, joint, jtype, parent in zip(rows, model.link_names, model.joint_names,
                                               ("revolute", "prismatic", "revolute"), ("world", "upper", "world")):
        assert row.split()[:5] == [str(rows.index(row)), body, joint, jtype, parent]
    assert "frames: base, sensor" in text


def test_frame_and_body_lookup(model):
    assert model.frame_index("upper")[0] == 0
    body, R, p = model.frame_index("sensor")
    assert body == 0
    np.testing.assert_array_equal(p, [0.05, 0, 0.4])
    assert model.frame_index("base")[0] == -1
    assert model.body_index("sensor") == 0 and model.body_index(-1) == 2 and model.body_index(1) == 1
    with pytest.raises(ValueError, match="unknown link or frame 'nope'"):
        model.frame_index("nope")
    with pytest.raises(TypeError):
        model.frame_index(3)
    with pytest.raises(ValueError, match="out of range"):
        model.body_index(3)


def test_replace(model):
    moon = model.replace(gravity=(0, 0, -1.62))
    np.testing.assert_array_equal(moon.gravity, [0, 0, -1.62])
    np.testing.assert_array_equal(model.gravity, [0, 0, -9.81])
    with pytest.raises(TypeError, match="unknown model fields"):
        model.replace(mass=3)


# ----------------------------------------------------------------------------------------
# constructor validation
# ----------------------------------------------------------------------------------------


def _kwargs(parent=(-1, 0), joint_type=(J.REVOLUTE, J.PRISMATIC), **changes):
    nb = len(parent)
    kw = dict(
        parent=parent, joint_type=joint_type, joint_axis=np.tile([0.0, 0.0, 1.0], (nb, 1)),
        X_tree_R=np.tile(np.eye(3), (nb, 1, 1)), X_tree_p=np.zeros((nb, 3)),
        theta=np.tile(inertial_parameters_from(1.0, (0, 0, 0.1), np.eye(3) * 0.01), (nb, 1)),
        link_names=[f"l{i}" for i in range(nb)], body_joint_names=[f"j{i}" for i in range(nb)],
    )
    kw.update(changes)
    return kw


def test_constructor_accepts_valid_input():
    m = Model(**_kwargs())
    assert (m.nq, m.nv) == (2, 2)
    np.testing.assert_array_equal(m.idx_q, [0, 1])


@pytest.mark.parametrize("parent", [(0, -1), (-1, 1), (-1, 2), (-2, 0)])
def test_parent_must_precede_child(parent):
    with pytest.raises(rd.ModelError, match="parent index"):
        Model(**_kwargs(parent=parent))


def test_loaded_models_have_parent_before_child(model):
    assert all(model.parent[i] < i for i in range(model.nbodies))


@pytest.mark.parametrize("seed", range(6))
def test_kernel_table_holds_the_end_of_each_subtree(seed):
    """``ints[i, SUBTREE_END]`` bounds the dofs of body ``i``'s subtree: every one of them lies in
    ``idx_v[i] <= k < end``, and ``end`` is the end of one of them (so, numbered depth first
    as the builder numbers them, the range holds exactly the subtree's dofs)."""
    from robodyn.layout import NDOF, SUBTREE_END
    from robodyn.random import random_model

    depth_first = small_tree_builder().build()
    for m in (random_model(9, seed=seed, floating_base=bool(seed % 2), branching=0.5), depth_first):
        ints = m.kernel.ints
        for i in range(m.nbodies):
            subtree = [j for j in range(m.nbodies) if i in _ancestors_and_self(m.parent, j)]
            ends = [m.idx_v[j] + ints[j, NDOF] for j in subtree]
            assert all(m.idx_v[j] >= m.idx_v[i] for j in subtree)
            assert ints[i, SUBTREE_END] == max(ends), (m.name, i)
            if m is depth_first:
                assert ints[i, SUBTREE_END] - m.idx_v[i] == sum(ints[j, NDOF] for j in subtree)


def _ancestors_and_self(parent, j):
    chain = [j]
    while parent[chain[-1]] >= 0:
        chain.append(parent[chain[-1]])
    return chain


@pytest.mark.parametrize("changes, what", [
    (dict(joint_type=(J.REVOLUTE, 7)), "unknown joint type code"),
    (dict(joint_type=(J.REVOLUTE, J.FREE)), "free joint must attach to the world"),
    (dict(joint_type=(J.REVOLUTE,)), "joint_type must have shape"),
    (dict(joint_axis=np.zeros((2, 3))), "joint axis is zero"),
    (dict(joint_axis=np.full((2, 3), np.nan)), "joint_axis is not finite"),
    (dict(X_tree_p=np.array([[0, 0, np.inf], [0, 0, 0]])), "X_tree_p is not finite"),
    (dict(X_tree_R=np.tile(2 * np.eye(3), (2, 1, 1))), "not a rotation matrix"),
    (dict(X_tree_R=np.tile(np.diag([1.0, 1.0, -1.0]), (2, 1, 1))), "not a rotation matrix"),
    (dict(theta=np.zeros((2, 9))), "theta must have shape"),
    (dict(link_names=["a"]), "need 2 entries"),
    (dict(link_names=["a", "a"]), "duplicate link or frame names"),
    (dict(body_joint_names=["j", "j"]), "duplicate joint names"),
    (dict(frame_names=["l0"], frame_body=[0], frame_R=[np.eye(3)], frame_p=[np.zeros(3)]), "duplicate"),
    (dict(frame_names=["f"], frame_body=[2], frame_R=[np.eye(3)], frame_p=[np.zeros(3)]), "frame_body"),
    (dict(lower=[0.0, 1.0], upper=[1.0, 0.0]), "lower <= upper"),
    (dict(lower=[np.nan, 0.0]), "lower <= upper"),
    (dict(damping=[-1.0, 0.0]), "damping must be non-negative"),
    (dict(coulomb=[np.inf, 0.0]), "coulomb must be finite"),
    (dict(velocity_limit=[-1.0, 1.0]), "velocity_limit"),
    (dict(gravity=(0, 0, np.nan)), "gravity is not finite"),
    (dict(coulomb_smoothing=-1.0), "coulomb_smoothing"),
])
def test_constructor_refuses(changes, what):
    with pytest.raises(rd.ModelError, match=what):
        Model(**_kwargs(**changes))


def test_constructor_physical_argument():
    with pytest.raises(ValueError, match="physical must be"):
        Model(**_kwargs(physical="ignore"))


def test_constructor_normalises_axis_without_touching_the_input():
    axis = np.array([[0, 0, 3.0], [0, 4.0, 0]])
    m = Model(**_kwargs(joint_axis=axis))
    np.testing.assert_array_equal(m.joint_axis, [[0, 0, 1], [0, 1, 0]])
    np.testing.assert_array_equal(axis, [[0, 0, 3.0], [0, 4.0, 0]])


def test_free_joint_limits_are_infinite():
    m = Model(**_kwargs(joint_type=(J.FREE, J.REVOLUTE), lower=np.zeros(7), upper=np.ones(7)))
    assert m.floating_base and (m.nq, m.nv) == (8, 7)
    assert np.all(np.isinf(m.lower[:6])) and (m.lower[6], m.upper[6]) == (0.0, 1.0)


def test_empty_model():
    m = Model(**_kwargs(parent=(), joint_type=()))
    assert (m.nq, m.nv, m.nbodies, m.total_mass) == (0, 0, 0, 0.0)
    assert m.inertial_parameters().shape == (0,)


# ----------------------------------------------------------------------------------------
# physical consistency of one body
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("Ic", [
    np.zeros((3, 3)),                # point mass
    np.diag([0.0, 1.0, 1.0]),        # thin rod: I1 + I2 = I3 exactly
    np.diag([1.0, 1.0, 2.0]),        # flat plate: equality again
    np.diag([1.0, 2.0, 2.5]),
])
def test_physical_bodies_pass(Ic):
    check_inertial_parameters(inertial_parameters_from(3.0, (0.1, -0.2, 0.3), Ic), "body")


@pytest.mark.parametrize("Ic, what", [
    (np.diag([1.0, 1.0, 2.0 + 1e-3]), "triangle inequality"),
    (np.diag([-1e-3, 1.0, 1.0]), "positive semi-definite"),
])
def test_unphysical_bodies_fail(Ic, what):
    with pytest.raises(rd.ModelError, match=f"body: .*{what}"):
        check_inertial_parameters(inertial_parameters_from(3.0, (0.1, -0.2, 0.3), Ic), "body")


def test_inertial_parameters_from_parallel_axis():
    theta = inertial_parameters_from(2.0, (1.0, 0.0, 0.0), np.diag([0.1, 0.2, 0.3]))
    np.testing.assert_allclose(theta, [2.0, 2.0, 0.0, 0.0, 0.1, 0.0, 2.2, 0.0, 0.0, 2.3])


def test_vectorised_inertia_check_agrees_with_the_scalar_one():
    """``consistent_inertial_parameters`` (every body at once, a filter before the per-body
    messages) accepts exactly what ``check_inertial_parameters`` accepts, on bodies around every
    boundary: massless, negative mass, non-finite, not PSD, triangle inequality just met or not."""
    rng = np.random.default_rng(7)
    bodies = []
    for _ in range(400):
        m = rng.choice([0.0, -0.5, 1e-9, 2.0])
        d = rng.uniform(0.0, 1.0, 3)
        d[2] = d[0] + d[1] + rng.choice([-1e-3, -1e-9, 0.0, 1e-9, 1e-3])  # around I1 + I2 = I3
        d[rng.integers(3)] *= rng.choice([1.0, 1.0, -1e-3])  # sometimes not PSD
        R = np.linalg.qr(rng.standard_normal((3, 3)))[0]
        theta = inertial_parameters_from(max(m, 0.0), rng.uniform(-1, 1, 3), R @ np.diag(d) @ R.T)
        theta[0] = m
        if rng.random() < 0.05:
            theta[rng.integers(10)] = rng.choice([np.nan, np.inf])
        if m == 0 and rng.random() < 0.5:
            theta[1:] = 0.0
        bodies.append(theta)
    mask = consistent_inertial_parameters(np.array(bodies))
    for theta, ok in zip(bodies, mask):
        try:
            check_inertial_parameters(theta, "body")
            scalar = True
        except rd.ModelError:
            scalar = False
        assert ok == scalar, theta
    assert 50 < mask.sum() < 350  # both kinds occur


def test_rigid_strips_friction_and_armature():
    model = rd.models.load("puma560")
    assert np.any(model.damping) and np.any(model.armature)
    rigid = model.rigid()
    assert not (np.any(rigid.damping) or np.any(rigid.coulomb) or np.any(rigid.armature))
    np.testing.assert_array_equal(rigid.theta, model.theta)
    q, v, a = np.full(6, 0.3), np.full(6, -0.5), np.full(6, 0.2)
    np.testing.assert_array_equal(rd.rnea(rigid, q, v, a), rd.rnea(model, q, v, a, friction=False, armature=False))
