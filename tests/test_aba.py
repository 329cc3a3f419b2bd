"""Forward dynamics (robodyn.aba): the inverse of rnea with external wrenches, friction and
armature, agreement with the mass matrix, singular models, batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, assert_rel, check_batch, check_input_validation, input_checks,
                     massless_leaf_model, random_model, random_models, rng_for, states, with_friction_and_armature)


@random_models
def test_inverse_of_rnea(model):
    q, v, a = states(model)
    assert_rel(rd.aba(model, q, v, rd.rnea(model, q, v, a)), a, 1e-9)


@random_models
@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_inverse_of_rnea_with_external_wrenches(model, frame):
    q, v, a = states(model, frame)
    f_ext = rng_for(model.name, frame).standard_normal((model.nbodies, 6))
    tau = rd.rnea(model, q, v, a, f_ext, frame=frame)
    assert_rel(rd.aba(model, q, v, tau, f_ext, frame=frame), a, 1e-9)


@random_models
@pytest.mark.parametrize("smoothing", [0.0, 0.05])
@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_inverse_of_rnea_with_friction_armature_and_wrenches(model, smoothing, frame):
    m = with_friction_and_armature(model, rng_for(model.name, smoothing), smoothing)
    q, v, a = states(m, smoothing, frame)
    f_ext = rng_for(model.name, "f", frame).standard_normal((model.nbodies, 6))
    for kw in ({}, {"friction": False}, {"armature": False}, {"friction": False, "armature": False}):
        tau = rd.rnea(m, q, v, a, f_ext, frame=frame, **kw)
        assert_rel(rd.aba(m, q, v, tau, f_ext, frame=frame, **kw), a, 1e-9, str(kw))


@random_models
def test_solves_the_equation_of_motion(model):
    """aba(q, v, tau) == M^-1 (tau - nonlinear_effects), with (M + armature) when set."""
    q, v, tau = states(model, "eom")
    expected = np.linalg.solve(rd.crba(model, q), tau - rd.nonlinear_effects(model, q, v))
    assert_rel(rd.aba(model, q, v, tau), expected, 1e-9)
    m = model.replace(armature=rng_for(model.name).uniform(0.1, 1, model.nv))
    expected = np.linalg.solve(rd.crba(m, q), tau - rd.nonlinear_effects(m, q, v))
    assert_rel(rd.aba(m, q, v, tau), expected, 1e-9)
    assert_rel(rd.crba(m, q), rd.crba(model, q) + np.diag(m.armature), 1e-12)


@pytest.mark.parametrize("floating_base", [False, True])
def test_massless_leaf_is_singular(floating_base):
    model = massless_leaf_model(floating_base)
    q, v, tau = states(model)
    with pytest.raises(ValueError, match=r"body \d+ \('finger', joint 'knuckle'\) is singular"):
        rd.aba(model, q, v, tau)
    with pytest.raises(ValueError, match="'finger'"):
        rd.aba(model, np.stack([q, q]), v, tau)  # batch path
    # armature on the massless joint makes it regular again
    assert model.joint_names[-1] == "knuckle"
    arm = model.replace(armature=np.where(np.arange(model.nv) == model.nv - 1, 0.01, 0.0))
    a = rd.aba(arm, q, v, tau)
    assert_rel(rd.rnea(arm, q, v, a), tau, 1e-9)


def test_point_mass_on_the_axis_is_singular():
    """A leaf whose only mass sits on its joint axis has no inertia about it."""
    b = rd.ModelBuilder("bead")
    b.add_link("base")
    b.add_link("bead", mass=1.0, com=(0, 0, 0.3))
    b.add_joint("spin", "revolute", "base", "bead", axis=(0, 0, 1))
    model = b.build()
    with pytest.raises(ValueError, match=r"body 0 \('bead', joint 'spin'\) is singular"):
        rd.aba(model, [0.2], [0.1], [0.0])


def test_batch():
    check_batch(rd.aba, random_model(7, seed=21, floating_base=True), ("q", "v", "tau"))
    check_batch(rd.aba, random_model(4, seed=22), ("q", "v", "tau"))


@input_checks
def test_bad_input(aspect):
    check_input_validation(rd.aba, ("q", "v", "tau"), aspect)
