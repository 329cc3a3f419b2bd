"""Interaction control (robodyn.control.interaction): under a known external wrench on the
frame, an impedance-controlled Panda settles where the spring balances it, a displacement
f / K and a rotation by the vector n / K (within 1 %); with inertia shaping its step response
is the desired mass-spring-damper's closed form; operational-space control (Panda, full pose
and mixed rows) and workspace computed torque (elbow arm, PUMA 560 full pose) give the task
error e'' + Kd e' + Kp e = 0 against simulation; the rotation error is SciPy's rotation
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


def pose_matrix(p, R):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def critically_damped(e0, ed0, w, t):
    """e(t) of e'' + 2 w e' + w^2 e = 0 from (e0, ed0): (e0 + (ed0 + w e0) t) exp(-w t), (N, m)."""
    return (e0[None] + (ed0 + w * e0)[None] * t[:, None]) * np.exp(-w * t)[:, None]


def test_operational_space_full_pose_error_dynamics_and_null_space():
    """Six task rows on the 7-dof Panda from a pose 5 cm and 0.3 rad (about a fixed axis u)
    away, at rest: with an exact model both the position error and the rotation vector
    log(R_d R^T) = theta u obey e'' + Kd e' + Kp e = 0 (the rotation keeps its axis, so the
    angle does too), to 1e-6 of the initial error; two postures in the one-dimensional null
    space give the same task motion."""
    model = rd.models.load("panda").rigid()
    assert model.nv == 7
    T0 = rd.frame_pose(model, Q0, "link7")
    e0, u, theta0, w = np.array([0.05, -0.03, 0.04]), np.array([1.0, -2.0, 2.0]) / 3, 0.3, 8.0
    R_d = Rotation.from_rotvec(theta0 * u).as_matrix() @ T0[:3, :3]
    errors, q_end = [], []
    for posture, target in ((Q0, (T0[:3, 3] + e0, R_d)), (Q0 + 0.3, pose_matrix(T0[:3, 3] + e0, R_d))):
        ctrl = control.OperationalSpace(model, "link7", target, w * w, 2 * w, posture=posture, posture_kp=20.0,
                                        posture_kd=5.0, rows="all")
        run = rd.simulate(model, Q0, np.zeros(7), 0.6, 1e-3, controller=ctrl, integrator="rk4")
        e = np.array([ctrl.error(t, q) for t, q in zip(run.t, run.q)])
        expected = critically_damped(np.concatenate([e0, theta0 * u]), np.zeros(6), w, run.t)
        assert_rel(e[:, :3], expected[:, :3], 1e-6 * np.abs(e0).max())
        assert_rel(e[:, 3:], expected[:, 3:], 1e-6 * theta0)
        assert np.abs(e[-1]).max() < 0.05 * theta0  # converging to the pose (5 % left at 0.6 s)
        errors.append(e)
        q_end.append(run.q[-1])
    assert_rel(errors[0], errors[1], 1e-8)
    assert np.abs(q_end[0] - q_end[1]).max() > 1e-2  # the postures did differ


def test_operational_space_rows_mixing_position_and_orientation():
    """Rows [0, 1, 5] (x, y and the rotation about z) from a moving start: x and y follow
    e'' + Kd e' + Kp e = 0 exactly (e'(0) = -(J v0)), the z entry of log(R_d R^T) goes from
    0.4 rad to below 1 % of it; the rows left free (z, the other rotations) are not held."""
    model = rd.models.load("panda").rigid()
    T0 = rd.frame_pose(model, Q0, "link7")
    v0 = np.array([0.2, -0.1, 0.3, 0.2, -0.4, 0.3, 0.5])
    T_d = pose_matrix(T0[:3, 3] + [0.04, -0.03, 0.05], Rotation.from_rotvec([0.2, -0.1, 0.4]).as_matrix() @ T0[:3, :3])
    w = 8.0
    ctrl = control.OperationalSpace(model, "link7", T_d, w * w, 2 * w, posture=Q0, posture_kp=20.0, posture_kd=5.0,
                                    rows=[0, 1, 5])
    run = rd.simulate(model, Q0, v0, 1.2, 1e-3, controller=ctrl, integrator="rk4")
    e = np.array([ctrl.error(t, q) for t, q in zip(run.t, run.q)])
    assert_rel(e[0], [0.04, -0.03, 0.4], 1e-12)
    ed0 = -(rd.jacobian(model, Q0, "link7", "local_world_aligned") @ v0)[:2]
    assert_rel(e[:, :2], critically_damped(e[0, :2], ed0, w, run.t), 1e-6 * 0.04)
    assert abs(e[-1, 2]) < 0.01 * 0.4
    p_end = rd.frame_pose(model, run.q[-1], "link7")[:3, 3]
    assert abs(p_end[2] - T_d[2, 3]) > 0.01  # z is not a task row


def test_workspace_computed_torque_tracks_a_pose_on_the_puma():
    """All six rows on the (6-dof) PUMA 560: the hand follows a moving pose (a circle of
    3 cm, a rotation oscillating by 0.3 rad about a fixed axis), starting 2 cm off and at
    rest; the position error and the rotation vector of the orientation error both follow
    e'' + Kd e' + Kp e = 0 (e'(0) = the target's twist), to 1e-6."""
    model = rd.models.load("puma560").rigid()
    assert model.nv == 6
    q0 = np.array([0.0, np.pi / 4, np.pi, 0.0, np.pi / 4, 0.0])
    T0 = rd.frame_pose(model, q0, "link6")
    u, a, s, w = np.array([2.0, 1.0, -2.0]) / 3, 0.3, 0.03, 6.0
    offset = np.array([0.02, -0.01, 0.015])

    def target(t):
        R = Rotation.from_rotvec(a * np.sin(t) * u).as_matrix() @ T0[:3, :3]
        p = T0[:3, 3] + offset + s * np.array([np.sin(t), 0.0, 1.0 - np.cos(t)])
        twist = np.concatenate([s * np.array([np.cos(t), 0.0, np.sin(t)]), a * np.cos(t) * u])
        twist_dot = np.concatenate([s * np.array([-np.sin(t), 0.0, np.cos(t)]), -a * np.sin(t) * u])
        return pose_matrix(p, R), twist, twist_dot

    ctrl = control.WorkspaceComputedTorque(model, "link6", target, w * w, 2 * w, rows="all")
    run = rd.simulate(model, q0, np.zeros(6), 1.0, 1e-3, controller=ctrl, integrator="rk4")
    e = np.array([ctrl.error(t, q) for t, q in zip(run.t, run.q)])
    expected = critically_damped(np.concatenate([offset, np.zeros(3)]), target(0.0)[1], w, run.t)
    assert_rel(e[:, :3], expected[:, :3], 1e-6 * np.abs(offset).max())
    assert_rel(e[:, 3:], expected[:, 3:], 1e-6 * a)
    assert np.abs(e[-1, :3]).max() < 1e-3 and np.abs(e[-1, 3:]).max() < 0.02 * a


def step_response(m, d, k, f, t):
    """x(t) of m x'' + d x' + k x = f (underdamped, per column) from rest at 0: (N, n)."""
    m, d, k, f = (np.atleast_1d(np.asarray(y, dtype=float)) for y in (m, d, k, f))
    wn, z = np.sqrt(k / m), d / (2.0 * np.sqrt(k * m))
    assert np.all(z < 1)
    wd, t = wn * np.sqrt(1.0 - z * z), t[:, None]
    return f / k * (1.0 - np.exp(-z * wn * t) * (np.cos(wd * t) + z * wn / wd * np.sin(wd * t)))


def test_inertia_shaping_gives_the_desired_mass_spring_damper():
    """Impedance with inertia shaping on the Panda (6 rows, a one-dimensional null space with
    joint damping), a step wrench [f; n] on the hand measured by the force sensor: the
    displacement x - x_d follows M_d x'' + D x' + K x = f per axis and the rotation (n about
    a fixed axis, equal angular gains) I phi'' + D phi' + K phi = |n| (within 1 % of f / K;
    about 1e-8 here), settling at f / K; a heavier M_d gives its own, slower response."""
    model = rd.models.load("panda").rigid()
    T0 = rd.frame_pose(model, Q0, "link7")
    K, D = np.array([400.0, 300.0, 500.0, 20.0, 20.0, 20.0]), np.array([40.0, 30.0, 35.0, 0.6, 0.6, 0.6])
    u, n = np.array([2.0, -1.0, 2.0]) / 3, 0.3
    h = np.concatenate([[6.0, -4.0, 5.0], n * u])
    wrench = np.zeros((model.nbodies, 6))
    wrench[model.frame_index("link7")[0]] = h
    moves = []
    for M_d in (np.array([2.0, 2.0, 2.0, 0.02, 0.02, 0.02]), np.array([6.0, 4.0, 8.0, 0.05, 0.05, 0.05])):
        ctrl = control.CartesianImpedance(model, "link7", T0[:3, 3], T0[:3, :3], stiffness=K, damping=D, inertia=M_d,
                                          force=lambda t, q, v: h, joint_damping=2.0)
        run = rd.simulate(model, Q0, np.zeros(7), 1.0, 1e-3, controller=ctrl, f_ext=wrench,
                          frame="local_world_aligned", integrator="rk4")
        moved = -np.array([ctrl.error(q) for q in run.q])  # x - x_d and log(R R_d^T)
        expected = np.concatenate([step_response(M_d[:3], D[:3], K[:3], h[:3], run.t),
                                   step_response(M_d[3], D[3], K[3], n, run.t) * u], axis=1)
        assert_rel(moved, expected, 0.01 * np.abs(h / K).min())
        moves.append(moved)
    assert_rel(moves[0][-1], h / K, 0.01 * np.abs(h / K).min())  # the light one has settled
    assert np.all(np.abs(moves[0] - moves[1]).max(axis=0) > 0.1 * np.abs(h / K))  # M_d matters, per axis


@pytest.mark.parametrize("orientation", [False, True], ids=["position", "pose"])
def test_inertia_shaping_law_and_the_default(orientation):
    """At a random moving state under a wrench h_e: the frame's acceleration J a + J' v (from
    aba with tau and J^T h_e) is M_d^-1 (K e - D J v + h_e) exactly; without inertia the
    torques are J^T (K e - D J v) - D_q v + g as before."""
    model = rd.models.load("panda").rigid()
    rng = rng_for("inertia-shaping", orientation)
    q, v = Q0 + 0.2 * rng.standard_normal(7), rng.standard_normal(7)
    T0 = rd.frame_pose(model, Q0, "link7")
    m = 6 if orientation else 3
    R_d = T0[:3, :3] if orientation else None
    h = rng.standard_normal(m)
    K, D, M_d = 100.0 + 50.0 * rng.random(m), 5.0 + rng.random(m), 0.5 + rng.random(m)
    ctrl = control.CartesianImpedance(model, "link7", T0[:3, 3], R_d, stiffness=K, damping=D, inertia=M_d,
                                      force=lambda t, q, v: h, joint_damping=2.0)
    J = rd.jacobian(model, q, "link7", "local_world_aligned")[:m]
    a = rd.aba(model, q, v, ctrl(0.0, q, v) + J.T @ h)
    xdd = J @ a + rd.jacobian_dot_times_v(model, q, v, "link7", "local_world_aligned")[:m]
    e = ctrl.error(q)
    assert_rel(xdd, (K * e - D * (J @ v) + h) / M_d, 1e-9)
    plain = control.CartesianImpedance(model, "link7", T0[:3, 3], R_d, stiffness=K, damping=D, joint_damping=2.0)
    assert_rel(plain(0.0, q, v), J.T @ (K * e - D * (J @ v)) - 2.0 * v + rd.gravity(model, q), 1e-12)


def test_pose_tasks_bad_input():
    model = rd.models.load("panda")
    T0 = rd.frame_pose(model, Q0, "link7")
    reflection = np.diag([1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"target: expected a pose, a \(4, 4\) homogeneous matrix"):
        control.OperationalSpace(model, "link7", T0[:3, 3], 1.0, 1.0, rows="all")
    with pytest.raises(ValueError, match=r"target \(rotation\): expected a 3 x 3 rotation matrix"):
        control.OperationalSpace(model, "link7", (T0[:3, 3], 2 * np.eye(3)), 1.0, 1.0, rows="all")
    with pytest.raises(ValueError, match=r"target \(rotation\): expected a 3 x 3 rotation matrix"):
        control.OperationalSpace(model, "link7", pose_matrix(T0[:3, 3], reflection), 1.0, 1.0, rows=[0, 5])
    with pytest.raises(ValueError, match=r"target: expected a pose"):
        control.OperationalSpace(model, "link7", np.eye(4) * 2, 1.0, 1.0, rows="angular")
    with pytest.raises(ValueError, match=r"the position must be 3 finite numbers"):
        control.OperationalSpace(model, "link7", ([0.0, np.nan, 0.0], np.eye(3)), 1.0, 1.0, rows="all")
    with pytest.raises(ValueError, match=r"target: twist_d has shape \(3,\), expected \(6,\) \(\[p'; w\] in world"):
        control.OperationalSpace(model, "link7", lambda t: (T0, np.zeros(3), np.zeros(3)), 1.0, 1.0, rows=[0, 1, 5])
    with pytest.raises(ValueError, match=r"target: x_d has shape \(4, 4\), expected \(3,\)"):
        control.OperationalSpace(model, "link7", lambda t: (T0, np.zeros(3), np.zeros(3)), 1.0, 1.0)
    with pytest.raises(ValueError, match="orientation: expected a 3 x 3 rotation matrix"):
        control.CartesianImpedance(model, "link7", np.zeros(3), reflection, stiffness=1.0, damping=1.0)
    ctrl = control.OperationalSpace(model, "link7", T0, 1.0, 1.0, rows="all")
    with pytest.raises(ValueError, match="position: the task rows .* include angular ones"):
        ctrl.position(Q0)
    with pytest.raises(ValueError, match="as many task rows as joints"):
        control.WorkspaceComputedTorque(model, "link7", T0, 1.0, 1.0, rows="all")
    with pytest.raises(ValueError, match=r"Admittance: position rows \(0-2\) only"):
        control.Admittance(model, "link7", T0, lambda t, q, v: np.zeros(6), mass=1.0, damping=1.0, stiffness=1.0,
                           kp=1.0, kd=1.0, rows="all")
    sensor = lambda t, q, v: np.zeros(3)  # noqa: E731
    for bad in (0.0, -1.0, [1.0, 0.0, 1.0], np.inf):
        with pytest.raises(ValueError, match=r"inertia: gains must be finite and > 0"):
            control.CartesianImpedance(model, "link7", np.zeros(3), stiffness=1.0, damping=1.0, inertia=bad,
                                       force=sensor)
    with pytest.raises(ValueError, match="force: inertia shaping needs the measured external wrench"):
        control.CartesianImpedance(model, "link7", np.zeros(3), stiffness=1.0, damping=1.0, inertia=1.0)
    with pytest.raises(ValueError, match="force: the measured wrench is used by inertia shaping only"):
        control.CartesianImpedance(model, "link7", np.zeros(3), stiffness=1.0, damping=1.0, force=sensor)
    ctrl = control.CartesianImpedance(model, "link7", T0[:3, 3], T0[:3, :3], stiffness=1.0, damping=1.0, inertia=1.0,
                                      force=sensor)
    with pytest.raises(ValueError, match=r"force: the sensor returned shape \(3,\), expected \(6,\)"):
        ctrl(0.0, Q0, np.zeros(7))
