"""Mass matrix (robodyn.crba): columns against rnea, symmetry and definiteness, armature,
invariance to the base pose, the two-link planar arm in closed form, batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (PLANAR_2R, assert_rel, check_batch, check_input_validation, input_checks, planar_2r,
                     planar_2r_terms, random_model, random_models, rng_for, states, unit,
                     with_friction_and_armature)


@random_models
def test_columns_are_rnea_of_unit_accelerations(model):
    """Column j == rnea(q, 0, e_j, friction=False) - gravity(q), also with friction and armature set."""
    m = with_friction_and_armature(model, rng_for(model.name))
    q, v, _ = states(m)
    M = rd.crba(m, q)
    g = rd.gravity(m, q)
    z = np.zeros(m.nv)
    for j in range(m.nv):
        assert_rel(M[:, j], rd.rnea(m, q, z, unit(m.nv, j), friction=False) - g, 1e-9, f"column {j}")
    # the same with all unit accelerations in one batch call, and with a velocity (friction off)
    E = np.eye(m.nv)
    assert_rel(M, (rd.rnea(m, q, v, E, friction=False) - rd.nonlinear_effects(m, q, v)).T, 1e-9)


@random_models
def test_symmetric_positive_definite(model):
    q, _, _ = states(model)
    M = rd.crba(model, q)
    assert np.array_equal(M, M.T)
    assert np.linalg.eigvalsh(M).min() > 0


@random_models
def test_armature_on_the_diagonal(model):
    arm = rng_for(model.name).uniform(0.1, 1.0, model.nv)
    m = model.replace(armature=arm)
    q, _, _ = states(model)
    assert_rel(rd.crba(m, q), rd.crba(model, q) + np.diag(arm), 1e-12)
    assert_rel(rd.crba(m, q, armature=False), rd.crba(model, q), 1e-12)


@random_models
def test_independent_of_the_base_pose(model):
    """M depends on the joints only: a floating base's position and orientation do not enter
    (velocities are in the base frame); for a fixed base, gravity does not enter."""
    q, _, _ = states(model)
    q2, _, _ = states(model, "other")
    if model.floating_base:
        q2[7:] = q[7:]
        assert_rel(rd.crba(model, q2), rd.crba(model, q), 1e-9)
    assert_rel(rd.crba(model.replace(gravity=(1.0, 2.0, 3.0)), q), rd.crba(model, q), 1e-12)


@pytest.mark.parametrize("params", [PLANAR_2R, dict(m1=1.0, m2=4.0, l1=0.3, l2=1.2)], ids=["arm1", "arm2"])
def test_planar_2r_closed_form(params):
    """Spong's M = [[alpha + 2 beta c2, delta + beta c2], [delta + beta c2, delta]]."""
    model = planar_2r(**params)
    for q in rng_for("2r", tuple(params.values())).uniform(-np.pi, np.pi, (6, 2)):
        M, _, _ = planar_2r_terms(q, np.zeros(2), **params)
        assert_rel(rd.crba(model, q), M, 1e-12, f"q={q}")


def test_batch():
    check_batch(rd.crba, random_model(8, seed=31, floating_base=True), ("q",))
    check_batch(rd.crba, random_model(3, seed=32), ("q",))


@input_checks
def test_bad_input(aspect):
    check_input_validation(rd.crba, ("q",), aspect)
