"""simulate: energy and momentum conservation, closed forms, order of accuracy, agreement
between integrators and between the compiled and Python-driven paths, torque limits,
friction, CSV round trip, progress bar and bad input."""

from __future__ import annotations

import io

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import robodyn as rd
from robodyn import control
from robodyn.io.log import write_log
from robodyn.random import random_model, random_state
from robodyn.simulation import read_trajectory
from robodyn.simulation.simulate import Progress

from helpers import G, pendulum, rng_for

PANDA_Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7])


def zero_torque(model):
    z = np.zeros(model.nv)
    return lambda t, q, v: z


def test_panda_energy_is_conserved():
    """No torque, no friction: 2 s at dt = 1 ms with RK4 keeps the total energy within 1e-6."""
    panda = rd.models.load("panda")
    assert not np.any(panda.damping) and not np.any(panda.coulomb)
    v0 = np.array([0.5, -0.3, 0.4, 0.2, -0.6, 0.5, 1.0])
    traj = rd.simulate(panda, PANDA_Q0, v0, 2.0, 1e-3, integrator="rk4")
    assert traj.t.shape == (2001,) and traj.t[-1] == pytest.approx(2.0)
    assert abs(traj.energy[0]) > 10.0  # a relative criterion on a sizeable energy
    assert np.abs(traj.energy - traj.energy[0]).max() <= 1e-6 * abs(traj.energy[0])
    assert np.ptp(traj.kinetic) > 1.0  # the arm did move: energy was exchanged
    # the recorded quantities are those of the states
    np.testing.assert_allclose(traj.kinetic, rd.kinetic_energy(panda, traj.q, traj.v), rtol=1e-12)
    np.testing.assert_allclose(traj.a, rd.aba(panda, traj.q, traj.v, traj.tau), rtol=1e-12, atol=1e-12)


def spatial_momentum(model, q, v, about):
    """Linear momentum (3,) and angular momentum (3,) about the point ``about`` (world)."""
    T = rd.forward_kinematics(model, q)
    lin, ang = np.zeros(3), np.zeros(3)
    for i in range(model.nbodies):
        theta = model.theta[i]
        m, R, p = theta[0], T[i, :3, :3], T[i, :3, 3]
        if m == 0:
            continue
        c_local = theta[1:4] / m
        Io = np.array([[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]])
        Ic = Io - m * (c_local @ c_local * np.eye(3) - np.outer(c_local, c_local))
        twist = rd.jacobian(model, q, i, "world") @ v  # [velocity of the point at the origin, omega]
        c = p + R @ c_local
        cdot = twist[:3] + np.cross(twist[3:], c)
        lin += m * cdot
        ang += R @ Ic @ R.T @ twist[3:] + m * np.cross(c - about, cdot)
    return lin, ang


@pytest.mark.parametrize("gravity", [True, False], ids=["gravity", "no-gravity"])
@pytest.mark.parametrize("seed", [5, 7])
def test_floating_base_free_fall_keeps_momentum(seed, gravity):
    """A floating tree without joint torques: linear momentum changes by m g t (zero without
    gravity), angular momentum about the centre of mass is conserved."""
    model = random_model(6, seed=seed, floating_base=True, branching=0.5)
    if not gravity:
        model = model.replace(gravity=np.zeros(3))
    q0, v0, _ = random_state(model, rng_for("fall", seed))
    traj = rd.simulate(model, q0, v0, 0.5, 1e-3)
    mass = model.total_mass
    lin0, ang0 = spatial_momentum(model, q0, v0, rd.center_of_mass(model, q0))
    scale = max(np.linalg.norm(lin0), np.linalg.norm(ang0), mass * G * 0.5)
    for k in (100, 250, 500):
        q, v, t = traj.q[k], traj.v[k], traj.t[k]
        lin, ang = spatial_momentum(model, q, v, rd.center_of_mass(model, q))
        np.testing.assert_allclose(lin, lin0 + mass * model.gravity * t, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(ang, ang0, rtol=0, atol=1e-8 * scale)
    quats = traj.q[:, 3:7]
    np.testing.assert_allclose(np.linalg.norm(quats, axis=1), 1.0, rtol=0, atol=1e-14)
    assert np.ptp(traj.energy) <= 1e-8 * (abs(traj.energy[0]) + np.abs(traj.kinetic).max())


def test_pendulum_matches_its_equation():
    """The pendulum from the textbook ODE m L^2 qdd = m g L sin(q), solved by SciPy."""
    m, L = 2.0, 0.7
    model = pendulum(m, L)
    traj = rd.simulate(model, [0.4], [0.0], 1.0, 1e-3)
    ref = solve_ivp(lambda t, y: [y[1], G / L * np.sin(y[0])], (0, 1.0), [0.4, 0.0], t_eval=traj.t,
                    rtol=1e-12, atol=1e-12, method="DOP853")
    np.testing.assert_allclose(traj.q[:, 0], ref.y[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.v[:, 0], ref.y[1], rtol=0, atol=1e-8)


def test_rk4_is_fourth_order_on_the_manifold():
    """Halving dt divides the error of a floating-base run by about 2^4."""
    model = random_model(5, seed=3, floating_base=True, branching=0.5)
    q0, v0, _ = random_state(model, rng_for("order"))
    fine = rd.simulate(model, q0, v0, 0.2, 2.5e-4)
    errors = [np.abs(rd.difference(model, fine.q[-1], rd.simulate(model, q0, v0, 0.2, dt).q[-1])).max()
              for dt in (4e-3, 2e-3)]
    assert 12.0 < errors[0] / errors[1] < 20.0, errors


@pytest.mark.parametrize("integrator", ["rk4", "semi_implicit_euler"])
def test_compiled_and_python_paths_agree(integrator):
    """controller=None runs compiled; a Python callable returning zeros is the same motion."""
    model = random_model(4, seed=2, floating_base=True, branching=0.5)
    q0, v0, _ = random_state(model, rng_for("paths"))
    a = rd.simulate(model, q0, v0, 0.1, 1e-3, integrator=integrator)
    b = rd.simulate(model, q0, v0, 0.1, 1e-3, controller=zero_torque(model), integrator=integrator)
    for key in ("q", "v", "a", "tau", "energy"):
        np.testing.assert_allclose(getattr(a, key), getattr(b, key), rtol=0, atol=1e-12)


@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "RK45", "DOP853", "Radau"])
def test_integrators_agree_with_rk4(integrator):
    model = random_model(4, seed=6, floating_base=True, branching=0.5)
    q0, v0, _ = random_state(model, rng_for("integrators"))
    ref = rd.simulate(model, q0, v0, 0.05, 1e-3)
    traj = rd.simulate(model, q0, v0, 0.05, 1e-3, integrator=integrator)
    tol = 1e-3 if integrator == "semi_implicit_euler" else 1e-7
    assert np.abs(rd.difference(model, ref.q, traj.q)).max() < tol
    assert np.abs(traj.v - ref.v).max() < 100 * tol
    assert traj.integrator == integrator


def test_semi_implicit_euler_is_first_order():
    model = rd.models.load("double_pendulum")
    q0, v0 = np.array([0.3, -0.2]), np.zeros(2)
    ref = rd.simulate(model, q0, v0, 0.2, 1e-4)
    e = [np.abs(rd.simulate(model, q0, v0, 0.2, dt, integrator="semi_implicit_euler").q[-1] - ref.q[-1]).max()
         for dt in (2e-3, 1e-3)]
    assert 1.6 < e[0] / e[1] < 2.4, e


def test_torques_are_clipped_to_the_effort_limits():
    model = rd.models.load("double_pendulum").replace(effort_limit=[3.0, 1.0])
    command = np.array([10.0, -5.0])
    traj = rd.simulate(model, [0.1, 0.2], [0.0, 0.0], 0.05, 1e-3, controller=lambda t, q, v: command)
    np.testing.assert_array_equal(traj.tau, np.tile([3.0, -1.0], (traj.t.shape[0], 1)))
    np.testing.assert_allclose(traj.a, rd.aba(model, traj.q, traj.v, traj.tau), rtol=1e-12, atol=1e-12)


def test_friction_dissipates_the_energy_it_should():
    """dE/dt = -v^T (damping v + coulomb tanh(v / eps)) without torques."""
    base = rd.models.load("double_pendulum")
    model = base.replace(damping=[0.3, 0.2], coulomb=[0.1, 0.05], coulomb_smoothing=0.01)
    traj = rd.simulate(model, [0.5, -0.3], [1.0, 0.0], 1.0, 1e-3)
    power = -np.sum(traj.v * (model.damping * traj.v + model.coulomb * np.tanh(traj.v / 0.01)), axis=1)
    dE = np.gradient(traj.energy, traj.t)
    np.testing.assert_allclose(dE[5:-5], power[5:-5], rtol=0, atol=1e-4 * np.abs(power).max())
    assert traj.energy[-1] < traj.energy[0] - 0.1


def test_armature_energy_is_counted():
    model = rd.models.load("double_pendulum").replace(armature=[0.05, 0.02])
    traj = rd.simulate(model, [0.5, -0.3], [1.0, 0.5], 0.5, 1e-3)
    assert np.ptp(traj.energy) < 1e-9 * abs(traj.energy).max()
    np.testing.assert_allclose(traj.kinetic, rd.kinetic_energy(model, traj.q, traj.v)
                               + 0.5 * (traj.v ** 2) @ model.armature, rtol=1e-12)


def test_csv_round_trip(tmp_path):
    model = random_model(3, seed=1, floating_base=True)
    q0, v0, _ = random_state(model, rng_for("csv"))
    traj = rd.simulate(model, q0, v0, 0.02, 1e-3)
    path = tmp_path / "traj.csv"
    traj.to_csv(path)
    t, q, v, a = read_trajectory(path, model)
    for mine, theirs in ((t, traj.t), (q, traj.q), (v, traj.v), (a, traj.a)):
        np.testing.assert_allclose(mine, theirs, rtol=1e-15, atol=0)


def test_csv_with_positions_only_is_differentiated(tmp_path):
    model = rd.models.load("double_pendulum")
    t = np.linspace(0, 1, 201)
    q = np.stack([np.sin(2 * t), t ** 3], axis=1)
    path = tmp_path / "q.csv"
    np.savetxt(path, np.column_stack([t, q]), delimiter=",", header="t,q:joint1,q:joint2", comments="")
    _, q_read, v, a = read_trajectory(path, model)
    np.testing.assert_allclose(q_read, q, rtol=0, atol=1e-15)
    np.testing.assert_allclose(v[20:-20], np.stack([2 * np.cos(2 * t), 3 * t ** 2], 1)[20:-20], rtol=0, atol=1e-5)
    np.testing.assert_allclose(a[20:-20], np.stack([-4 * np.sin(2 * t), 6 * t], 1)[20:-20], rtol=0, atol=1e-3)


def test_csv_with_velocities_only_gets_the_accelerations(tmp_path):
    """v given, a not: v is read as written, a comes from the spline through q."""
    model = rd.models.load("double_pendulum")
    t = np.linspace(0, 1, 201)
    q = np.stack([np.sin(2 * t), t ** 3], axis=1)
    v = np.stack([2 * np.cos(2 * t), 3 * t ** 2], axis=1)
    _, _, v_read, a = read_trajectory(write_log(tmp_path / "qv.csv", model, t, q, v=v), model)
    np.testing.assert_array_equal(v_read, v)
    np.testing.assert_allclose(a[20:-20], np.stack([-4 * np.sin(2 * t), 6 * t], 1)[20:-20], rtol=0, atol=1e-3)


def test_csv_errors(tmp_path):
    model = rd.models.load("double_pendulum")
    path = tmp_path / "bad.csv"
    path.write_text("t,q:joint1\n0,0\n1,1\n")
    with pytest.raises(ValueError, match=r"missing columns \['q:joint2'\]"):
        read_trajectory(path, model)
    path.write_text("t,q:joint1,q:joint2\n0,0,0\n0,1,1\n")
    with pytest.raises(ValueError, match="not strictly increasing at line 3"):
        read_trajectory(path, model)
    path.write_text("t,q:joint1,q:joint2\n0,0,nan\n1,1,1\n")
    with pytest.raises(ValueError, match=r"missing or non-finite values at lines \[2\]"):
        read_trajectory(path, model)


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_only_on_terminals():
    out = _Terminal()
    bar = Progress(200, stream=out)
    for k in range(0, 201, 50):
        bar.update(k)
    bar.close()
    text = out.getvalue()
    assert "\r[" in text and " 50%" in text and "100%" in text and text.endswith("\n")
    quiet = io.StringIO()
    bar = Progress(200, stream=quiet)
    bar.update(100)
    bar.close()
    assert quiet.getvalue() == ""


def test_progress_bar_of_a_run(capfd):
    model = rd.models.load("pendulum")
    a = rd.simulate(model, [0.3], [0.0], 0.2, 1e-3, progress=True)
    b = rd.simulate(model, [0.3], [0.0], 0.2, 1e-3)
    assert "100%" in capfd.readouterr().err
    np.testing.assert_array_equal(a.q, b.q)  # computed in pieces, same result
    from robodyn import control

    ct = control.ComputedTorque(model, control.quintic([0.3], [0.0], 0.1, t0=0.05), 100.0, 20.0)
    a = rd.simulate(model, [0.3], [0.0], 0.2, 1e-3, controller=ct, progress=True)
    b = rd.simulate(model, [0.3], [0.0], 0.2, 1e-3, controller=ct)
    np.testing.assert_array_equal(a.q, b.q)  # the pieces restart at the right time


def test_bad_input():
    model = rd.models.load("double_pendulum")
    ok = dict(q0=[0.1, 0.2], v0=[0.0, 0.0], duration=0.1, dt=1e-3)

    def call(**kw):
        args = {**ok, **kw}
        return rd.simulate(model, args.pop("q0"), args.pop("v0"), args.pop("duration"), args.pop("dt"), **args)

    with pytest.raises(ValueError, match=r"q0: expected shape \(2,\), got \(3,\)"):
        call(q0=[0, 0, 0])
    with pytest.raises(ValueError, match=r"v0: contains NaN"):
        call(v0=[np.nan, 0])
    with pytest.raises(ValueError, match=r"dt: must be finite and > 0, got 0"):
        call(dt=0.0)
    with pytest.raises(ValueError, match=r"dt: must be finite and > 0, got -0.001"):
        call(dt=-1e-3)
    with pytest.raises(ValueError, match=r"duration: must be finite and > 0, got inf"):
        call(duration=np.inf)
    with pytest.raises(ValueError, match=r"dt: must not exceed duration"):
        call(dt=1.0)
    with pytest.raises(ValueError, match=r"integrator: unknown 'euler'"):
        call(integrator="euler")
    with pytest.raises(ValueError, match=r"controller: expected None or a callable"):
        call(controller="pd")
    with pytest.raises(ValueError, match=r"controller: returned shape \(3,\) at t = 0"):
        call(controller=lambda t, q, v: np.zeros(3))
    with pytest.raises(ValueError, match=r"tau \(controller output\) contains NaN"):
        call(controller=lambda t, q, v: np.array([0.0, np.nan]) if t > 0.05 else np.zeros(2))
    from robodyn import control

    with pytest.raises(ValueError, match=r"controller: its model has nq=7, nv=7; the simulated model has nq=2"):
        call(controller=control.PDGravity(rd.models.load("panda"), np.zeros(7), 1.0, 1.0))
    floating = random_model(2, seed=0, floating_base=True)
    q0, v0, _ = random_state(floating, rng_for("quat"))
    q0[3:7] *= 1.5
    with pytest.raises(ValueError, match=r"q0: quaternion q0\[3:7\] has norm 1.5"):
        rd.simulate(floating, q0, v0, 0.1, 1e-3)


# --- external wrenches and bilateral constraints ---------------------------------------------

def free_body(mass=2.0, gravity=(0.0, 0.0, 0.0)):
    b = rd.ModelBuilder(gravity=gravity)
    b.add_link("body", mass=mass, inertia=np.diag([0.01, 0.02, 0.03]))
    return b.build(floating_base=True)


def test_a_constant_force_accelerates_a_free_body_uniformly():
    body = free_body()
    F = np.zeros((1, 6))
    F[0, :3] = [2.0, -1.0, 0.5]
    v0 = np.array([0, 0, 0, 0.3, -0.2, 0.5])  # spinning: the world force must not turn with it
    for frame, integrator in (("world", "rk4"), ("local_world_aligned", "semi_implicit_euler")):
        traj = rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], v0, 1.0, 1e-3, None, integrator, f_ext=F, frame=frame)
        np.testing.assert_allclose(traj.q[-1, :3], F[0, :3] / 2.0 / 2.0, rtol=2e-3 if integrator != "rk4" else 1e-9)
        # the compiled run (constant array) equals the Python-driven one (callable)
        again = rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], v0, 1.0, 1e-3, None, integrator, f_ext=lambda t, q, v: F,
                            frame=frame)
        np.testing.assert_allclose(again.q, traj.q, rtol=0, atol=1e-12)


def test_a_spring_to_the_world_makes_a_harmonic_oscillator():
    body, k = free_body(mass=2.0), 50.0

    def spring(t, q, v):
        f = np.zeros((1, 6))
        f[0, :3] = -k * q[:3]  # world force at the body origin
        return f

    traj = rd.simulate(body, [0.1, 0, 0, 0, 0, 0, 1], np.zeros(6), 2.0, 1e-3, f_ext=spring,
                       frame="local_world_aligned")
    np.testing.assert_allclose(traj.q[:, 0], 0.1 * np.cos(np.sqrt(k / 2.0) * traj.t), rtol=0, atol=1e-9)


def test_simulated_accelerations_satisfy_the_inverse_dynamics_with_wrenches():
    model = random_model(5, seed=11, floating_base=True)
    rng = np.random.default_rng(11)
    q0, v0 = random_state(model, rng)[:2]
    F = rng.standard_normal((model.nbodies, 6))
    traj = rd.simulate(model, q0, v0, 0.05, 1e-3, f_ext=F, frame="world")
    for s in (0, 20, 50):
        np.testing.assert_allclose(rd.rnea(model, traj.q[s], traj.v[s], traj.a[s], F, "world"), traj.tau[s],
                                   atol=1e-8 * (1 + np.abs(traj.a[s]).max()))


def test_a_four_bar_linkage_stays_closed_under_simulate():
    from test_constrained import _closed_configuration, _four_bar
    from robodyn.algorithms.constrained import constraint_jacobian

    model, loop = _four_bar()
    q0 = _closed_configuration(1.0)
    J = constraint_jacobian(model, q0, np.zeros(3), [loop])[0][0]
    v0 = 2.0 * np.linalg.svd(J)[2][-1]
    traj = rd.simulate(model, q0, v0, 3.0, 1e-3, constraints=[loop])
    assert traj.constraint_force.shape == (3001, 3) and np.ptp(traj.q[:, 0]) > 1.0
    phi = np.array([constraint_jacobian(model, q, v, [loop])[2][0] for q, v in zip(traj.q[::50], traj.v[::50])])
    assert np.abs(phi).max() < 1e-6
    assert np.ptp(traj.energy) < 1e-5 * abs(traj.energy[0])
    # pushed at the coupler: the inverse dynamics with the wrench balance the loop's force
    F = np.zeros((model.nbodies, 6))
    F[model.link_names.index("coupler"), :3] = [0.0, 5.0, 0.0]
    traj = rd.simulate(model, q0, v0, 0.5, 1e-3, f_ext=F, frame="local_world_aligned", constraints=[loop],
                       baumgarte=(20.0, 20.0))
    for s in (0, 250, 500):
        q, v = traj.q[s], traj.v[s]
        Jc = constraint_jacobian(model, q, v, [loop])[0][0]
        lhs = rd.rnea(model, q, v, traj.a[s], F, "local_world_aligned") - traj.tau[s]
        np.testing.assert_allclose(lhs, Jc.T @ traj.constraint_force[s], atol=1e-9)


def test_contacts_with_an_external_push():
    """A box on the ground pushed by a horizontal force F: it stays when F < mu m g, else it
    slides with (F - mu m g) / m."""
    from robodyn.contact import Box, Contacts, Plane

    b = rd.ModelBuilder()
    b.add_link("box", mass=1.0, inertia=np.diag([0.002, 0.002, 0.003]))
    box = b.build(floating_base=True)
    contacts = Contacts([Box("box", (0.1, 0.1, 0.05))], surfaces=[Plane(friction=0.5)])
    q0 = [0, 0, 0.025, 0, 0, 0, 1]
    for push, accel in ((4.0, 0.0), (7.0, 7.0 - 0.5 * G)):
        F = np.zeros((1, 6))
        F[0, 0] = push
        traj = rd.simulate(box, q0, np.zeros(6), 0.5, 1e-3, f_ext=F, frame="local_world_aligned",
                           contacts=contacts)
        x = traj.q[:, 0]
        assert x[-1] == pytest.approx(0.5 * accel * 0.5 * 0.501, abs=1e-6)  # semi-implicit Euler: t (t + dt) / 2


def test_bad_wrenches_and_constraints_are_refused():
    body = free_body()
    with pytest.raises(ValueError, match=r"f_ext: expected shape \(\.\.\., 1, 6\)"):
        rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, f_ext=np.zeros(6))
    with pytest.raises(ValueError, match="frame must be one of"):
        rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, f_ext=np.zeros((1, 6)), frame="base")
    with pytest.raises(ValueError, match=r"f_ext at t = 0.05: f_ext: contains NaN"):
        rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3,
                    f_ext=lambda t, q, v: np.full((1, 6), np.nan if t > 0.0499 else 0.0))
    from robodyn.contact import Contacts, Sphere

    pin = rd.PointConstraint("body", (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="constraints: not with contacts"):
        rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, constraints=[pin],
                    contacts=Contacts([Sphere("body", 0.1)]))
    with pytest.raises(ValueError, match="baumgarte"):
        rd.simulate(body, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, constraints=[pin], baumgarte=(-1.0, 0.0))


def test_symplectic_energy_stays_bounded_where_euler_drifts():
    """Stormer-Verlet in momentum form on the double pendulum, 100,000 steps (500 s): the
    energy error oscillates without drift (the last quarter's largest error is no larger than
    the first quarter's, within 50 %), while the velocity-form semi-implicit Euler step gains
    energy steadily (benchmarks/energy_drift.py prints the numbers)."""
    model = rd.models.load("double_pendulum")
    q0, v0 = np.array([1.0, -0.5]), np.zeros(2)
    run = rd.simulate(model, q0, v0, 500.0, 5e-3, integrator="symplectic")
    error = np.abs(run.energy - run.energy[0])
    quarter = len(error) // 4
    assert error[-quarter:].max() <= 1.5 * error[:quarter].max()
    assert error.max() < 0.02 * abs(run.energy[0])
    euler = rd.simulate(model, q0, v0, 500.0, 5e-3, integrator="semi_implicit_euler")
    drift = np.abs(euler.energy - euler.energy[0])
    assert drift[-quarter:].max() > 10 * error.max()


def test_symplectic_is_second_order_and_forced_runs_agree_with_rk4():
    """Halving dt divides the error at t = 1 by about 4 (against RK4 at dt / 64), unforced and
    under a PD controller with friction (the forcing enters at both ends of each step)."""
    model = rd.models.load("double_pendulum").replace(damping=np.array([0.2, 0.1]))
    q0, v0 = np.array([1.0, -0.5]), np.array([0.3, 0.0])
    pd = control.PDGravity(model, np.array([0.2, 0.1]), 20.0, 5.0)
    for controller in (None, pd):
        exact = rd.simulate(model, q0, v0, 1.0, 1e-2 / 64, controller=controller, integrator="rk4")
        errors = []
        for dt in (1e-2, 5e-3, 2.5e-3):
            run = rd.simulate(model, q0, v0, 1.0, dt, controller=controller, integrator="symplectic")
            errors.append(np.abs(run.q[-1] - exact.q[-1]).max())
        ratios = np.array(errors[:-1]) / np.array(errors[1:])
        assert np.all((ratios > 3.5) & (ratios < 4.6)), (controller, errors, ratios)


def test_symplectic_refuses_what_it_does_not_integrate():
    ball = rd.ModelBuilder()
    ball.add_link("body", mass=1.0, inertia=0.01 * np.eye(3))
    with pytest.raises(ValueError, match="integrator 'symplectic': fixed-base models of 1-dof joints"):
        rd.simulate(ball.build(floating_base=True), [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3,
                    integrator="symplectic")
