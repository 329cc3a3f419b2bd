"""Regressors (robodyn.regressor, kinetic/potential_energy_regressor): linear in the inertial
parameters and equal to rnea and the energies on random trees, with friction, armature and
offset columns; the power balance column by column; the pendulum in closed form; Pinocchio's
computeJointTorqueRegressor on every example-robot-data URDF; batches and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from robodyn.algorithms.regressor import extended_parameters, extra_columns
from conftest import erd_id
from helpers import (G, assert_rel, check_batch, check_input_validation, input_checks, integrate, pendulum,
                     random_models, rng_for, states, with_friction_and_armature)
from test_pinocchio import URDFS, _pair
from test_urdf import PINOCCHIO_REFUSES

# the files both libraries load (those Pinocchio refuses are checked in test_pinocchio.py)
BOTH_LOAD = [p for p in URDFS if erd_id(p) not in PINOCCHIO_REFUSES]


@random_models
def test_regressor_times_parameters_is_rnea(model):
    """Y(q, v, a) theta == rnea(q, v, a) without friction and armature, on a batch of states."""
    q, v, a = states(model, "regressor", size=4)
    Y = rd.regressor(model, q, v, a)
    assert Y.shape == (4, model.nv, 10 * model.nbodies)
    assert_rel(Y @ model.inertial_parameters(), rd.rnea(model, q, v, a, friction=False, armature=False), 1e-10)


@random_models
def test_regressor_is_linear_in_each_body(model):
    """Column block i of Y is the torque of body i alone: rnea with every other body massless."""
    q, v, a = states(model, "blocks")
    Y = rd.regressor(model, q, v, a)
    for i in range(model.nbodies):
        theta = np.zeros(10 * model.nbodies)
        theta[10 * i:10 * i + 10] = model.theta[i]
        alone = model.replace(theta=theta.reshape(-1, 10), physical="warn")
        assert_rel(Y[:, 10 * i:10 * i + 10] @ model.theta[i],
                   rd.rnea(alone, q, v, a, friction=False, armature=False), 1e-10, f"body {i}")


@random_models
@pytest.mark.parametrize("smoothing", [0.0, 0.3])
def test_friction_armature_and_offset_columns(model, smoothing):
    """[Y, v, sgn v, a, 1] [theta, damping, coulomb, armature, offset] == rnea + offset."""
    rng = rng_for(model.name, "extra", smoothing)
    m = with_friction_and_armature(model, rng, smoothing)
    q, v, a = states(model, "extra", smoothing, size=3)
    v[0, 0] = 0.0  # Coulomb column at rest: sgn(0) = 0, as in rnea
    offset = rng.standard_normal(model.nv)
    Y = rd.regressor(m, q, v, a, damping=True, coulomb=True, armature=True, offset=True)
    nb, nv = model.nbodies, model.nv
    assert Y.shape == (3, nv, 10 * nb + 4 * nv)
    theta = extended_parameters(m, damping=True, coulomb=True, armature=True, offset=offset)
    assert_rel(Y @ theta, rd.rnea(m, q, v, a) + offset, 1e-10)
    assert_rel(Y[..., :10 * nb], rd.regressor(m, q, v, a), 0.0)
    sgn = np.tanh(v / smoothing) if smoothing else np.sign(v)
    for block, expected in enumerate((v, sgn, a, np.ones_like(v))):
        cols = Y[..., 10 * nb + block * nv:10 * nb + (block + 1) * nv]
        assert_rel(cols, expected[:, :, None] * np.eye(nv), 1e-15, f"block {block}")
    names = extra_columns(m, damping=True, coulomb=True, armature=True, offset=True)
    assert len(names) == 4 * nv and names[0] == f"damping[{m.dof_names[0]}]"
    only = rd.regressor(m, q, v, a, coulomb=True, offset=True)
    assert_rel(only[..., 10 * nb:], np.concatenate([Y[..., 10 * nb + nv:10 * nb + 2 * nv],
                                                    Y[..., 10 * nb + 3 * nv:]], axis=-1), 0.0)
    assert extra_columns(m, coulomb=True, offset=True) == names[nv:2 * nv] + names[3 * nv:]


@random_models
def test_energy_regressors(model):
    """Y_T theta == kinetic_energy, Y_U theta == potential_energy; inertia columns of Y_U are 0."""
    q, v, _ = states(model, "energy", size=3)
    theta = model.inertial_parameters()
    YT, YU = rd.kinetic_energy_regressor(model, q, v), rd.potential_energy_regressor(model, q)
    assert YT.shape == YU.shape == (3, 10 * model.nbodies)
    assert_rel(YT @ theta, rd.kinetic_energy(model, q, v), 1e-10)
    assert_rel(YU @ theta, rd.potential_energy(model, q), 1e-10)
    assert np.all(YU.reshape(3, -1, 10)[..., 4:] == 0.0)


@random_models
def test_power_balance_column_by_column(model):
    """v^T Y(q, v, a) = d/dt (Y_T + Y_U) along q(t) with qd = v, qdd = a: the energy theorem
    for every parameter vector at once (central differences)."""
    q, v, a = states(model, "power")
    h = 1e-5

    def energy(t):
        qt, vt = integrate(model, q, v, t), v + a * t
        return rd.kinetic_energy_regressor(model, qt, vt) + rd.potential_energy_regressor(model, qt)

    rate = (energy(h) - energy(-h)) / (2 * h)
    assert_rel(v @ rd.regressor(model, q, v, a), rate, 1e-7)


def test_pendulum_closed_form():
    """Point-mass pendulum about y (helpers.pendulum): tau = Iyy qdd - g (m cx cos q + m cz sin q),
    so the only non-zero columns are m cx: -g cos q, m cz: -g sin q, Iyy: qdd; and
    U = g (m cz cos q - m cx sin q), whose derivative is the gravity part."""
    model = pendulum()
    for q, v, a in ((0.3, 0.7, 1.1), (-2.0, 0.0, -0.4)):
        expected = np.zeros(10)
        expected[1], expected[3], expected[6] = -G * np.cos(q), -G * np.sin(q), a
        assert_rel(rd.regressor(model, np.array([q]), np.array([v]), np.array([a]))[0], expected, 1e-12)
        assert_rel(rd.potential_energy_regressor(model, np.array([q]))[[0, 1, 3]],
                   [0.0, -G * np.sin(q), G * np.cos(q)], 1e-12)


@pytest.mark.parametrize("floating_base", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("path", BOTH_LOAD, ids=erd_id)
def test_agrees_with_pinocchio(path, floating_base):
    """Same column order as pin.computeJointTorqueRegressor (Pinocchio's dynamic parameters
    [m, mc, Ixx, Ixy, Iyy, Ixz, Iyz, Izz] about the joint frame are robodyn's 10 parameters),
    and Y theta == rnea, on every example-robot-data URDF."""
    pair = _pair(path, floating_base)
    assert not isinstance(pair, Exception), f"Pinocchio refuses {erd_id(path)}: {pair}"
    model, pm, data = pair.model, pair.pm, pair.data
    for j in range(1, pm.njoints):
        assert_rel(model.theta[j - 1], pm.inertias[j].toDynamicParameters(), 1e-12, "parameters")
    rng = rng_for(erd_id(path), floating_base, "regressor")
    q, v, a = rd.random.random_state(model, rng)
    Y = rd.regressor(model, q, v, a)
    assert_rel(Y, pin.computeJointTorqueRegressor(pm, data, pair.pin_q(q), v, a), 1e-9)
    assert_rel(Y @ model.inertial_parameters(), rd.rnea(model, q, v, a, friction=False, armature=False), 1e-9)


def test_batch():
    model = rd.random.random_model(4, seed=11, floating_base=True)
    check_batch(rd.regressor, model, ("q", "v", "a"))
    check_batch(rd.kinetic_energy_regressor, model, ("q", "v"))
    check_batch(rd.potential_energy_regressor, model, ("q",))


def test_robot_without_joints():
    """No bodies: empty regressors."""
    b = rd.ModelBuilder("statue")
    b.add_link("base", mass=1.0, inertia=np.eye(3))
    model = b.build()
    assert rd.regressor(model, np.zeros(0), np.zeros(0), np.zeros(0)).shape == (0, 0)
    assert rd.regressor(model, np.zeros((3, 0)), np.zeros(0), np.zeros(0), damping=True).shape == (3, 0, 0)
    assert rd.kinetic_energy_regressor(model, np.zeros(0), np.zeros(0)).shape == (0,)
    assert rd.potential_energy_regressor(model, np.zeros((2, 0))).shape == (2, 0)


def test_builtin_robots():
    """Y theta == rnea on every built-in robot."""
    for name in rd.models.names():
        model = rd.models.load(name)
        q, v, a = states(model, "builtin", size=2)
        assert_rel(rd.regressor(model, q, v, a) @ model.inertial_parameters(),
                   rd.rnea(model, q, v, a, friction=False, armature=False), 1e-10, name)


@input_checks
@pytest.mark.parametrize("fn, names", [
    (rd.regressor, ("q", "v", "a")),
    (lambda model, q, v, **kw: rd.kinetic_energy_regressor(model, q, v, **kw), ("q", "v")),
    (lambda model, q, **kw: rd.potential_energy_regressor(model, q, **kw), ("q",)),
], ids=["regressor", "kinetic", "potential"])
def test_bad_input(fn, names, aspect):
    check_input_validation(fn, names, aspect)
