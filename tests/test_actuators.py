"""Geared DC motors driven by voltage (robodyn.actuators): the locked rotor's current and
torque V / R and k_t V / R with the electrical time constant L / R, the no-load speed
V / (k_e N) with the mechanical time constant J R / (k_t k_e N^2), both within 1 %; the
energy balance (electrical power in = copper loss + magnetic energy + kinetic energy +
friction) to 1e-6; the reflected rotor inertia and friction in the model; bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn import actuators

from helpers import assert_rel


def rotor(inertia=0.02, **joint):
    """One revolute joint about z (gravity does not act on it) carrying a disk."""
    b = rd.ModelBuilder("rotor", gravity=(0.0, 0.0, -9.81))
    b.add_link("disk", mass=1.0, inertia=np.diag([0.01, 0.01, inertia]))
    b.add_joint("shaft", "revolute", "world", "disk", axis=(0, 0, 1), **joint)
    return b.build()


MOTOR = dict(torque_constant=0.05, back_emf=0.05, resistance=2.0, inductance=2e-3, gear_ratio=10.0)


def test_locked_rotor():
    """A rotor too heavy to move (armature 1e9): i(t) = V/R (1 - exp(-t R/L))."""
    motor = actuators.DCMotor(**MOTOR)
    plant = motor.plant(rotor().replace(armature=np.array([1e9])))
    V = 12.0
    drive = actuators.VoltageDrive(plant, motor, lambda t, q, v: np.array([V]))
    tau_e = MOTOR["inductance"] / MOTOR["resistance"]
    run = rd.simulate(plant, np.zeros(1), np.zeros(1), 10 * tau_e, tau_e / 100, controller=drive, integrator="rk4")
    i = run.controller_state[:, 0]
    assert_rel(i[100], V / MOTOR["resistance"] * (1 - np.exp(-1.0)), 0.01 * V / MOTOR["resistance"])
    assert i[-1] == pytest.approx(V / MOTOR["resistance"], rel=1e-3)
    assert run.tau[-1, 0] == pytest.approx(MOTOR["torque_constant"] * MOTOR["gear_ratio"] * V / MOTOR["resistance"],
                                           rel=1e-3)


def test_no_load_speed_and_mechanical_time_constant():
    motor = actuators.DCMotor(**{**MOTOR, "inductance": 1e-5}, rotor_inertia=1e-4)
    plant = motor.plant(rotor())
    V, N, k = 6.0, MOTOR["gear_ratio"], MOTOR["torque_constant"]
    drive = actuators.VoltageDrive(plant, motor, lambda t, q, v: np.array([V]))
    J = 0.02 + N * N * 1e-4                          # the disk and the reflected rotor
    tau_m = J * MOTOR["resistance"] / (k * MOTOR["back_emf"] * N * N)
    run = rd.simulate(plant, np.zeros(1), np.zeros(1), 8 * tau_m, tau_m / 200, controller=drive, integrator="Radau",
                      rtol=1e-10, atol=1e-12)
    speed = V / (MOTOR["back_emf"] * N)
    assert run.v[-1, 0] == pytest.approx(speed * (1 - np.exp(-8.0)), rel=1e-3)
    assert run.v[200, 0] == pytest.approx(speed * (1 - np.exp(-1.0)), rel=0.01)


def test_energy_balance():
    """Over a run with friction, saturation and a varying command: the integral of V i equals
    the copper loss, the magnetic energy, the kinetic energy and the friction losses (joint
    and rotor) to 1e-6."""
    from scipy.integrate import simpson

    L = 0.05  # an electrical time constant of 25 ms: the samples resolve it
    motor = actuators.DCMotor(**{**MOTOR, "inductance": L}, rotor_inertia=2e-4, viscous=1e-4, max_voltage=9.0)
    plant = motor.plant(rotor(damping=0.01))
    drive = actuators.VoltageDrive(plant, motor, lambda t, q, v: np.array([12.0 * np.sin(3.0 * t)]))
    run = rd.simulate(plant, np.zeros(1), np.zeros(1), 1.0, 5e-4, controller=drive, integrator="Radau",
                      rtol=1e-11, atol=1e-13)
    i, v = run.controller_state[:, 0], run.v[:, 0]
    V = np.clip(12.0 * np.sin(3.0 * run.t), -9.0, 9.0)
    saturated = np.abs(12.0 * np.sin(3.0 * run.t)) > 9.0
    integral = lambda y: float(simpson(y, x=run.t))  # noqa: E731
    energy_in = integral(V * i)
    copper = integral(MOTOR["resistance"] * i * i)
    magnetic = 0.5 * L * (i[-1] ** 2 - i[0] ** 2)
    friction = integral(plant.damping[0] * v * v)                  # joint and reflected rotor viscous
    kinetic = run.kinetic[-1] - run.kinetic[0]
    assert abs(energy_in - (copper + magnetic + friction + kinetic)) < 1e-6 * energy_in
    assert saturated.any() and kinetic > 0 and friction > 0


def test_reflected_terms_and_bad_input():
    motor = actuators.DCMotor(**MOTOR, rotor_inertia=1e-4, viscous=2e-4, coulomb=0.01)
    plant = motor.plant(rotor(damping=0.1))
    assert plant.armature[0] == pytest.approx(100 * 1e-4)
    assert plant.damping[0] == pytest.approx(0.1 + 100 * 2e-4)
    assert plant.coulomb[0] == pytest.approx(10 * 0.01)
    assert rd.crba(plant, np.zeros(1))[0, 0] == pytest.approx(0.02 + 0.01)
    with pytest.raises(ValueError, match=r"DCMotor.resistance: expected > 0"):
        actuators.DCMotor(**{**MOTOR, "resistance": 0.0}).plant(rotor())
    with pytest.raises(ValueError, match=r"DCMotor.efficiency: expected values in \(0, 1\]"):
        actuators.DCMotor(**MOTOR, efficiency=1.5).plant(rotor())
    with pytest.raises(ValueError, match="voltage: expected a callable"):
        actuators.VoltageDrive(rotor(), actuators.DCMotor(**MOTOR), 12.0)


def test_flexible_joints_conserve_energy_and_approach_the_rigid_robot():
    """Without input or damping the links, motors and springs conserve their energy; with
    Tomei's motor PD the links settle at the set point; as K grows the motion approaches the
    rigid robot's (with the motors' inertia as armature), the error shrinking like 1 / K."""
    model = rd.models.load("double_pendulum")
    q0, B = np.array([0.6, -0.3]), np.array([0.05, 0.05])
    free = actuators.FlexibleJoints(model, 200.0, B, theta0=q0)
    run = rd.simulate(model, q0, np.zeros(2), 1.0, 1e-3, controller=free, integrator="rk4")
    total = run.energy + np.array([free.energy(q, v, z) for q, v, z in zip(run.q, run.v, run.controller_state)])
    assert np.ptp(total) < 1e-8 * np.abs(total).max()
    assert np.abs(run.controller_state[:, 0] - run.q[:, 0]).max() > 1e-3  # the springs do stretch
    # regulation: Tomei's PD on the motors brings the links to q_d (slowly: the links are damped
    # through the springs only)
    q_d = np.array([0.3, 0.2])
    law = actuators.motor_pd_gravity(model, q_d, 500.0, 500.0, 20.0)
    held = actuators.FlexibleJoints(model, 500.0, B, law, damping=3.0, theta0=q0)
    run = rd.simulate(model, q0, np.zeros(2), 8.0, 2e-3, controller=held, integrator="rk4")
    error = np.abs(run.q - q_d).max(axis=1)
    assert error[-1] < 2e-3 and error[-1] < 0.05 * error[500]
    # the rigid limit, from the consistent start (the springs already carry the motors'
    # share of the initial acceleration: theta - q = -B a0 / K)
    Bm = 1e-3
    stiff = model.replace(armature=np.full(2, Bm))
    rigid = rd.simulate(stiff, q0, np.zeros(2), 0.2, 1e-4, integrator="rk4")
    a0 = rd.aba(stiff, q0, np.zeros(2), np.zeros(2))
    errors = []
    for K in (1e3, 4e3):
        flexible = actuators.FlexibleJoints(model, K, Bm, theta0=q0 - Bm * a0 / K)
        run = rd.simulate(model, q0, np.zeros(2), 0.2, 1e-4, controller=flexible, integrator="rk4")
        errors.append(np.abs(run.q - rigid.q).max())
    assert 3.6 < errors[0] / errors[1] < 4.4, errors  # K four times stiffer: four times closer


def test_position_servo():
    """A motor-side PD in volts on a horizontal rotor reaches its set point; on a pendulum
    under gravity it settles where the motor's static torque k_t N V / R holds the load."""
    motor = actuators.DCMotor(**MOTOR, rotor_inertia=1e-4)
    plant = motor.plant(rotor())
    drive = actuators.VoltageDrive(plant, motor, actuators.position_servo([1.0], 40.0, 4.0))
    run = rd.simulate(plant, np.zeros(1), np.zeros(1), 3.0, 1e-3, controller=drive, integrator="Radau")
    assert run.q[-1, 0] == pytest.approx(1.0, abs=1e-4)
    pendulum = motor.plant(rd.models.load("pendulum"))
    kp = 400.0
    drive = actuators.VoltageDrive(pendulum, motor, actuators.position_servo([0.5], kp, 60.0))
    run = rd.simulate(pendulum, np.array([0.5]), np.zeros(1), 4.0, 1e-3, controller=drive, integrator="Radau")
    q = run.q[-1, 0]
    held = MOTOR["torque_constant"] * MOTOR["gear_ratio"] * kp * (0.5 - q) / MOTOR["resistance"]
    assert held == pytest.approx(rd.gravity(pendulum, run.q[-1])[0], rel=1e-6)
    assert 0.01 < q - 0.5 < 0.1  # the offset a proportional servo leaves under load


def test_composite_tracking_of_elastic_joints():
    """Spong's composite control: the links track a quintic motion like the rigid robot under
    computed torque (the error shrinking as K grows), and the fast damping Kv (v - theta')
    is what keeps the elastic mode down: the rigid law alone lets it grow."""
    model = rd.models.load("double_pendulum")
    q0, q1, B = np.array([0.4, -0.3]), np.array([-0.2, 0.5]), np.array([0.05, 0.05])
    ref = rd.control.quintic(q0, q1, 1.0)
    kp, kd = 100.0, 20.0
    errors = []
    for K in (2e3, 2e4):
        law = actuators.composite_tracking(model, ref, B, kp, kd, kv=2.0)
        theta0 = q0 + rd.gravity(model, q0) / K  # the springs hold the links still at the start
        flexible = actuators.FlexibleJoints(model, K, B, law, theta0=theta0)
        run = rd.simulate(model, q0, np.zeros(2), 1.5, 2e-4, controller=flexible, integrator="rk4")
        errors.append(np.abs(run.q - np.array([ref(t)[0] for t in run.t])).max())
    assert errors[1] < 3e-3 and errors[0] / errors[1] > 4, errors  # ten times stiffer: much closer
    # the elastic mode: the rigid law alone lets it grow (the closed loop is unstable); with
    # the fast damping it stays small
    K = 2e3
    theta0 = q0 + rd.gravity(model, q0) / K
    rigid_law = rd.control.ComputedTorque(model.replace(armature=B), ref, kp, kd)
    undamped = actuators.FlexibleJoints(model, K, B, lambda t, q, v, th, thd: rigid_law(t, q, v), theta0=theta0)
    damped = actuators.FlexibleJoints(model, K, B, actuators.composite_tracking(model, ref, B, kp, kd, 2.0),
                                      theta0=theta0)
    stretch = {}
    for name, plant_law in (("undamped", undamped), ("damped", damped)):
        run = rd.simulate(model, q0, np.zeros(2), 0.6, 2e-4, controller=plant_law, integrator="rk4")
        s = np.abs(run.controller_state[:, :2] - run.q).max(axis=1)
        stretch[name] = (s[run.t <= 0.1].max(), s[run.t > 0.5].max())
    assert stretch["undamped"][1] > 4 * stretch["undamped"][0], stretch  # growing
    assert stretch["damped"][1] < 0.2 * stretch["undamped"][1], stretch
    with pytest.raises(ValueError, match="kv"):
        actuators.composite_tracking(model, ref, B, kp, kd, kv=-1.0)


def test_gear_backlash_is_a_dead_zone_in_the_elastic_coupling():
    """Within the gap the motor turns without moving the link; beyond it the spring pushes
    with ``K (x - b sgn x)``; links, motors and springs conserve their energy through the
    impacts of the teeth (no damping); Tomei's PD with the gap crossed holds the link."""
    model = rd.models.load("double_pendulum")
    K, B, b = 300.0, np.array([0.05, 0.05]), np.array([0.05, 0.02])
    flex = actuators.FlexibleJoints(model, K, B, backlash=b)
    q, v = np.array([0.3, -0.2]), np.zeros(2)
    for x, expected in ((np.array([0.04, -0.01]), [0.0, 0.0]), (np.array([0.08, -0.05]), [K * 0.03, -K * 0.03])):
        z = np.concatenate([q + x, np.zeros(2)])
        np.testing.assert_allclose(flex.spring(q, v, z), expected, rtol=1e-12, atol=1e-12)
    damped = actuators.FlexibleJoints(model, K, B, damping=2.0, backlash=b)
    z = np.concatenate([q + np.array([0.04, -0.05]), [1.0, 1.0]])  # first joint in the gap, second in touch
    np.testing.assert_allclose(damped.spring(q, v, z), [0.0, -K * 0.03 + 2.0], rtol=1e-12)
    with pytest.raises(ValueError, match="backlash"):
        actuators.FlexibleJoints(model, K, B, backlash=-0.1)
    # free motion: the motors rattle through the gaps, the energy stays
    q0 = np.array([0.6, -0.3])
    run = rd.simulate(model, q0, np.zeros(2), 1.0, 2e-4, controller=flex.__class__(model, K, B, backlash=b, theta0=q0),
                      integrator="rk4")
    total = run.energy + np.array([flex.energy(q, v, z) for q, v, z in zip(run.q, run.v, run.controller_state)])
    assert np.ptp(total) < 1e-6 * np.abs(total).max()
    twist = np.abs(run.controller_state[:, :2] - run.q)
    assert np.any(twist[:, 0] < b[0]) and np.any(twist[:, 0] > b[0])  # in the gap and in touch
    # regulation: the set point crosses the gap on the side gravity loads
    q_d = np.array([0.3, 0.2])
    law = actuators.motor_pd_gravity(model, q_d, K, 500.0, 20.0, backlash=b)
    held = actuators.FlexibleJoints(model, K, B, law, damping=10.0, backlash=b, theta0=q0)
    run = rd.simulate(model, q0, np.zeros(2), 10.0, 2e-3, controller=held, integrator="rk4")
    assert np.abs(run.q[-1] - q_d).max() < 1e-3
    naive = actuators.FlexibleJoints(model, K, B, actuators.motor_pd_gravity(model, q_d, K, 500.0, 20.0),
                                     damping=10.0, backlash=b, theta0=q0)
    off = rd.simulate(model, q0, np.zeros(2), 10.0, 2e-3, controller=naive, integrator="rk4")
    assert np.abs(off.q[-1] - q_d).max() > 0.5 * b.min()  # without it the link sags by the gap
