"""Task-space dynamics (robodyn.task_space_inertia, dynamically_consistent_inverse,
task_space_dynamics): the formulas from crba and jacobian on random trees, the task-space
equation of motion against aba, a point mass in closed form, Pinocchio on URDFs, batches,
singular configurations and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import G, PLANAR_2R, RANDOM_MODELS, assert_rel, planar_2r, random_models, rng_for, states
from test_pinocchio import JACOBIAN_FRAMES
from urdf_subset import load_pair, pairs

FRAMES = ("world", "local", "local_world_aligned")
ROWS = {"all": slice(0, 6), "linear": slice(0, 3), "angular": slice(3, 6)}


def _body(model):
    """The last body; it has at least three dofs among its ancestors in every random tree used."""
    return model.nbodies - 1


def _reference(model, q, v, body, frame, rows):
    """Lambda, mu, p and Jbar from crba, nonlinear_effects, gravity and the Jacobians."""
    M = rd.crba(model, q)
    J = rd.jacobian(model, q, body, frame)[ROWS[rows]]
    Minv = np.linalg.inv(M)
    Lam = np.linalg.inv(J @ Minv @ J.T)
    Jbar = Minv @ J.T @ Lam
    g = rd.gravity(model, q)
    Cv = rd.nonlinear_effects(model, q, v) - g
    mu = Jbar.T @ Cv - Lam @ rd.jacobian_dot_times_v(model, q, v, body, frame)[ROWS[rows]]
    return Lam, mu, Jbar.T @ g, Jbar, J


def _task_rank_ok(model, q, body, frame, rows):
    J = rd.jacobian(model, q, body, frame)[ROWS[rows]]
    return np.linalg.matrix_rank(J) == J.shape[0]


@random_models
@pytest.mark.parametrize("frame", FRAMES)
@pytest.mark.parametrize("rows", ["all", "linear", "angular"])
def test_against_the_formulas(model, frame, rows):
    q, v, _ = states(model, "task", frame, rows)
    body = _body(model)
    if not _task_rank_ok(model, q, body, frame, rows):
        with pytest.raises(ValueError, match="is singular"):
            rd.task_space_inertia(model, q, body, frame, rows)
        return
    Lam, mu, p, Jbar, J = _reference(model, q, v, body, frame, rows)
    assert_rel(rd.task_space_inertia(model, q, body, frame, rows), Lam, 1e-8, "Lambda")
    assert_rel(rd.dynamically_consistent_inverse(model, q, body, frame, rows), Jbar, 1e-8, "Jbar")
    ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
    for name, mine, ref in (("Lambda", ts.Lambda, Lam), ("mu", ts.mu, mu), ("p", ts.p, p), ("Jbar", ts.Jbar, Jbar),
                            ("J", ts.J, J)):
        assert_rel(mine, ref, 1e-8, name)


@pytest.mark.parametrize("model", [m for m in RANDOM_MODELS if m.nv >= 6], ids=lambda m: m.name)
@pytest.mark.parametrize("frame", FRAMES)
def test_task_space_equation_of_motion(model, frame):
    """Joint forces tau = J^T F give the frame x'' = J a + Jdot v with Lambda x'' + mu + p = F;
    Jbar is a right inverse of J and Jbar^T M Jbar = Lambda."""
    q, v, _ = states(model, "eom")
    body = _body(model)
    rows = "all" if _task_rank_ok(model, q, body, frame, "all") else "linear"
    assert _task_rank_ok(model, q, body, frame, rows)
    ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
    m = ts.J.shape[0]
    F = rng_for(model.name, "F").standard_normal(m)
    a = rd.aba(model, q, v, ts.J.T @ F, friction=False)
    xdd = ts.J @ a + rd.jacobian_dot_times_v(model, q, v, body, frame)[ROWS[rows]]
    assert_rel(ts.Lambda @ xdd + ts.mu + ts.p, F, 1e-8)
    assert_rel(ts.J @ ts.Jbar, np.eye(m), 1e-9)
    assert_rel(ts.Jbar.T @ rd.crba(model, q) @ ts.Jbar, ts.Lambda, 1e-8)


def test_point_mass_closed_form():
    """A point mass on three prismatic joints: Lambda = m 1, mu = 0, p = -m g_vec."""
    b = rd.ModelBuilder("xyz")
    b.add_link("world")
    b.add_link("sx")
    b.add_link("sy")
    b.add_link("ball", mass=1.5)
    b.add_joint("x", "prismatic", "world", "sx", axis=(1, 0, 0))
    b.add_joint("y", "prismatic", "sx", "sy", axis=(0, 1, 0))
    b.add_joint("z", "prismatic", "sy", "ball", axis=(0, 0, 1))
    model = b.build()
    ts = rd.task_space_dynamics(model, [0.1, 0.2, 0.3], [1.0, -2.0, 0.5], "ball", rows="linear")
    assert_rel(ts.Lambda, 1.5 * np.eye(3), 1e-12)
    assert_rel(ts.mu, np.zeros(3), 1e-12)
    assert_rel(ts.p, [0.0, 0.0, 1.5 * G], 1e-12)
    assert_rel(ts.Jbar, np.eye(3), 1e-12)


@pytest.mark.parametrize("path, floating_base", pairs())
def test_urdf_against_pinocchio(path, floating_base):
    """Lambda, Jbar, mu and p of the last joint's frame from Pinocchio's computeMinverse,
    getJointJacobian, getJointJacobianTimeVariation, nonLinearEffects and gravity."""
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    q, v, _ = states(model, "urdf-task")
    qp, body = pair.pin_q(q), model.nbodies - 1
    Minv = pin.computeMinverse(pm, data, qp)
    Minv = np.triu(Minv) + np.triu(Minv, 1).T
    pin.computeJointJacobians(pm, data, qp)
    pin.computeJointJacobiansTimeVariation(pm, data, qp, v)
    g = pin.computeGeneralizedGravity(pm, data, qp)
    Cv = pin.nonLinearEffects(pm, data, qp, v) - g
    for frame, rf in JACOBIAN_FRAMES.items():
        J = pin.getJointJacobian(pm, data, pm.njoints - 1, rf)
        rows = "all" if np.linalg.matrix_rank(J) == 6 else "linear"
        J = J[ROWS[rows]]
        if np.linalg.matrix_rank(J) < J.shape[0]:  # a short chain (the double pendulum)
            with pytest.raises(ValueError, match="is singular"):
                rd.task_space_dynamics(model, q, v, body, frame, rows)
            continue
        dJv = (pin.getJointJacobianTimeVariation(pm, data, pm.njoints - 1, rf) @ v)[ROWS[rows]]
        Lam = np.linalg.inv(J @ Minv @ J.T)
        Jbar = Minv @ J.T @ Lam
        ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
        assert_rel(ts.Lambda, Lam, 1e-8, f"Lambda {frame}")
        assert_rel(ts.Jbar, Jbar, 1e-8, f"Jbar {frame}")
        assert_rel(ts.mu, Jbar.T @ Cv - Lam @ dJv, 1e-8, f"mu {frame}")
        assert_rel(ts.p, Jbar.T @ g, 1e-8, f"p {frame}")


def test_short_chain_is_refused():
    """Two joints cannot move a point in three directions: no task-space inertia."""
    pair = load_pair("double_pendulum_description/urdf/double_pendulum_continuous.urdf", False)
    with pytest.raises(ValueError, match=r"task_space_inertia: J M\^-1 J\^T of 1 \(linear rows"):
        rd.task_space_inertia(pair.model, np.zeros(pair.model.nq), 1, rows="linear")


def test_batch_matches_single_states():
    model = rd.random.random_model(8, seed=5, floating_base=True)
    q, v, _ = rd.random.random_state(model, rng_for("task-batch"), (2, 3))
    ts = rd.task_space_dynamics(model, q, v, "body8")
    assert ts.Lambda.shape == (2, 3, 6, 6) and ts.Jbar.shape == (2, 3, model.nv, 6) and ts.mu.shape == (2, 3, 6)
    assert rd.task_space_inertia(model, q, "body8").shape == (2, 3, 6, 6)
    assert rd.dynamically_consistent_inverse(model, q, "body8", rows="angular").shape == (2, 3, model.nv, 3)
    for i in np.ndindex(2, 3):
        one = rd.task_space_dynamics(model, q[i], v[i], "body8")
        for a, b in zip(one, ts):
            assert_rel(b[i], a, 1e-12)


def test_singular_configurations():
    arm = planar_2r(**PLANAR_2R)
    with pytest.raises(ValueError, match=r"task_space_inertia: J M\^-1 J\^T of 'rod2' \(all rows, frame "
                                         r"'local_world_aligned'\) is singular: eigenvalues .*kinematic singularity"):
        rd.task_space_inertia(arm, np.array([0.3, 0.4]), "rod2")
    # a 6-dof chain at a wrist singularity (two wrist axes aligned)
    b = rd.ModelBuilder("chain6")
    b.add_link("l0")
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0)]
    for i, ax in enumerate(axes, start=1):
        b.add_link(f"l{i}", mass=1.0, com=(0.1, 0, 0), inertia=np.eye(3) * 0.01)
        b.add_joint(f"j{i}", "revolute", f"l{i - 1}", f"l{i}", xyz=(0.3 if i > 1 else 0, 0, 0), axis=ax)
    chain = b.build()
    q = np.array([0.1, 0.5, -0.7, 0.3, 0.0, 0.2])  # j4 and j6 aligned when j5 = 0
    with pytest.raises(ValueError, match=r"'l6' \(all rows.* is singular"):
        rd.task_space_dynamics(chain, q, np.zeros(6), "l6")
    with pytest.raises(ValueError, match=r"batch element \(1,\)"):
        rd.task_space_inertia(chain, np.stack([q + 0.3, q]), "l6")
    q[4] = 0.5
    assert np.all(np.isfinite(rd.task_space_inertia(chain, q, "l6")))


def test_bad_input():
    model = rd.random.random_model(8, seed=5, floating_base=True)
    q, v, _ = states(model, "task-bad")
    with pytest.raises(ValueError, match=r"frame must be one of"):
        rd.task_space_inertia(model, q, "body8", frame="base")
    with pytest.raises(ValueError, match=r"rows must be one of \('all', 'linear', 'angular'\), got 'xy'"):
        rd.dynamically_consistent_inverse(model, q, "body8", rows="xy")
    with pytest.raises(ValueError, match=r"unknown link or frame 'nope'"):
        rd.task_space_inertia(model, q, "nope")
    with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\), got \(3,\)"):
        rd.task_space_inertia(model, q[:3], "body8")
    with pytest.raises(ValueError, match=r"task_space_dynamics: v contains NaN or Inf"):
        rd.task_space_dynamics(model, q, np.full(model.nv, np.nan), "body8")
    with pytest.raises(ValueError, match=r"q contains NaN or Inf"):
        rd.task_space_inertia(model, np.full(model.nq, np.nan), "body8")
