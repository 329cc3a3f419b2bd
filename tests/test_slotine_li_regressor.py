"""Slotine-Li regressor (robodyn.slotine_li_regressor): Y(q, qd, qd_r, qdd_r) theta ==
M qdd_r + C(q, qd) qd_r + g with the Christoffel-consistent C of rd.coriolis_matrix, on
random trees (every joint type, branching, floating base), body by body, on the built-in
robots, the two-link arm in closed form and Pinocchio's M, C, g on every example-robot-data
URDF; equal to rd.regressor when qd_r = qd; friction, armature and offset columns; batches
and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from robodyn.algorithms.regressor import extended_parameters
from conftest import erd_id
from helpers import (PLANAR_2R, assert_rel, check_input_validation, input_checks, planar_2r, planar_2r_terms,
                     random_models, rng_for, states, with_friction_and_armature)
from test_pinocchio import URDFS, _pair, _symmetric
from test_urdf import PINOCCHIO_REFUSES

# the files both libraries load (those Pinocchio refuses are checked in test_pinocchio.py)
BOTH_LOAD = [p for p in URDFS if erd_id(p) not in PINOCCHIO_REFUSES]


def reference_states(model, *keys, size=()):
    """Random ``(q, qd, qd_r, qdd_r)``: the reference velocity independent of ``qd``."""
    q, v, a = states(model, *keys, size=size)
    _, v_r, _ = states(model, *keys, "reference", size=size)
    return q, v, v_r, a


def expected(model, q, v, v_r, a_r):
    """``M qdd_r + C(q, qd) qd_r + g`` from crba (without armature), coriolis_matrix and gravity."""
    return (np.einsum("...ij,...j->...i", rd.crba(model, q, armature=False), a_r)
            + np.einsum("...ij,...j->...i", rd.coriolis_matrix(model, q, v), v_r) + rd.gravity(model, q))


@random_models
def test_is_mass_coriolis_and_gravity_terms(model):
    """Y theta == M qdd_r + C(q, qd) qd_r + g on a batch of states (for a floating base
    with the base velocity as quasi-velocity, as in coriolis_matrix)."""
    q, v, v_r, a_r = reference_states(model, "slotine-li", size=3)
    Y = rd.slotine_li_regressor(model, q, v, v_r, a_r)
    assert Y.shape == (3, model.nv, 10 * model.nbodies)
    assert_rel(Y @ model.inertial_parameters(), expected(model, q, v, v_r, a_r), 1e-10)


@random_models
def test_is_the_joint_torque_regressor_when_reference_velocity_is_velocity(model):
    """qd_r = qd: Y(q, qd, qd, qdd) == regressor(q, qd, qdd)."""
    q, v, _, a = reference_states(model, "same-velocity", size=2)
    assert_rel(rd.slotine_li_regressor(model, q, v, v, a), rd.regressor(model, q, v, a), 1e-12)


@random_models
def test_each_column_block_is_one_body(model):
    """Column block i is body i alone: the terms of the model with every other body massless;
    Y is linear in (qd_r, qdd_r) but not in qd (C(q, qd) is)."""
    q, v, v_r, a_r = reference_states(model, "blocks")
    Y = rd.slotine_li_regressor(model, q, v, v_r, a_r)
    for i in range(model.nbodies):
        theta = np.zeros((model.nbodies, 10))
        theta[i] = model.theta[i]
        alone = model.replace(theta=theta, physical="warn")
        assert_rel(Y[:, 10 * i:10 * i + 10] @ model.theta[i], expected(alone, q, v, v_r, a_r), 1e-10, f"body {i}")
    Y2 = rd.slotine_li_regressor(model, q, v, 2.0 * v_r - v, a_r)
    Y0 = rd.slotine_li_regressor(model, q, v, 0 * v, 0 * a_r)
    assert_rel(Y2 - Y0, 2.0 * (Y - Y0) - (rd.slotine_li_regressor(model, q, v, v, a_r) - Y0), 1e-10, "linear")


@random_models
@pytest.mark.parametrize("smoothing", [0.0, 0.3])
def test_friction_armature_and_offset_columns(model, smoothing):
    """[Y, qd, sgn qd, qdd_r, 1] [theta, damping, coulomb, armature, offset] ==
    rnea(q, qd, qdd_r) - C (qd - qd_r) + offset: friction at the true velocity, armature at
    the reference acceleration; each block reads back its column."""
    rng = rng_for(model.name, "sl-extra", smoothing)
    m = with_friction_and_armature(model, rng, smoothing)
    q, v, v_r, a_r = reference_states(model, "sl-extra", smoothing, size=3)
    v[0, 0] = 0.0  # Coulomb column at rest: sgn(0) = 0, as in rnea
    offset = rng.standard_normal(model.nv)
    Y = rd.slotine_li_regressor(m, q, v, v_r, a_r, damping=True, coulomb=True, armature=True, offset=True)
    nb, nv = model.nbodies, model.nv
    assert Y.shape == (3, nv, 10 * nb + 4 * nv)
    theta = extended_parameters(m, damping=True, coulomb=True, armature=True, offset=offset)
    C = rd.coriolis_matrix(m, q, v)
    assert_rel(Y @ theta, rd.rnea(m, q, v, a_r) - np.einsum("...ij,...j->...i", C, v - v_r) + offset, 1e-10)
    assert_rel(Y[..., :10 * nb], rd.slotine_li_regressor(m, q, v, v_r, a_r), 0.0)
    sgn = np.tanh(v / smoothing) if smoothing else np.sign(v)
    for block, column in enumerate((v, sgn, a_r, np.ones_like(v))):
        cols = Y[..., 10 * nb + block * nv:10 * nb + (block + 1) * nv]
        assert_rel(cols, column[:, :, None] * np.eye(nv), 1e-15, f"block {block}")
    only = rd.slotine_li_regressor(m, q, v, v_r, a_r, armature=True)
    assert_rel(only[..., 10 * nb:], Y[..., 10 * nb + 2 * nv:10 * nb + 3 * nv], 0.0)


def test_planar_2r_closed_form():
    """The two-link arm: textbook M, C (Christoffel symbols) and g (Spong et al. 2006, 7.4)."""
    model = planar_2r(**PLANAR_2R)
    rng = rng_for("sl-2r")
    for _ in range(3):
        q, v, v_r, a_r = rng.uniform(-2, 2, (4, 2))
        M, C, g = planar_2r_terms(q, v, **PLANAR_2R)
        assert_rel(rd.slotine_li_regressor(model, q, v, v_r, a_r) @ model.inertial_parameters(),
                   M @ a_r + C @ v_r + g, 1e-12)


def test_builtin_robots():
    """Y theta == M qdd_r + C qd_r + g on every built-in robot."""
    for name in rd.models.names():
        model = rd.models.load(name)
        q, v, v_r, a_r = reference_states(model, "sl-builtin", size=2)
        assert_rel(rd.slotine_li_regressor(model, q, v, v_r, a_r) @ model.inertial_parameters(),
                   expected(model, q, v, v_r, a_r), 1e-10, name)


@pytest.mark.parametrize("floating_base", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("path", BOTH_LOAD, ids=erd_id)
def test_agrees_with_pinocchio(path, floating_base):
    """Y theta == M qdd_r + C qd_r + g with Pinocchio's crba, computeCoriolisMatrix and
    computeGeneralizedGravity on every example-robot-data URDF."""
    pair = _pair(path, floating_base)
    assert not isinstance(pair, Exception), f"Pinocchio refuses {erd_id(path)}: {pair}"
    model, pm, data = pair.model, pair.pm, pair.data
    rng = rng_for(erd_id(path), floating_base, "slotine-li")
    q, v, a_r = rd.random.random_state(model, rng)
    v_r = rng.standard_normal(model.nv)
    qp = pair.pin_q(q)
    theirs = (_symmetric(pin.crba(pm, data, qp)) @ a_r + pin.computeCoriolisMatrix(pm, data, qp, v) @ v_r
              + pin.computeGeneralizedGravity(pm, data, qp))
    assert_rel(rd.slotine_li_regressor(model, q, v, v_r, a_r) @ model.inertial_parameters(), theirs, 1e-9)


def test_batch_and_broadcast():
    """A (2, 3) batch equals the single calls; one q broadcasts against (4, nv) velocities."""
    model = rd.random.random_model(4, seed=11, floating_base=True)
    q, v, v_r, a_r = reference_states(model, "sl-batch", size=(2, 3))
    Y = rd.slotine_li_regressor(model, q, v, v_r, a_r)
    assert Y.shape == (2, 3, model.nv, 10 * model.nbodies)
    for i in np.ndindex(2, 3):
        assert_rel(Y[i], rd.slotine_li_regressor(model, q[i], v[i], v_r[i], a_r[i]), 1e-13, f"element {i}")
    Yb = rd.slotine_li_regressor(model, q[0, 0], v[0], v_r[0], a_r[1])
    assert Yb.shape == (3, model.nv, 10 * model.nbodies)
    assert_rel(Yb[2], rd.slotine_li_regressor(model, q[0, 0], v[0, 2], v_r[0, 2], a_r[1, 2]), 1e-13)


def test_robot_without_joints():
    b = rd.ModelBuilder("statue")
    b.add_link("base", mass=1.0, inertia=np.eye(3))
    model = b.build()
    z = np.zeros(0)
    assert rd.slotine_li_regressor(model, z, z, z, z).shape == (0, 0)
    assert rd.slotine_li_regressor(model, np.zeros((3, 0)), z, z, z, damping=True).shape == (3, 0, 0)


@input_checks
def test_bad_input(aspect):
    """q and qd as in every algorithm (wrong shapes, NaN/Inf, quaternions)."""
    def call(model, q, v, **kw):
        return rd.slotine_li_regressor(model, q, v, v, v, **kw)

    check_input_validation(call, ("q", "v"), aspect)


@pytest.mark.parametrize("name", ["v_ref", "a_ref"])
def test_bad_reference(name):
    """The reference velocity and acceleration: shapes and NaN/Inf, named in the error."""
    model = rd.random.random_model(3, seed=2)
    q, v, v_r, a_r = reference_states(model, "sl-bad")
    args = dict(q=q, v=v, v_ref=v_r, a_ref=a_r)
    with pytest.raises(ValueError, match=rf"{name}: expected shape \(\.\.\., 3\), got \(4,\)"):
        rd.slotine_li_regressor(model, **{**args, name: np.zeros(4)})
    for batch in (False, True):
        bad = args[name].copy()
        bad[1] = np.nan
        arrays = {**args, name: np.stack([args[name], bad]) if batch else bad}
        with pytest.raises(ValueError, match=rf"slotine_li_regressor: {name} contains NaN or Inf"):
            rd.slotine_li_regressor(model, **arrays)
        assert rd.slotine_li_regressor(model, **arrays, check_finite=False).shape[-2:] == (3, 30)
