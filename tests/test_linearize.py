"""robodyn.linearize: the (A, B) of one simulate step against differences of simulate itself
(both integrators, fixed and floating bases, viscous and smoothed Coulomb friction, armature,
clipped and unactuated joints), batches, bad input, and the LQR and iLQR examples it serves."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from helpers import assert_rel, richardson, rng_for
from robodyn.random import random_model, random_state

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

DT = 0.01
STEP = 1e-4
# Richardson-extrapolated central differences (steps h, h/2): error O(h^4) ~ 1e-16 times the
# step's fifth derivative, plus rounding eps |x| / h ~ 1e-12; the tolerance keeps a margin of 100.
TOL = 1e-8


def one_step(model, q, v, tau, integrator):
    """``(q+, v+)`` of :func:`robodyn.simulate` under the constant joint force ``tau``."""
    traj = rd.simulate(model, q, v, DT, DT, lambda t, q_, v_: tau, integrator, progress=False)
    return traj.q[-1], traj.v[-1]


def by_differences(model, q, v, tau, integrator):
    """``(A, B)`` by differences of :func:`one_step` in tangent coordinates."""
    q1, v1 = one_step(model, q, v, tau, integrator)
    n = model.nv

    def moved(d):
        qp, vp = one_step(model, rd.integrate(model, q, d[:n]), v + d[n:2 * n], tau + d[2 * n:], integrator)
        return np.concatenate([rd.difference(model, q1, qp), vp - v1])

    J = richardson(moved, 3 * n, STEP)
    return J[:, :2 * n], J[:, 2 * n:]


ONE_DOF, MIXED = (J.REVOLUTE, J.PRISMATIC), (J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL, J.PLANAR)
CASES = [(4, 1, False, "semi_implicit_euler", ONE_DOF), (4, 1, False, "rk4", ONE_DOF),
         (5, 2, True, "semi_implicit_euler", ONE_DOF), (5, 2, True, "rk4", ONE_DOF),
         (3, 3, True, "semi_implicit_euler", ONE_DOF), (3, 3, True, "rk4", ONE_DOF),
         (4, 13, False, "semi_implicit_euler", MIXED), (4, 13, False, "rk4", MIXED), (4, 24, True, "rk4", MIXED)]


@pytest.mark.parametrize("n, seed, floating_base, integrator, joint_types", CASES)
def test_against_differences_of_simulate(n, seed, floating_base, integrator, joint_types):
    rng = rng_for("linearize", n, seed, floating_base, integrator)
    base = random_model(n, seed=seed, floating_base=floating_base, branching=0.5, joint_types=joint_types)
    assert all(kind in base.joint_type for kind in (J.SPHERICAL, J.PLANAR)) == (joint_types == MIXED)
    model = base.replace(damping=rng.uniform(0.1, 1.0, base.nv), armature=rng.uniform(0.01, 0.1, base.nv),
                         coulomb=rng.uniform(0.1, 1.0, base.nv), coulomb_smoothing=0.5)
    q, v, tau = random_state(model, rng)
    A, B = rd.linearize(model, q, v, tau, DT, integrator)
    fd_A, fd_B = by_differences(model, q, v, tau, integrator)
    assert A.shape == (2 * model.nv, 2 * model.nv) and B.shape == (2 * model.nv, model.nv)
    assert_rel(A, fd_A, TOL, "A")
    assert_rel(B, fd_B, TOL, "B")


@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "rk4"])
def test_fast_spinning_base(integrator):
    """A base turning at 60 rad/s turns 0.3-0.6 rad within a step: the closed forms of the
    chart's Jacobians, not their small-angle series; a large torque on it turns its angular
    velocity within the step, so that the stages' rotation vectors leave its direction."""
    model = random_model(3, seed=7, floating_base=True)
    q, v, tau = random_state(model, rng_for("spin", integrator))
    v[3:6] = [40.0, -30.0, 30.0]
    tau[3:6] = 1e3 * np.array([1.0, 2.0, -1.5]) * model.total_mass
    A, B = rd.linearize(model, q, v, tau, DT, integrator)
    fd_A, fd_B = by_differences(model, q, v, tau, integrator)
    assert_rel(A, fd_A, TOL, "A")
    assert_rel(B, fd_B, TOL, "B")


@pytest.mark.parametrize("floating_base", [False, True])
@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "rk4"])
def test_clipped_and_unactuated_joints_have_no_input(floating_base, integrator):
    model = random_model(3, seed=4, floating_base=floating_base)
    q, v, tau = random_state(model, rng_for("clip", floating_base, integrator))
    limit = np.abs(tau) * 2.0
    limit[-2] = np.abs(tau[-2]) / 2.0  # saturated
    limit[-1], tau[-1] = 0.0, 0.0  # unactuated: no force whatever the command
    limited = model.replace(effort_limit=limit)
    A, B = rd.linearize(limited, q, v, tau, DT, integrator)
    fd_A, fd_B = by_differences(limited, q, v, tau, integrator)
    assert_rel(A, fd_A, TOL, "A")
    assert_rel(B, fd_B, TOL, "B")
    assert np.all(B[:, -2:] == 0) and np.all(np.any(B[:, :-2] != 0, axis=0))


def test_batch():
    model = random_model(4, seed=5, floating_base=True)
    Q, V, T = random_state(model, rng_for("batch"), (2, 3))
    A, B = rd.linearize(model, Q, V, T, DT)
    assert A.shape == (2, 3, 2 * model.nv, 2 * model.nv) and B.shape == (2, 3, 2 * model.nv, model.nv)
    for i in np.ndindex(2, 3):
        a, b = rd.linearize(model, Q[i], V[i], T[i], DT)
        assert_rel(A[i], a, 1e-12)
        assert_rel(B[i], b, 1e-12)


def test_bad_input():
    model = random_model(3, seed=6, floating_base=True)
    q, v, tau = random_state(model, rng_for("bad"))
    with pytest.raises(ValueError, match="integrator: unknown 'euler'"):
        rd.linearize(model, q, v, tau, DT, "euler")
    for dt in (0.0, -1.0, np.nan, "0.1", True):
        with pytest.raises(ValueError, match="dt: expected a positive number"):
            rd.linearize(model, q, v, tau, dt)
    with pytest.raises(ValueError, match="v: expected an array of numbers, got str"):
        rd.linearize(model, q, "abc", tau, DT)
    bad = q.copy()
    bad[3:7] *= 2.0
    with pytest.raises(ValueError, match=r"linearize: q: quaternion q\[3:7\] has norm 2, not 1"):
        rd.linearize(model, bad, v, tau, DT)
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 10\), got \(9,\)"):
        rd.linearize(model, q[:-1], v, tau, DT)
    with pytest.raises(ValueError, match="do not broadcast"):
        rd.linearize(model, np.stack([q] * 2), np.stack([v] * 3), tau, DT)
    with pytest.raises(ValueError, match=r"linearize: v contains NaN or Inf \(first at index \(0,\)\)"):
        rd.linearize(model, q, np.full(model.nv, np.nan), tau, DT)
    with pytest.raises(ValueError, match=r"linearize: tau contains NaN or Inf"):
        rd.linearize(model, q, v, np.full(model.nv, np.inf), DT)
    with pytest.raises(ValueError, match=r"\btau\b"):
        rd.linearize(model, q, v, tau[:-1], DT)


def test_lqr_acrobot_example_keeps_the_acrobot_upright():
    import lqr_acrobot

    model = lqr_acrobot.acrobot()
    _, B = rd.linearize(model, np.zeros(2), np.zeros(2), np.zeros(2), lqr_acrobot.DT)
    assert np.all(B[:, 0] == 0) and np.all(B[2:, 1] != 0)  # no shoulder motor: effort limit 0
    _, eigenvalues = lqr_acrobot.lqr_gain(model)
    assert np.abs(eigenvalues).max() < 1.0
    traj = lqr_acrobot.run()
    assert np.abs(traj.q).max() > 0.1  # the push moved it
    assert np.abs(traj.q[-1]).max() < 1e-6 and np.abs(traj.v[-1]).max() < 1e-6


def test_ilqr_example_swings_the_double_pendulum_up():
    import ilqr_double_pendulum as ex

    X, U, costs = ex.swing_up()
    assert np.all(np.diff(costs) < 0)  # every accepted iteration lowers the cost
    assert costs[-1] < 1e-3 * costs[0]
    assert np.abs(X[-1]).max() < 0.01  # upright at rest at the end
    # the example's rollout is the simulator's semi-implicit Euler step under the held inputs
    model = rd.models.load("double_pendulum")
    traj = rd.simulate(model, X[0, :2], X[0, 2:], ex.DT * ex.HORIZON, ex.DT,
                       lambda t, q, v: U[min(int(round(t / ex.DT)), ex.HORIZON - 1)], "semi_implicit_euler",
                       progress=False)
    assert_rel(np.hstack([traj.q, traj.v]), X, 1e-9)


def test_lqr_panda_example_returns_to_the_pose_after_a_push():
    import lqr_panda as ex

    model = rd.models.load("panda")
    _, eigenvalues = ex.lqr_gain(model, ex.POSE)
    assert np.abs(eigenvalues).max() < 1.0
    traj = ex.run()
    err = np.abs(traj.q - ex.POSE).max(axis=1)
    assert err.max() > 0.01 and err[-1] < 1e-6 and np.abs(traj.v[-1]).max() < 1e-6
    assert np.all(np.abs(traj.tau).max(axis=0) < 0.9 * model.effort_limit)  # never near clipping
