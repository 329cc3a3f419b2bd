"""Interaction control (robodyn.control.interaction): under a known external wrench on the
frame, an impedance-controlled Panda settles where the spring balances it, a displacement
f / K and a rotation by the vector n / K (within 1 %); the rotation error is SciPy's rotation
vector; bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
from robodyn import control

from helpers import assert_rel, rng_for

Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8])


def settle(ctrl, model, wrench, duration=2.0):
    """The frame's pose after ``duration`` s under ``wrench`` (world axes, about its origin)."""
    F = np.zeros((model.nbodies, 6))
    F[model.frame_index(ctrl.body)[0]] = wrench
    run = rd.simulate(model, Q0, np.zeros(model.nv), duration, 2e-3, controller=ctrl, f_ext=F,
                      frame="local_world_aligned")
    assert np.abs(run.v[-1]).max() < 1e-4, "not at rest"
    return rd.frame_pose(model, run.q[-1], ctrl.body)


def test_the_frame_yields_like_its_spring():
    model = rd.models.load("panda").rigid()
    T0 = rd.frame_pose(model, Q0, "link7")
    K, D = np.array([800.0, 600.0, 700.0, 40.0, 30.0, 50.0]), np.array([80.0, 70.0, 75.0, 2.0, 2.0, 2.5])
    ctrl = control.CartesianImpedance(model, "link7", T0[:3, 3], T0[:3, :3], stiffness=K, damping=D)
    wrench = np.array([8.0, -4.0, 6.0, 0.4, -0.2, 0.3])
    T = settle(ctrl, model, wrench)
    assert_rel(T[:3, 3] - T0[:3, 3], wrench[:3] / K[:3], 0.01 * np.abs(wrench[:3] / K[:3]).max())
    turn = Rotation.from_matrix(T[:3, :3] @ T0[:3, :3].T).as_rotvec()
    assert_rel(turn, wrench[3:] / K[3:], 0.01 * np.abs(wrench[3:] / K[3:]).max())


def test_position_only_leaves_the_orientation_free():
    model = rd.models.load("panda").rigid()
    T0 = rd.frame_pose(model, Q0, "link7")
    ctrl = control.CartesianImpedance(model, "link7", T0[:3, 3], stiffness=500.0, damping=60.0, joint_damping=2.0)
    force = np.array([0.0, 5.0, -5.0, 0.0, 0.0, 0.0])
    T = settle(ctrl, model, force)
    assert_rel(T[:3, 3] - T0[:3, 3], force[:3] / 500.0, 1e-4)


def test_rotation_vector_is_the_log_map():
    rng = rng_for("rotation-vector")
    for angle in (0.0, 1e-9, 1e-4, 0.3, 2.0, np.pi - 1e-5, np.pi):
        for _ in range(5):
            u = rng.standard_normal(3)
            r = angle * u / np.linalg.norm(u)
            got = control.rotation_vector(Rotation.from_rotvec(r).as_matrix())
            if angle == np.pi:  # +u and -u are the same rotation
                assert min(np.abs(got - r).max(), np.abs(got + r).max()) < 1e-7
            else:
                assert_rel(got, r, 1e-7 if angle > np.pi - 1e-3 else 1e-12, f"angle {angle}")


def test_bad_input():
    model = rd.models.load("panda")
    with pytest.raises(ValueError, match="unknown"):
        control.CartesianImpedance(model, "nowhere", np.zeros(3), stiffness=1.0, damping=1.0)
    with pytest.raises(ValueError, match="position: expected 3 finite numbers"):
        control.CartesianImpedance(model, "link7", [0.0, np.nan, 0.0], stiffness=1.0, damping=1.0)
    with pytest.raises(ValueError, match="orientation: expected a 3 x 3 rotation matrix"):
        control.CartesianImpedance(model, "link7", np.zeros(3), 2 * np.eye(3), stiffness=1.0, damping=1.0)
    with pytest.raises(ValueError, match=r"stiffness: gains must be finite and > 0"):
        control.CartesianImpedance(model, "link7", np.zeros(3), np.eye(3), stiffness=(100.0, -1.0), damping=1.0)


def test_hybrid_control_holds_a_force_on_a_wall_while_sliding():
    """The Panda's hand (a 2 cm sphere on link7) against a wall with friction 0.2: the normal
    contact force holds 10 N within 2 % while the hand slides 5 cm along the wall (the issue's
    check), and the hand follows the path within 1 cm (friction lags it)."""
    from robodyn.contact import Contacts, Plane, Sphere

    model = rd.models.load("panda").rigid()
    q0 = np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])
    x0 = rd.frame_pose(model, q0, "link7")[:3, 3]
    radius, n = 0.02, np.array([-1.0, 0.0, 0.0])
    wall = Plane(normal=n, height=-(x0[0] + radius + 0.002), friction=0.2)  # 2 mm in front of the hand
    contacts = Contacts([Sphere("link7", radius)], surfaces=[wall])

    def path(t):
        return x0 + [0.0, 0.05 * np.clip((t - 0.5) / 2.0, 0.0, 1.0), 0.0]

    ctrl = control.HybridForcePosition(model, "link7", n, 10.0, path, stiffness=800.0, damping=80.0,
                                       normal_damping=40.0, joint_damping=2.0)
    run = rd.simulate(model, q0, np.zeros(7), 3.0, 1e-3, controller=ctrl, contacts=contacts)
    sliding = run.t > 0.7
    assert np.abs(run.normal_force[sliding, 0] - 10.0).max() < 0.2
    x_end = rd.frame_pose(model, run.q[-1], "link7")[:3, 3]
    assert abs(x_end[1] - path(3.0)[1]) < 0.01 and x_end[1] - x0[1] > 0.04
    with pytest.raises(ValueError, match="normal: expected a unit vector"):
        control.HybridForcePosition(model, "link7", [1.0, 1.0, 0.0], 10.0, path, stiffness=1.0, damping=1.0)
    with pytest.raises(ValueError, match="force: expected a number > 0"):
        control.HybridForcePosition(model, "link7", n, -1.0, path, stiffness=1.0, damping=1.0)


def test_operational_space_error_dynamics_and_null_space():
    """With an exact model the task error of operational-space control obeys e'' + Kd e' +
    Kp e = 0 (critically damped here: e(t) = e0 (1 + w t) exp(-w t)), and two postures in the
    null space leave the task motion the same."""
    model = rd.models.load("panda").rigid()
    x0 = rd.frame_pose(model, Q0, "link7")[:3, 3]
    e0 = np.array([0.05, -0.03, 0.04])
    w = 8.0
    runs = []
    for posture in (Q0, Q0 + 0.3):
        ctrl = control.OperationalSpace(model, "link7", x0 + e0, w * w, 2 * w, posture=posture, posture_kp=20.0,
                                        posture_kd=5.0)
        run = rd.simulate(model, Q0, np.zeros(7), 0.6, 1e-3, controller=ctrl, integrator="rk4")
        x = np.array([ctrl.position(q) for q in run.q])
        runs.append((run, x))
        expected = e0 * ((1 + w * run.t) * np.exp(-w * run.t))[:, None]
        assert_rel(x0 + e0 - x, expected, 1e-6)
    assert_rel(runs[0][1], runs[1][1], 1e-6)
    assert np.abs(runs[0][0].q[-1] - runs[1][0].q[-1]).max() > 1e-2  # the postures did differ


def test_impedance_against_a_wall_presses_with_its_spring():
    """The hand held 2 cm behind a rigid wall by a Cartesian spring K rests pressing K * 2 cm
    (the example's first scene), within 1 %."""
    from robodyn.contact import Contacts, Plane, Sphere

    model = rd.models.load("panda").rigid()
    q0 = np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])
    x0 = rd.frame_pose(model, q0, "link7")[:3, 3]
    wall = Plane(normal=[-1.0, 0.0, 0.0], height=-(x0[0] + 0.022), friction=0.2)
    contacts = Contacts([Sphere("link7", 0.02)], surfaces=[wall])
    ctrl = control.CartesianImpedance(model, "link7", x0 + [0.022, 0.0, 0.0], stiffness=800.0, damping=80.0,
                                      joint_damping=2.0)
    run = rd.simulate(model, q0, np.zeros(7), 2.0, 1e-3, controller=ctrl, contacts=contacts)
    assert run.normal_force[-1, 0] == pytest.approx(800.0 * 0.02, rel=0.01)


def test_admittance_yields_as_its_virtual_spring():
    """A constant force pushing the hand: the admittance model moves the hand to rest + f / K_a
    (within 1 %), the inner loop tracking the virtual motion; the virtual state is integrated
    with the robot."""
    model = rd.models.load("panda").rigid()
    x0 = rd.frame_pose(model, Q0, "link7")[:3, 3]
    f = np.array([6.0, -3.0, 4.0])
    wrench = np.zeros((model.nbodies, 6))
    wrench[model.frame_index("link7")[0], :3] = f
    ctrl = control.Admittance(model, "link7", x0, lambda t, q, v: f, mass=2.0, damping=60.0, stiffness=300.0,
                              kp=400.0, kd=40.0, posture=Q0, posture_kp=20.0, posture_kd=5.0)
    run = rd.simulate(model, Q0, np.zeros(7), 2.0, 1e-3, controller=ctrl, f_ext=wrench, frame="local_world_aligned")
    x = rd.frame_pose(model, run.q[-1], "link7")[:3, 3]
    assert_rel(x - x0, f / 300.0, 0.01 * np.abs(f / 300.0).max())
    assert_rel(run.controller_state[-1, :3], x, 1e-4)  # the hand is where the virtual mass is
    with pytest.raises(ValueError, match="force: expected a callable"):
        control.Admittance(model, "link7", x0, f, mass=1.0, damping=1.0, stiffness=1.0, kp=1.0, kd=1.0)


def test_workspace_computed_torque_on_a_non_redundant_arm():
    """MLS's workspace computed torque on the 3-joint elbow arm tracking a moving point: the
    error follows e'' + Kd e' + Kp e = 0 (here from e(0) with e'(0) = x_d'(0)), to 1e-6; a
    redundant task is refused."""
    model = rd.models.load("elbow_3r")
    q0 = np.array([0.3, 0.4, -0.8])
    x0 = rd.frame_pose(model, q0, "frame3")[:3, 3]
    w, s = 6.0, 0.02
    def target(t):
        return x0 + [s * np.sin(t), 0.01, 0.0], [s * np.cos(t), 0.0, 0.0], [-s * np.sin(t), 0.0, 0.0]

    ctrl = control.WorkspaceComputedTorque(model, "frame3", target, w * w, 2 * w)
    run = rd.simulate(model, q0, np.zeros(3), 1.0, 1e-3, controller=ctrl, integrator="rk4")
    e = np.array([target(t)[0] - ctrl.position(q) for t, q in zip(run.t, run.q)])
    e0, ed0 = e[0], np.array([s, 0.0, 0.0])  # the arm starts at rest, the target moving
    expected = (e0[None] + (ed0 + w * e0)[None] * run.t[:, None]) * np.exp(-w * run.t)[:, None]
    assert_rel(e, expected, 1e-6)
    with pytest.raises(ValueError, match="as many task rows as joints"):
        control.WorkspaceComputedTorque(rd.models.load("panda"), "link7", np.zeros(3), 1.0, 1.0)
