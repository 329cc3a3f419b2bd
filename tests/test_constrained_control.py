"""Hybrid force/position control of a constrained manipulator (MLS ch. 4, 5.3): a planar
arm whose tool is held on a circle by a rod to a world anchor (a curved wall) follows a path
along it while pressing with a commanded force.

Oracles: the constraint force of the simulated constrained dynamics equals the command
(within 2 %, in practice to the Baumgarte drift), the joint error follows the linear error
dynamics, the tool stays on the circle, bad input.
"""

import numpy as np
import pytest

import robodyn as rd
from robodyn import control

from helpers import PLANAR_2R, planar_2r

L1, L2 = PLANAR_2R["l1"], PLANAR_2R["l2"]
ANCHOR, RADIUS = np.array([1.0, 0.0, 0.0]), 0.4


def ik(p):
    """Elbow-down inverse kinematics of the planar arm: joint angles putting the tool at p."""
    c2 = (p[0] ** 2 + p[1] ** 2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    q2 = -np.arccos(np.clip(c2, -1, 1))
    q1 = np.arctan2(p[1], p[0]) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2))
    return np.array([q1, q2])


def jac(q):
    s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q.sum()), np.cos(q.sum())
    return np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])


def circle_reference(t):
    """The tool on the circle at angle ``s(t) = 2.4 + 0.4 sin(t)`` about the anchor: joint
    position, velocity and acceleration (exact, through the arm's Jacobian)."""
    s, sd, sdd = 2.4 + 0.4 * np.sin(t), 0.4 * np.cos(t), -0.4 * np.sin(t)
    u, du = np.array([np.cos(s), np.sin(s)]), np.array([-np.sin(s), np.cos(s)])
    p = ANCHOR[:2] + RADIUS * u
    pd, pdd = RADIUS * du * sd, RADIUS * (du * sdd - u * sd * sd)
    q = ik(p)
    Jq = jac(q)
    qd = np.linalg.solve(Jq, pd)
    eps = 1e-6  # Jdot qd by a central difference along the motion
    Jdot = (jac(q + eps * qd) - jac(q - eps * qd)) / (2 * eps)
    return q, qd, np.linalg.solve(Jq, pdd - Jdot @ qd)


def setup():
    model = planar_2r(**PLANAR_2R)
    rod = rd.DistanceConstraint("rod2", (L2, 0.0, 0.0), None, ANCHOR, RADIUS)
    return model, rod


def test_the_tool_presses_with_the_commanded_force_while_following_the_path():
    model, rod = setup()
    force = lambda t: np.array([-8.0 + 3.0 * np.sin(2 * t)])  # noqa: E731  tension in the rod, varying
    ctrl = control.ConstrainedForcePosition(model, rod, circle_reference, force, kp=100.0, kd=20.0)
    q0 = ik(ANCHOR[:2] + RADIUS * np.array([np.cos(2.3), np.sin(2.3)]))  # on the circle, off the path
    dt = 2e-3
    traj = rd.simulate(model, q0, np.zeros(2), 1.5, dt, controller=ctrl, constraints=[rod], integrator="rk4")
    lam = traj.constraint_force[:, 0]
    lam_d = np.array([force(t)[0] for t in traj.t])
    assert np.abs(lam - lam_d).max() < 0.02 * np.abs(lam_d).min()
    assert np.abs(lam - lam_d).max() < 1e-3  # exact but for the Baumgarte drift correction
    error = np.abs(traj.q - np.array([circle_reference(t)[0] for t in traj.t])).max(axis=1)
    assert error[0] > 0.05 and error[-1] < 1e-4
    # the error decays as e'' + 20 e' + 100 e = 0 (critically damped at 10 rad/s): (1 + 10 t) e^-10t
    k = int(round(1.0 / dt))
    assert error[k] < 2 * error[0] * (1 + 10.0) * np.exp(-10.0)
    # the rod holds: the tool stays on the circle
    tool = rd.frame_pose(model, traj.q, "rod2")[..., :3, :3] @ np.array([L2, 0, 0]) + \
        rd.frame_pose(model, traj.q, "rod2")[..., :3, 3]
    np.testing.assert_allclose(np.linalg.norm(tool - ANCHOR, axis=-1), RADIUS, atol=1e-6)


def test_bad_input():
    model, rod = setup()
    with pytest.raises(ValueError, match="force"):
        control.ConstrainedForcePosition(model, rod, circle_reference, [1.0, 2.0], kp=1.0, kd=1.0)
    with pytest.raises(ValueError, match="constraint"):
        control.ConstrainedForcePosition(model, [], circle_reference, 1.0, kp=1.0, kd=1.0)
    ctrl = control.ConstrainedForcePosition(model, rod, circle_reference, lambda t: np.zeros(3), kp=1.0, kd=1.0)
    with pytest.raises(ValueError, match="force"):
        ctrl(0.0, *circle_reference(0.0)[:2])
