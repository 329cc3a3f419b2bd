"""Coriolis matrix and Christoffel symbols (robodyn.coriolis_matrix, christoffel_symbols):
Mdot = C + C^T by finite differences, C v against the RNEA, Christoffel symbols from the
derivatives of M (robodyn's and Pinocchio's, fixed base), Christoffel symbols and C against
Pinocchio's Coriolis matrix and nonlinear effects on floating-base robots, the two-link planar
arm in closed form, batches and bad input."""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import (FD_TOL, PLANAR_2R, assert_rel, check_batch, check_input_validation, input_checks,
                     columns_by_differences, directional_derivative, fixed_base_models, planar_2r,
                     planar_2r_terms, random_model, random_models, richardson, rng_for, states)
from urdf_subset import load_pair


@random_models
def test_mass_matrix_derivative_is_c_plus_c_transpose(model):
    """dM/dt along the motion (quaternion manifold for a floating base) == C + C^T, so
    Mdot - 2C is skew-symmetric."""
    q, v, _ = states(model)
    Mdot = directional_derivative(lambda x: rd.crba(model, x), model, q, v)
    C = rd.coriolis_matrix(model, q, v)
    assert_rel(C + C.T, Mdot, 1e-6)
    S = Mdot - 2 * C
    assert_rel(S + S.T, np.zeros_like(S), 1e-6)


@random_models
def test_c_times_v_is_the_velocity_product_term(model):
    q, v, _ = states(model)
    assert_rel(rd.coriolis_matrix(model, q, v) @ v, rd.nonlinear_effects(model, q, v) - rd.gravity(model, q), 1e-9)


@random_models
def test_linear_in_v(model):
    q, v, w = states(model)
    C = functools.partial(rd.coriolis_matrix, model, q)
    assert_rel(C(2.0 * v - 3.0 * w), 2.0 * C(v) - 3.0 * C(w), 1e-9)
    assert_rel(C(np.zeros(model.nv)), np.zeros((model.nv, model.nv)), 1e-15)


@random_models
def test_christoffel_symbols_give_c(model):
    """C == Gamma v; Gamma[:, :, k] == C(q, e_k). Wiring only: christoffel_symbols runs the
    kernel of coriolis_matrix at v = e_k (the independent checks follow)."""
    q, v, _ = states(model)
    Gamma = rd.christoffel_symbols(model, q)
    assert Gamma.shape == (model.nv,) * 3
    assert_rel(np.einsum("ijk,k->ij", Gamma, v), rd.coriolis_matrix(model, q, v), 1e-9)


@fixed_base_models
def test_christoffel_symbols_from_mass_matrix_derivatives(model):
    """Fixed base: Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2, symmetric in (j, k)."""
    q, _, _ = states(model)
    Gamma = rd.christoffel_symbols(model, q)
    assert_rel(Gamma, Gamma.transpose(0, 2, 1), 1e-9)
    dM = columns_by_differences(lambda x: rd.crba(model, x), model, q)  # dM[i, j, k] = dM_ij / dq_k
    expected = 0.5 * (dM + dM.transpose(0, 2, 1) - dM.transpose(2, 0, 1))
    assert_rel(Gamma, expected, 1e-6)


def _pin_mass_matrix(pair, q):
    M = pin.crba(pair.pm, pair.data, pair.pin_q(q))
    return np.triu(M) + np.triu(M, 1).T


@pytest.mark.parametrize("path", ["panda_description/urdf/panda.urdf",
                                  "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
                                  "ur_description/urdf/ur5_robot.urdf"])
def test_christoffel_symbols_from_pinocchio_mass_matrix(path):
    """Fixed base, real robots: Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2 with the
    derivatives of Pinocchio's mass matrix by Richardson differences."""
    pair = load_pair(path, False)
    q, _, _ = states(pair.model, "pinocchio M")
    dM = richardson(lambda d: _pin_mass_matrix(pair, q + d), pair.model.nv)  # dM[i, j, k] = dM_ij / dq_k
    expected = 0.5 * (dM + dM.transpose(0, 2, 1) - dM.transpose(2, 0, 1))
    assert_rel(rd.christoffel_symbols(pair.model, q), expected, FD_TOL)


@pytest.mark.parametrize("path", ["solo_description/robots/solo12.urdf",
                                  "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
                                  "anymal_b_simple_description/robots/anymal-kinova.urdf"])
def test_floating_base_christoffel_symbols_against_pinocchio(path):
    """Floating base (quasi-velocities, Gamma not symmetric): Gamma[:, :, k] is Pinocchio's
    Coriolis matrix at v = e_k, Gamma v v is Pinocchio's nonlinear effects minus gravity, and
    coriolis_matrix is Pinocchio's at two velocities."""
    pair = load_pair(path, True)
    model, pm, data = pair.model, pair.pm, pair.data
    q, v, w = states(model, "pinocchio C")
    qp = pair.pin_q(q)
    Gamma = rd.christoffel_symbols(model, q)
    for k in range(model.nv):
        assert_rel(Gamma[:, :, k], pin.computeCoriolisMatrix(pm, data, qp, np.eye(model.nv)[k]), 1e-9, f"k={k}")
    h = pin.nonLinearEffects(pm, data, qp, v) - pin.computeGeneralizedGravity(pm, data, qp)
    assert_rel(np.einsum("ijk,j,k->i", Gamma, v, v), h, 1e-9, "Gamma v v")
    assert rel_asymmetry(Gamma) > 1e-3  # the base's quasi-velocities
    for x in (v, w):
        assert_rel(rd.coriolis_matrix(model, q, x), pin.computeCoriolisMatrix(pm, data, qp, x), 1e-9, "C")


def rel_asymmetry(Gamma) -> float:
    """``max |Gamma_ijk - Gamma_ikj| / max |Gamma|``."""
    return float(np.abs(Gamma - Gamma.transpose(0, 2, 1)).max() / np.abs(Gamma).max())


@pytest.mark.parametrize("params", [PLANAR_2R, dict(m1=1.0, m2=4.0, l1=0.3, l2=1.2)], ids=["arm1", "arm2"])
def test_planar_2r_closed_form(params):
    """Spong's C = [[-beta s2 qd2, -beta s2 (qd1 + qd2)], [beta s2 qd1, 0]]."""
    model = planar_2r(**params)
    for q, qd in rng_for("2r-C", tuple(params.values())).uniform(-3, 3, (6, 2, 2)):
        _, C, _ = planar_2r_terms(q, qd, **params)
        assert_rel(rd.coriolis_matrix(model, q, qd), C, 1e-12, f"q={q}, qd={qd}")


def test_batch():
    for model in (random_model(8, seed=41, floating_base=True), random_model(5, seed=42)):
        check_batch(rd.coriolis_matrix, model, ("q", "v"))
        check_batch(rd.christoffel_symbols, model, ("q",))


@pytest.mark.parametrize("fn, names", [(rd.coriolis_matrix, ("q", "v")), (rd.christoffel_symbols, ("q",))],
                         ids=["coriolis_matrix", "christoffel_symbols"])
@input_checks
def test_bad_input(fn, names, aspect):
    check_input_validation(fn, names, aspect)
