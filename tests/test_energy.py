"""Kinetic and potential energy (robodyn.kinetic_energy, potential_energy): against the mass
matrix and the centre of mass, dU/dq = g(q) by finite differences, and the power balance
d(T + U)/dt = v . tau along a simulated motion; batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (assert_rel, check_batch, check_input_validation, input_checks, columns_by_differences,
                     configuration_rate, directional_derivative, fixed_base_models, random_model,
                     random_models, rk4, rng_for, states)


@random_models
def test_kinetic_energy_is_quadratic_form_of_mass_matrix(model):
    q, v, _ = states(model)
    assert rd.kinetic_energy(model, q, v) == pytest.approx(v @ rd.crba(model, q) @ v / 2, rel=1e-12)
    # armature (rotor energy) is not part of the rigid-body kinetic energy
    m = model.replace(armature=np.full(model.nv, 0.5))
    assert rd.kinetic_energy(m, q, v) == pytest.approx(v @ rd.crba(m, q, armature=False) @ v / 2, rel=1e-12)


@random_models
def test_potential_energy_convention(model):
    """U = -m_total g . c: zero when the centre of mass is at the world origin."""
    q, _, _ = states(model)
    expected = -model.total_mass * model.gravity @ rd.center_of_mass(model, q)
    assert rd.potential_energy(model, q) == pytest.approx(expected, rel=1e-12, abs=1e-12)


@fixed_base_models
def test_potential_energy_gradient_is_gravity(model):
    q, _, _ = states(model)
    assert_rel(columns_by_differences(lambda x: rd.potential_energy(model, x), model, q), rd.gravity(model, q), 1e-6)


@random_models
def test_potential_energy_rate_is_gravity_power(model):
    """dU/dt == g(q) . v along the motion (the base velocity being in the base frame)."""
    q, v, _ = states(model)
    rate = directional_derivative(lambda x: rd.potential_energy(model, x), model, q, v)
    assert rate == pytest.approx(rd.gravity(model, q) @ v, rel=1e-6, abs=1e-6)


def _kinetic(model, q, v):
    """Kinetic energy of the bodies and of the rotors (armature)."""
    return rd.kinetic_energy(model, q, v) + 0.5 * model.armature @ v ** 2


@random_models
@pytest.mark.parametrize("dissipative", [False, True], ids=["conservative", "damping+armature"])
def test_power_balance(model, dissipative):
    """Simulate 0.01 s with constant joint forces (RK4, 100 steps, quaternion as coordinates):
    energy change (rotor energy included) == work of tau minus the viscous losses."""
    rng = rng_for(model.name, "power", dissipative)
    if dissipative:
        model = model.replace(damping=rng.uniform(0.5, 2.0, model.nv), armature=rng.uniform(0.01, 0.1, model.nv))
    q0, v0, tau = states(model, "power")
    nq, nv = model.nq, model.nv

    def rate(x):
        q, v = x[:nq], x[nq:nq + nv]
        a = rd.aba(model, q, v, tau)
        return np.concatenate([configuration_rate(model, q, v), a, [v @ tau - model.damping @ v ** 2]])

    x = rk4(rate, np.concatenate([q0, v0, [0.0]]), 0.01, 100)
    q1, v1, work = x[:nq], x[nq:nq + nv], x[-1]
    kinetic = _kinetic(model, q1, v1) - _kinetic(model, q0, v0)
    potential = rd.potential_energy(model, q1) - rd.potential_energy(model, q0)
    size = abs(kinetic) + abs(potential) + abs(work)
    assert size > 1e-3  # a real motion
    assert abs(kinetic + potential - work) / size < 1e-9, (kinetic, potential, work)


def test_robot_without_joints():
    """A fixed-base robot without joints has no bodies (its root link is the world): no energy."""
    b = rd.ModelBuilder("statue")
    b.add_link("base", mass=1.0, inertia=np.eye(3))
    model = b.build()
    assert (model.nq, model.nv, model.nbodies) == (0, 0, 0)
    assert rd.kinetic_energy(model, np.zeros(0), np.zeros(0)) == 0.0
    assert rd.potential_energy(model, np.zeros(0)) == 0.0


def test_batch():
    for model in (random_model(8, seed=71, floating_base=True), random_model(4, seed=72)):
        check_batch(rd.kinetic_energy, model, ("q", "v"))
        check_batch(rd.potential_energy, model, ("q",))


def test_shapes():
    model = random_model(3, seed=73)
    q, v, _ = states(model, size=(5,))
    assert np.shape(rd.kinetic_energy(model, q[0], v[0])) == ()
    assert np.shape(rd.potential_energy(model, q[0])) == ()
    assert rd.kinetic_energy(model, q, v).shape == (5,)
    assert rd.potential_energy(model, q).shape == (5,)


@pytest.mark.parametrize("fn, names", [(rd.kinetic_energy, ("q", "v")), (rd.potential_energy, ("q",))],
                         ids=["kinetic_energy", "potential_energy"])
@input_checks
def test_bad_input(fn, names, aspect):
    check_input_validation(fn, names, aspect)
