"""Centre of mass and its Jacobian (robodyn.center_of_mass, com_jacobian): against the body
poses, finite differences, the base translation, the potential energy; massless models,
batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (assert_rel, check_batch, check_input_validation, input_checks, columns_by_differences,
                     random_model, random_models, states)


def com_from_poses(model, q):
    """sum_i m_i (p_i + R_i c_i) / m from forward_kinematics and the inertial parameters."""
    T = rd.forward_kinematics(model, q)
    moment = sum(model.theta[i, 0] * T[i, :3, 3] + T[i, :3, :3] @ model.theta[i, 1:4] for i in range(model.nbodies))
    return moment / model.total_mass


@random_models
def test_center_of_mass_from_body_poses(model):
    q, _, _ = states(model)
    assert_rel(rd.center_of_mass(model, q), com_from_poses(model, q), 1e-12)


@random_models
def test_jacobian_is_derivative_of_center_of_mass(model):
    q, v, _ = states(model)
    J = rd.com_jacobian(model, q)
    assert J.shape == (3, model.nv)
    assert_rel(J, columns_by_differences(lambda x: rd.center_of_mass(model, x), model, q), 1e-6)


@random_models
def test_linear_momentum(model):
    """m J_com v == sum_b m_b (velocity of the centre of mass of body b), from body Jacobians."""
    q, v, _ = states(model)
    momentum = np.zeros(3)
    for b in range(model.nbodies):
        lin, ang = np.split(rd.jacobian(model, q, b, frame="local_world_aligned") @ v, 2)
        R = rd.forward_kinematics(model, q)[b, :3, :3]
        momentum += model.theta[b, 0] * lin + np.cross(ang, R @ model.theta[b, 1:4])
    assert_rel(model.total_mass * rd.com_jacobian(model, q) @ v, momentum, 1e-9)


def test_floating_base_translation_moves_the_center_of_mass():
    model = random_model(6, seed=61, floating_base=True)
    q, _, _ = states(model)
    shifted = q.copy()
    shifted[:3] += (0.3, -1.0, 2.0)
    assert_rel(rd.center_of_mass(model, shifted), rd.center_of_mass(model, q) + (0.3, -1.0, 2.0), 1e-12)
    J = rd.com_jacobian(model, q)
    R = rd.forward_kinematics(model, q)[0, :3, :3]
    assert_rel(J[:, :3], R, 1e-12)  # base linear velocity (base frame) moves the whole robot


def test_massless_model_has_no_center_of_mass():
    b = rd.ModelBuilder("ghost")
    b.add_link("base")
    b.add_link("arm")
    b.add_joint("j", "revolute", "base", "arm", axis=(0, 0, 1))
    model = b.build()
    for fn in (rd.center_of_mass, rd.com_jacobian):
        with pytest.raises(ValueError, match="no mass"):
            fn(model, [0.1])


def test_batch():
    for model in (random_model(8, seed=62, floating_base=True), random_model(4, seed=63)):
        check_batch(rd.center_of_mass, model, ("q",))
        check_batch(rd.com_jacobian, model, ("q",))


@pytest.mark.parametrize("fn", [rd.center_of_mass, rd.com_jacobian], ids=["center_of_mass", "com_jacobian"])
@input_checks
def test_bad_input(fn, aspect):
    check_input_validation(fn, ("q",), aspect)
