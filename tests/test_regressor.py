"""Regressors (robodyn.regressor, kinetic/potential_energy_regressor): linear in the inertial
parameters and equal to rnea and the energies on random trees, with friction, stiffness,
armature and offset columns (also of the Slotine-Li regressor); the power balance column by
column; the pendulum in closed form; Pinocchio's computeJointTorqueRegressor on every
example-robot-data URDF; batches and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from robodyn import joints as J
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


def one_dof(model) -> np.ndarray:
    """(nv,) whether each dof is that of a joint of one dof (the joints that take springs)."""
    out = np.zeros(model.nv, dtype=bool)
    for i in range(model.nbodies):
        out[model.idx_v[i]] = J.NV[model.joint_type[i]] == 1
    return out


def with_springs(model, rng):
    """``model`` with random springs on its joints of one dof (free, spherical and planar
    joints take none)."""
    one = one_dof(model)
    return model.replace(stiffness=np.where(one, rng.uniform(0.5, 5.0, model.nv), 0.0),
                         spring_reference=np.where(one, rng.uniform(-1.0, 1.0, model.nv), 0.0))


def joint_coordinates(model, q) -> np.ndarray:
    """(..., nv): ``q`` of each dof of a joint of one dof, 0 on the others."""
    out = np.zeros(q.shape[:-1] + (model.nv,))
    for i in range(model.nbodies):
        if J.NV[model.joint_type[i]] == 1:
            out[..., model.idx_v[i]] = q[..., model.idx_q[i]]
    return out


@random_models
def test_stiffness_columns(model):
    """[Y, v, sgn v, q, a, 1] [theta, damping, coulomb, K, armature, -K q_ref] == rnea with
    friction, springs and armature, floating bases and ball joints included (their dofs have
    zero stiffness columns); the stiffness and offset blocks alone give the springs' torque."""
    rng = rng_for(model.name, "stiffness")
    m = with_springs(with_friction_and_armature(model, rng), rng)
    q, v, a = states(model, "stiffness", size=3)
    flags = dict(damping=True, coulomb=True, stiffness=True, armature=True, offset=True)
    Y = rd.regressor(m, q, v, a, **flags)
    nb, nv = model.nbodies, model.nv
    assert Y.shape == (3, nv, 10 * nb + 5 * nv)
    theta = extended_parameters(m, **flags)
    assert_rel(theta[10 * nb + 2 * nv:10 * nb + 3 * nv], m.stiffness, 0.0)
    assert_rel(theta[-nv:], -m.stiffness * m.spring_reference, 0.0)
    assert_rel(Y @ theta, rd.rnea(m, q, v, a), 1e-10)
    assert_rel(rd.regressor(m, q[1], v[1], a[1], **flags), Y[1], 0.0)  # one state: the same columns
    cols = Y[..., 10 * nb + 2 * nv:10 * nb + 3 * nv]
    assert_rel(cols, joint_coordinates(m, q)[:, :, None] * np.eye(nv), 0.0, "stiffness block")
    names = extra_columns(m, **flags)
    assert len(names) == 5 * nv and names[2 * nv:3 * nv] == [f"stiffness[{n}]" for n in m.dof_names]
    springs = rd.regressor(m, q, v, a, stiffness=True, offset=True)[..., 10 * nb:]
    K = extended_parameters(m, stiffness=True, offset=True)[10 * nb:]
    no_friction = m.replace(damping=np.zeros(nv), coulomb=np.zeros(nv))
    assert_rel(springs @ K, rd.rnea(no_friction, q, v, a) - rd.rnea(m, q, v, a, friction=False), 1e-10, "springs")
    # offsets given as numbers: the joint torque offsets as before; False is None
    offset = rng.standard_normal(nv)
    assert_rel(Y @ extended_parameters(m, **{**flags, "offset": offset}),
               rd.rnea(m, q, v, a) + m.stiffness * m.spring_reference + offset, 1e-10, "offset array")
    assert_rel(extended_parameters(m, offset=False), m.inertial_parameters(), 0.0)
    with pytest.raises(ValueError, match=rf"offset: expected True, None or shape \({nv},\)"):
        extended_parameters(m, offset=np.zeros(nv + 1))


@random_models
def test_slotine_li_stiffness_columns(model):
    """The Slotine-Li regressor's stiffness columns: ``Y @ extended_parameters(...) ==
    rnea(q, qd, qdd_r) - C (qd - qd_r)`` with springs (at ``q``), friction and armature."""
    rng = rng_for(model.name, "sl-stiffness")
    m = with_springs(with_friction_and_armature(model, rng, 0.3), rng)
    q, v, a_r = states(model, "sl-stiffness", size=3)
    _, v_r, _ = states(model, "sl-stiffness", "reference", size=3)
    flags = dict(damping=True, coulomb=True, stiffness=True, armature=True, offset=True)
    Y = rd.slotine_li_regressor(m, q, v, v_r, a_r, **flags)
    C = rd.coriolis_matrix(m, q, v)
    expected = rd.rnea(m, q, v, a_r) - np.einsum("...ij,...j->...i", C, v - v_r)
    assert_rel(Y @ extended_parameters(m, **flags), expected, 1e-10)
    nb, nv = model.nbodies, model.nv
    stiffness = slice(10 * nb + 2 * nv, 10 * nb + 3 * nv)
    assert_rel(Y[..., stiffness], rd.regressor(m, q, v, a_r, **flags)[..., stiffness], 0.0, "the same q columns")
    assert_rel(rd.slotine_li_regressor(m, q, v, v, a_r, **flags), rd.regressor(m, q, v, a_r, **flags), 1e-10,
               "qd_r = qd")


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
