"""Terms of the equation of motion (robodyn.gravity, nonlinear_effects, generalized_momentum):
against rnea and crba, the two-link planar arm's gravity vector, batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (PLANAR_2R, assert_rel, check_batch, check_input_validation, input_checks, planar_2r,
                     planar_2r_terms, random_model, random_models, rng_for, states,
                     with_friction_and_armature)


@random_models
def test_gravity_is_rnea_at_rest(model):
    m = with_friction_and_armature(model, rng_for(model.name))
    q, _, _ = states(m)
    z = np.zeros(m.nv)
    assert_rel(rd.gravity(m, q), rd.rnea(m, q, z, z), 1e-12)
    assert_rel(rd.gravity(m, q), rd.gravity(model, q), 1e-12)


@random_models
def test_nonlinear_effects_is_rnea_without_acceleration(model):
    m = with_friction_and_armature(model, rng_for(model.name))
    q, v, _ = states(m)
    assert_rel(rd.nonlinear_effects(m, q, v), rd.rnea(m, q, v, np.zeros(m.nv), friction=False), 1e-12)
    assert_rel(rd.nonlinear_effects(m, q, v), rd.rnea(model, q, v, np.zeros(m.nv)), 1e-12)


@random_models
def test_generalized_momentum_is_mass_matrix_times_v(model):
    q, v, _ = states(model)
    assert_rel(rd.generalized_momentum(model, q, v), rd.crba(model, q) @ v, 1e-9)
    m = with_friction_and_armature(model, rng_for(model.name))
    assert_rel(rd.generalized_momentum(m, q, v), rd.crba(m, q) @ v, 1e-9)
    assert_rel(rd.generalized_momentum(m, q, v, armature=False), rd.crba(model, q) @ v, 1e-9)


@random_models
def test_equation_of_motion(model):
    """rnea == M a + nonlinear_effects, nonlinear_effects == C v + g."""
    q, v, a = states(model)
    assert_rel(rd.rnea(model, q, v, a), rd.crba(model, q) @ a + rd.nonlinear_effects(model, q, v), 1e-9)
    assert_rel(rd.nonlinear_effects(model, q, v), rd.coriolis_matrix(model, q, v) @ v + rd.gravity(model, q), 1e-9)


@pytest.mark.parametrize("params", [PLANAR_2R, dict(m1=1.0, m2=4.0, l1=0.3, l2=1.2)], ids=["arm1", "arm2"])
def test_planar_2r_closed_form(params):
    """g = [(m1 r1 + m2 l1) g c1 + m2 r2 g c12, m2 r2 g c12]; nonlinear effects C qd + g."""
    model = planar_2r(**params)
    for q, qd in rng_for("2r-g", tuple(params.values())).uniform(-3, 3, (6, 2, 2)):
        M, C, g = planar_2r_terms(q, qd, **params)
        assert_rel(rd.gravity(model, q), g, 1e-12, f"q={q}")
        assert_rel(rd.nonlinear_effects(model, q, qd), C @ qd + g, 1e-12, f"q={q}, qd={qd}")
        assert_rel(rd.generalized_momentum(model, q, qd), M @ qd, 1e-12)


FUNCTIONS = [(rd.gravity, ("q",)), (rd.nonlinear_effects, ("q", "v")), (rd.generalized_momentum, ("q", "v"))]
FUNCTION_IDS = ["gravity", "nonlinear_effects", "generalized_momentum"]


@pytest.mark.parametrize("fn, names", FUNCTIONS, ids=FUNCTION_IDS)
def test_batch(fn, names):
    for model in (random_model(8, seed=81, floating_base=True), random_model(4, seed=82)):
        check_batch(fn, model, names)


@pytest.mark.parametrize("fn, names", FUNCTIONS, ids=FUNCTION_IDS)
@input_checks
def test_bad_input(fn, names, aspect):
    check_input_validation(fn, names, aspect)
