"""Controllers and references: the closed-loop behaviour theory predicts (exponential error
decay of computed torque, convergence and Lyapunov decrease of PD with gravity compensation,
task-space PD and Slotine-Li), model mismatch, references and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn import control
from robodyn.random import random_model

from helpers import rng_for


def planar_2r():
    return rd.models.load("planar_2r")


def assert_lyapunov_rate(traj, rate, tol):
    """``V(t) - V(0)`` is the integral of the theoretical ``dV/dt`` (trapezoidal rule)."""
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(traj.t))])
    np.testing.assert_allclose(traj.lyapunov - traj.lyapunov[0], integral, rtol=0, atol=tol * traj.lyapunov[0])


@pytest.mark.parametrize("model", [planar_2r(), random_model(5, seed=4, branching=0.5)], ids=["planar_2r", "tree5"])
def test_computed_torque_error_decays_at_the_rate_of_the_gains(model):
    """Exact model: each joint's error solves e'' + 2 w e' + w^2 e = 0, so
    e(t) = (e0 + w e0 t) exp(-w t) from rest, with w set per joint by the gains."""
    rng = rng_for(model.name, "ct")
    q_start, q_end = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    reference = control.quintic(q_start, q_end, 1.0)
    w = np.linspace(6.0, 12.0, model.nv)
    ct = control.ComputedTorque(model, reference, kp=w ** 2, kd=2 * w)
    e0 = rng.uniform(-0.05, 0.05, model.nv)
    traj = rd.simulate(model, q_start - e0, np.zeros(model.nv), 1.5, 1e-3, controller=ct)
    e = traj.q_desired - traj.q
    expected = (e0 + w * e0 * traj.t[:, None]) * np.exp(-w * traj.t[:, None])
    np.testing.assert_allclose(e, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.q_desired[-1], q_end, rtol=0, atol=1e-15)
    assert np.all(np.diff(traj.lyapunov) <= 1e-12 * traj.lyapunov[0])


def test_computed_torque_with_model_mismatch_tracks_less_well():
    plant = planar_2r()
    wrong = plant.with_inertial_parameters(1.2 * plant.inertial_parameters())
    reference = control.quintic([0.0, 0.0], [1.0, -0.5], 1.0)
    exact = rd.simulate(plant, [0.0, 0.0], [0.0, 0.0], 1.0, 1e-3,
                        controller=control.ComputedTorque(plant, reference, kp=100.0, kd=20.0))
    mismatch = rd.simulate(plant, [0.0, 0.0], [0.0, 0.0], 1.0, 1e-3,
                           controller=control.ComputedTorque(wrong, reference, kp=100.0, kd=20.0))
    assert np.abs(exact.tracking_error).max() < 1e-9
    assert 1e-4 < np.abs(mismatch.tracking_error).max() < 0.1


def test_pd_gravity_converges_and_its_lyapunov_function_decreases():
    model = planar_2r()
    q_goal = np.array([0.8, -0.6])
    kp, kd = np.array([600.0, 300.0]), np.array([150.0, 60.0])
    pd = control.PDGravity(model, q_goal, kp, kd)
    traj = rd.simulate(model, [0.0, 0.3], [0.5, 0.0], 3.0, 1e-3, controller=pd)
    assert np.abs(traj.q[-1] - q_goal).max() < 1e-4 and np.abs(traj.v[-1]).max() < 1e-3
    assert np.all(np.diff(traj.lyapunov) <= 1e-9 * traj.lyapunov[0])
    # dV/dt = -qd^T Kd qd (no friction)
    assert_lyapunov_rate(traj, -np.sum(kd * traj.v ** 2, axis=1), 1e-4)
    e = q_goal - traj.q[0]
    expected_v0 = 0.5 * traj.v[0] @ rd.crba(model, traj.q[0]) @ traj.v[0] + 0.5 * e @ (kp * e)
    assert traj.lyapunov[0] == pytest.approx(expected_v0, rel=1e-12)


def test_pd_gravity_with_wrong_gravity_settles_where_the_springs_balance_it():
    """Model mismatch: the steady state satisfies Kp (q_d - q) = g_plant(q) - g_model(q)."""
    plant = planar_2r()
    wrong = plant.with_inertial_parameters(0.8 * plant.inertial_parameters())
    kp = np.array([800.0, 400.0])
    pd = control.PDGravity(wrong, [0.5, 0.5], kp, [200.0, 80.0])
    traj = rd.simulate(plant, [0.5, 0.5], [0.0, 0.0], 3.0, 1e-3, controller=pd)
    q = traj.q[-1]
    assert np.abs(q - [0.5, 0.5]).max() > 1e-3  # an offset remains
    np.testing.assert_allclose(kp * (0.5 - q), rd.gravity(plant, q) - rd.gravity(wrong, q), rtol=1e-5, atol=1e-6)


def test_slotine_li_tracks_and_its_lyapunov_function_decreases():
    model = random_model(4, seed=8, branching=0.5)
    rng = rng_for("slotine-li")
    q_start, q_end = rng.uniform(-1, 1, model.nv), rng.uniform(-1, 1, model.nv)
    reference = control.quintic(q_start, q_end, 1.0)
    lam, kd = np.full(model.nv, 5.0), np.full(model.nv, 20.0)
    sl = control.SlotineLi(model, reference, lam, kd)
    traj = rd.simulate(model, q_start + 0.1, np.zeros(model.nv), 1.5, 1e-3, controller=sl)
    assert np.abs(traj.tracking_error[-1]).max() < 0.1 * np.abs(traj.tracking_error[0]).max()
    assert np.all(np.diff(traj.lyapunov) <= 1e-9 * traj.lyapunov[0])
    # dV/dt = -q~'^T Kd q~' - q~^T Lambda Kd Lambda q~
    e = -traj.tracking_error
    ed = traj.v - traj.v_desired
    rate = -np.sum(kd * ed ** 2 + lam * kd * lam * e ** 2, axis=1)
    assert_lyapunov_rate(traj, rate, 1e-4)


def test_slotine_li_feedforward_is_m_qdd_r_plus_c_qd_r_plus_g():
    model = random_model(6, seed=9, branching=0.5)
    rng = rng_for("feedforward")
    sl = control.SlotineLi(model, control.quintic(np.zeros(model.nv), np.ones(model.nv), 1.0), 2.0, 3.0)
    q, v, v_r, a_r = (rng.standard_normal(model.nv) for _ in range(4))
    expected = rd.crba(model, q) @ a_r + rd.coriolis_matrix(model, q, v) @ v_r + rd.gravity(model, q)
    np.testing.assert_allclose(sl.feedforward(q, v, v_r, a_r), expected, rtol=1e-10, atol=1e-10)


def test_task_space_pd_reaches_the_point():
    panda = rd.models.load("panda")
    q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7])
    frame = "flange"
    x0 = rd.frame_pose(panda, q0, frame)[:3, 3]
    ts = control.TaskSpacePD(panda, frame, x0 + [0.1, 0.05, -0.1], kp=400.0, kd=60.0, joint_damping=2.0)
    traj = rd.simulate(panda, q0, np.zeros(7), 2.0, 1e-3, controller=ts)
    assert np.abs(ts.position(traj.q[-1]) - ts.x_d).max() < 1e-3
    assert np.all(np.diff(traj.lyapunov) <= 1e-9 * traj.lyapunov[0])
    assert np.all(np.abs(traj.tau) <= panda.effort_limit)


@pytest.mark.parametrize("profile", ["cubic", "quintic"])
def test_point_to_point_references(profile):
    q0, q1, T, t0 = np.array([0.2, -1.0]), np.array([1.0, 0.5]), 2.0, 0.5
    ref = control.PointToPoint(q0, q1, T, profile, t0)
    for t, q in ((t0, q0), (t0 + T, q1), (0.0, q0), (10.0, q1)):
        pos, vel, acc = ref(t)
        np.testing.assert_allclose(pos, q, rtol=0, atol=1e-15)
        np.testing.assert_allclose(vel, 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ref(t0 + T / 2)[0], (q0 + q1) / 2, rtol=0, atol=1e-15)
    if profile == "quintic":
        np.testing.assert_allclose(ref(t0 + 1e-9)[2], 0.0, atol=1e-6)
    else:  # cubic: acceleration 6 (q1 - q0) / T^2 at the start
        np.testing.assert_allclose(ref(t0 + 1e-12)[2], 6 * (q1 - q0) / T ** 2, rtol=1e-9)
    h = 1e-6
    for t in (0.9, 1.7, 2.3):
        np.testing.assert_allclose(ref(t)[1], (ref(t + h)[0] - ref(t - h)[0]) / (2 * h), rtol=0, atol=1e-8)
        np.testing.assert_allclose(ref(t)[2], (ref(t + h)[1] - ref(t - h)[1]) / (2 * h), rtol=0, atol=1e-7)


def test_sampled_reference_interpolates(tmp_path):
    t = np.linspace(0.0, 1.0, 11)
    q = np.stack([t ** 3 - t, 2 * t ** 2], axis=1)  # a cubic spline reproduces cubics exactly
    ref = control.Sampled(t, q)
    for s in (0.05, 0.5, 0.93):
        pos, vel, acc = ref(s)
        np.testing.assert_allclose(pos, [s ** 3 - s, 2 * s ** 2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(vel, [3 * s ** 2 - 1, 4 * s], rtol=0, atol=1e-10)
        np.testing.assert_allclose(acc, [6 * s, 4.0], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(ref(2.0)[0], q[-1])
    path = tmp_path / "ref.csv"
    np.savetxt(path, np.column_stack([t, q]), delimiter=",", header="t,q:joint1,q:joint2", comments="")
    from_file = control.Sampled.from_csv(path, rd.models.load("double_pendulum"))
    np.testing.assert_allclose(from_file(0.5)[0], ref(0.5)[0], rtol=0, atol=1e-15)


def test_bad_input():
    model = planar_2r()
    ref = control.quintic([0, 0], [1, 1], 1.0)
    with pytest.raises(ValueError, match=r"kp: gains must be finite and > 0"):
        control.PDGravity(model, [0, 0], -1.0, 1.0)
    with pytest.raises(ValueError, match=r"kd: expected a positive number or shape \(2,\)"):
        control.ComputedTorque(model, ref, 1.0, [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"q_desired: expected \(2,\)"):
        control.PDGravity(model, [0, 0, 0], 1.0, 1.0)
    with pytest.raises(ValueError, match=r"reference: q_d has shape \(3,\), expected \(2,\)"):
        control.SlotineLi(model, control.quintic([0, 0, 0], [1, 1, 1], 1.0), 1.0, 1.0)
    with pytest.raises(ValueError, match=r"reference: expected a callable"):
        control.ComputedTorque(model, [0, 0], 1.0, 1.0)
    with pytest.raises(ValueError, match=r"fixed-base model"):
        control.PDGravity(random_model(2, seed=0, floating_base=True), np.zeros(8), 1.0, 1.0)
    with pytest.raises(ValueError, match=r"unknown link or frame 'nope'"):
        control.TaskSpacePD(model, "nope", [0, 0, 0], 1.0, 1.0)
    with pytest.raises(ValueError, match=r"profile: expected 'cubic' or 'quintic'"):
        control.PointToPoint([0], [1], 1.0, "septic")
    with pytest.raises(ValueError, match=r"duration: must be finite and > 0"):
        control.quintic([0], [1], 0.0)
    with pytest.raises(ValueError, match=r"q1: expected shape \(1,\)"):
        control.cubic([0], [1, 2], 1.0)
    with pytest.raises(ValueError, match=r"strictly increasing"):
        control.Sampled([0.0, 0.0], [[0.0], [1.0]])


def test_task_space_jacobian_is_the_library_one():
    panda = rd.models.load("panda")
    ts = control.TaskSpacePD(panda, "flange", [0.3, 0.0, 0.5], 1.0, 1.0)
    q = rng_for("ts-jacobian").uniform(-1, 1, 7)
    x, Jl = ts.position_and_jacobian(q)
    np.testing.assert_allclose(x, rd.frame_pose(panda, q, "flange")[:3, 3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(Jl, rd.jacobian(panda, q, "flange", "local_world_aligned")[:3], rtol=0, atol=1e-13)


@pytest.mark.parametrize("integrator", ["rk4", "semi_implicit_euler", "DOP853"])
def test_pid_integral_state_removes_the_offset_of_a_wrong_gravity_model(integrator):
    """The controller's internal state is integrated with the robot: z(t) is the integral of
    the error, and the integral action cancels the gravity error PD alone leaves."""
    plant = planar_2r()
    wrong = plant.with_inertial_parameters(0.8 * plant.inertial_parameters())
    pid = control.PIDGravity(wrong, [0.5, 0.5], kp=[800.0, 400.0], ki=[1500.0, 600.0], kd=[200.0, 80.0])
    if integrator == "DOP853":  # adaptive: agrees with RK4 on a short run
        traj = rd.simulate(plant, [0.5, 0.5], [0.0, 0.0], 0.05, 1e-3, controller=pid, integrator=integrator)
        rk4 = rd.simulate(plant, [0.5, 0.5], [0.0, 0.0], 0.05, 1e-3, controller=pid)
        np.testing.assert_allclose(traj.controller_state, rk4.controller_state, rtol=0,
                                   atol=1e-7 * np.abs(rk4.controller_state).max())
    else:
        traj = rd.simulate(plant, [0.5, 0.5], [0.0, 0.0], 4.0, 1e-3, controller=pid, integrator=integrator)
        e = 0.5 - traj.q
        integral = np.concatenate([[np.zeros(2)], np.cumsum(0.5 * (e[1:] + e[:-1]) * 1e-3, axis=0)])
        tol = 1e-3 if integrator == "semi_implicit_euler" else 1e-6
        np.testing.assert_allclose(traj.controller_state, integral, rtol=0, atol=tol * np.abs(integral).max())
        assert np.abs(e[-1]).max() < 1e-3
        np.testing.assert_allclose(pid.ki * traj.controller_state[-1], rd.gravity(plant, traj.q[-1])
                                   - rd.gravity(wrong, traj.q[-1]), rtol=2e-2)
    np.testing.assert_allclose(traj.tau[5], pid.torque(traj.t[5], traj.q[5], traj.v[5], traj.controller_state[5]),
                               rtol=1e-12)


def test_bad_controller_state():
    class Broken(control.PIDGravity):
        def state_rate(self, t, q, v, z):
            return np.zeros(3)

    model = planar_2r()
    with pytest.raises(ValueError, match=r"controller: state_rate returned shape \(3,\) at t = 0"):
        rd.simulate(model, [0, 0], [0, 0], 0.01, 1e-3, controller=Broken(model, [0, 0], 1.0, 1.0, 1.0))


@pytest.mark.parametrize("integrator", ["rk4", "semi_implicit_euler"])
@pytest.mark.parametrize("case", ["pd-gravity", "quintic", "cubic", "sampled"])
def test_compiled_controllers_match_their_python_law(case, integrator):
    """PDGravity and ComputedTorque run compiled in simulate; the same law called from Python
    (wrapped in a lambda) gives the same motion. Plant and controller models differ, both
    with friction and armature."""
    from helpers import with_friction_and_armature

    rng = rng_for("compiled", case)
    plant = with_friction_and_armature(random_model(5, seed=11, branching=0.5), rng, smoothing=0.05)
    model = plant.with_inertial_parameters(1.1 * plant.inertial_parameters())
    q0, q1 = rng.uniform(-1, 1, 5), rng.uniform(-1, 1, 5)
    if case == "pd-gravity":
        ctrl = control.PDGravity(model, q1, kp=20.0, kd=np.linspace(2.0, 4.0, 5))
    else:
        ref = {"quintic": lambda: control.quintic(q0, q1, 0.2, t0=0.05), "cubic": lambda: control.cubic(q0, q1, 0.2),
               "sampled": lambda: control.Sampled(np.linspace(0.0, 0.25, 6), rng.uniform(-1, 1, (6, 5)))}[case]()
        ctrl = control.ComputedTorque(model, ref, kp=np.linspace(50.0, 100.0, 5), kd=15.0)
    assert ctrl.kernel_law() is not None
    a = rd.simulate(plant, q0, np.zeros(5), 0.3, 1e-3, controller=ctrl, integrator=integrator)
    b = rd.simulate(plant, q0, np.zeros(5), 0.3, 1e-3, controller=lambda t, q, v: ctrl(t, q, v), integrator=integrator)
    for key in ("q", "v", "a", "tau"):
        x, y = getattr(a, key), getattr(b, key)
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-10 * max(1.0, np.abs(y).max()), err_msg=key)
    assert a.lyapunov is not None and a.q_desired is not None
    np.testing.assert_allclose(a.tau[7], ctrl(a.t[7], a.q[7], a.v[7]), rtol=1e-12, atol=1e-12)


def test_subclasses_with_their_own_law_run_in_python():
    class Softer(control.PDGravity):
        def __call__(self, t, q, v):
            return 0.5 * super().__call__(t, q, v)

    model = planar_2r()
    assert Softer(model, [0, 0], 1.0, 1.0).kernel_law() is None
    assert control.ComputedTorque(model, lambda t: (np.zeros(2),) * 3, 1.0, 1.0).kernel_law() is None
    assert control.SlotineLi(model, control.quintic([0, 0], [1, 1], 1.0), 1.0, 1.0).kernel_law() is None


@pytest.mark.parametrize("make", [lambda m: control.PDGravity(m, [0.3, -0.2], [50.0, 20.0], [10.0, 5.0]),
                                  lambda m: control.ComputedTorque(m, control.cubic([0, 0], [1, -1], 0.3), 30.0, 9.0),
                                  lambda m: control.SlotineLi(m, control.Sampled([0, 0.1, 0.3], [[0, 0], [0.2, 0.1],
                                                                                                 [0.5, -0.4]]), 3.0, 5.0)],
                         ids=["pd-gravity", "computed-torque", "slotine-li"])
def test_lyapunov_and_reference_of_a_whole_trajectory(make):
    """The vectorized evaluation after a run equals the evaluation sample by sample."""
    model = planar_2r()
    ctrl = make(model)
    assert ctrl.vectorized
    traj = rd.simulate(model, [0.1, 0.1], [0.0, 0.0], 0.4, 2e-3, controller=ctrl)
    one_by_one = [ctrl.lyapunov(t, q, v) for t, q, v in zip(traj.t, traj.q, traj.v)]
    np.testing.assert_allclose(traj.lyapunov, one_by_one, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(traj.q_desired, [ctrl.desired(t)[0] for t in traj.t], rtol=0, atol=1e-14)
    np.testing.assert_allclose(traj.v_desired, [ctrl.desired(t)[1] for t in traj.t], rtol=0, atol=1e-12)
