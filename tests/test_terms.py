"""Terms of the equation of motion (robodyn.gravity, nonlinear_effects, generalized_momentum).

gravity and nonlinear_effects run the RNEA kernel itself (at v = a = 0, and at a = 0): the tests
named ``..._is_wired_to_rnea...`` only check that wiring (options passed on, friction and
armature left out). The checks of their values are independent: the equation of motion with
crba and coriolis_matrix (other kernels), the two-link planar arm in closed form here, and
Pinocchio's gravity and nonlinear effects in test_pinocchio.py. Also batches and bad input; their
derivatives (gravity_derivatives, ...) against Richardson differences, batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (FD_TOL, PLANAR_2R, assert_rel, check_batch, check_input_validation, input_checks, planar_2r,
                     planar_2r_terms, random_model, random_models, richardson, rng_for, states, tangent_differences,
                     with_friction_and_armature)


@random_models
def test_gravity_is_wired_to_rnea_at_rest(model):
    """Wiring: gravity(q) is the RNEA kernel at v = a = 0, without friction or armature."""
    m = with_friction_and_armature(model, rng_for(model.name))
    q, _, _ = states(m)
    z = np.zeros(m.nv)
    assert_rel(rd.gravity(m, q), rd.rnea(m, q, z, z), 1e-12)
    assert_rel(rd.gravity(m, q), rd.gravity(model, q), 1e-12)


@random_models
def test_nonlinear_effects_is_wired_to_rnea_without_acceleration(model):
    """Wiring: nonlinear_effects(q, v) is the RNEA kernel at a = 0, without friction or armature."""
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
    """rnea == M a + nonlinear_effects, nonlinear_effects == C v + g (crba and coriolis_matrix
    run kernels of their own)."""
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


@random_models
def test_derivatives_of_the_terms_are_their_differences(model):
    m = with_friction_and_armature(model, rng_for(model.name, "terms"), 0.2)  # the terms leave friction out
    q, v, _ = states(model, "terms")
    dg = rd.gravity_derivatives(m, q)
    assert_rel(dg, richardson(lambda d: rd.gravity(m, rd.integrate(m, q, d)), m.nv), FD_TOL, "dg/dq")
    nq, nv = rd.nonlinear_effects_derivatives(m, q, v)
    fd_q, fd_v = tangent_differences(lambda m_, q_, v_, _: rd.nonlinear_effects(m_, q_, v_), m, q, v, None)
    assert_rel(nq, fd_q, FD_TOL, "d nle/dq")
    assert_rel(nv, fd_v, FD_TOL, "d nle/dv")
    for armature in (True, False):
        pq, M = rd.generalized_momentum_derivatives(m, q, v, armature=armature)
        fd_q, fd_v = tangent_differences(
            lambda m_, q_, v_, _: rd.generalized_momentum(m_, q_, v_, armature=armature), m, q, v, None)
        assert_rel(pq, fd_q, FD_TOL, "d(M v)/dq")
        assert_rel(M, fd_v, FD_TOL, "d(M v)/dv")
        assert_rel(M, rd.crba(m, q, armature=armature), 1e-12)


def test_derivatives_of_the_terms_batch_and_bad_input():
    model = random_model(5, seed=34, floating_base=True)
    Q, V, _ = states(model, "terms-batch", size=(2, 3))
    for fun, args in ((rd.gravity_derivatives, (Q,)), (rd.nonlinear_effects_derivatives, (Q, V)),
                      (rd.generalized_momentum_derivatives, (Q, V))):
        out = fun(model, *args)
        for i in np.ndindex(2, 3):
            one = fun(model, *(x[i] for x in args))
            for x, y in zip(out if isinstance(out, tuple) else (out,), one if isinstance(one, tuple) else (one,)):
                assert x.shape == (2, 3, model.nv, model.nv)
                assert_rel(x[i], y, 1e-12)
        with pytest.raises(ValueError, match=r"q contains NaN or Inf"):
            fun(model, np.full(model.nq, np.nan), *args[1:])
        with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\)"):
            fun(model, np.zeros(model.nq + 1), *args[1:])
