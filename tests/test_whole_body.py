"""Whole-body inverse dynamics with contacts (robodyn.control.whole_body_inverse_dynamics):
a standing quadruped's contact forces sum to its weight and the torques are rnea's with those
forces; desired accelerations are realised (forward dynamics with the computed torques and
forces gives them back); friction cones and torque limits hold or the call says which fails."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn import control

from conftest import example_robot_data_dir
from helpers import assert_rel

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
STANCE = np.array([0, 0.8, -1.6] * 2 + [0, -0.8, 1.6] * 2)


def solo12():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)  # the file's <contact> elements
        return rd.load_urdf(example_robot_data_dir() / "solo_description/robots/solo12.urdf", floating_base=True)


def contact_wrenches(model, q, forces):
    """The contact forces as per-body wrenches (world axes, torque about the body origin)."""
    F = np.zeros((model.nbodies, 6))
    for name, f in zip(FEET, forces):
        b, R, p = model.frame_index(name)
        T = rd.forward_kinematics(model, q)[b]
        r = T[:3, :3] @ p  # the foot point from the body origin, world axes
        F[b, :3] += f
        F[b, 3:] += np.cross(r, f)
    return F


def test_standing_quadruped():
    model = solo12()
    q = np.concatenate([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0, 1.0], STANCE])
    v = a = np.zeros(model.nv)
    out = control.whole_body_inverse_dynamics(model, q, v, a, FEET, mu=0.7)
    weight = model.total_mass * 9.81
    assert_rel(out.forces.sum(axis=0), [0.0, 0.0, weight], 1e-8 * weight)
    assert np.all(out.forces[:, 2] > 0) and np.all(np.hypot(out.forces[:, 0], out.forces[:, 1])
                                                      <= 0.7 * out.forces[:, 2] + 1e-9)
    assert np.all(out.tau[:6] == 0)
    expected = rd.rnea(model, q, v, a, contact_wrenches(model, q, out.forces), frame="local_world_aligned")
    assert_rel(expected[:6], np.zeros(6), 1e-8 * weight)
    assert_rel(out.tau[6:], expected[6:], 1e-9)
    # the symmetric stance shares the weight: four equal normal forces within 1 %
    assert np.ptp(out.forces[:, 2]) < 0.01 * weight


def test_desired_accelerations_are_realised():
    """Forward dynamics under the computed torques and contact forces gives the accelerations
    asked for (a base accelerating up and forward, the legs moving)."""
    model = solo12()
    q = np.concatenate([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0, 1.0], STANCE + 0.05])
    v = np.zeros(model.nv)
    a = np.zeros(model.nv)
    a[0], a[2] = 0.5, 1.0
    a[6:] = np.linspace(-1.0, 1.0, 12)
    out = control.whole_body_inverse_dynamics(model, q, v, a, FEET, mu=1.0)
    achieved = rd.aba(model, q, v, out.tau, contact_wrenches(model, q, out.forces), frame="local_world_aligned")
    assert_rel(achieved, a, 1e-7)


def test_what_contacts_cannot_do_is_refused():
    model = solo12()
    q = np.concatenate([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0, 1.0], STANCE])
    a = np.zeros(model.nv)
    a[0] = 30.0  # a sideways push no friction of 0.2 can give
    with pytest.raises(ValueError, match="friction cones|equation of motion"):
        control.whole_body_inverse_dynamics(model, q, np.zeros(model.nv), a, FEET, mu=0.2)
    a[0], a[2] = 0.0, -20.0  # pulling the body down faster than gravity: the feet would pull
    with pytest.raises(ValueError, match="no admissible contact forces"):
        control.whole_body_inverse_dynamics(model, q, np.zeros(model.nv), a, FEET)
    with pytest.raises(ValueError, match="at least one contact"):
        control.whole_body_inverse_dynamics(model, q, np.zeros(model.nv), a, [])
