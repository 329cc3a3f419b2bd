"""Frame Jacobians and Jdot v (robodyn.jacobian, jacobian_dot_times_v): columns against finite
differences of the forward kinematics in all three frames, Jdot v against finite differences
of J(q(t)) v, merged frames, velocities against the kinetic energy, batches and bad input."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import robodyn as rd
from conftest import small_tree_builder
from helpers import (assert_rel, check_batch, check_input_validation, input_checks, columns_by_differences,
                     directional_derivative, random_model, random_models, states)

FRAMES = ("world", "local", "local_world_aligned")


def _skew_to_vector(W):
    return np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]]) / 2


def velocity_from_pose_rate(T, Tdot, frame):
    """Velocity [linear; angular] in ``frame`` of a moving pose ``T`` (4 x 4) with rate ``Tdot``."""
    R, p, Rdot, pdot = T[:3, :3], T[:3, 3], Tdot[:3, :3], Tdot[:3, 3]
    omega = _skew_to_vector(Rdot @ R.T)  # world axes
    if frame == "local_world_aligned":
        return np.concatenate([pdot, omega])
    if frame == "world":  # velocity of the body point at the world origin
        return np.concatenate([pdot - np.cross(omega, p), omega])
    return np.concatenate([R.T @ pdot, R.T @ omega])


def _pose_fn(model, frame_name):
    if frame_name is None:
        return functools.partial(rd.forward_kinematics, model)
    return lambda x: rd.frame_pose(model, x, frame_name)


@random_models
@pytest.mark.parametrize("frame", FRAMES)
def test_columns_are_pose_derivatives(model, frame):
    """Column k of every body's Jacobian == velocity of the body when moving along e_k."""
    q, _, _ = states(model, frame)
    T = rd.forward_kinematics(model, q)
    Tdot = columns_by_differences(_pose_fn(model, None), model, q)  # (nb, 4, 4, nv)
    for b in range(model.nbodies):
        J = rd.jacobian(model, q, b, frame=frame)
        assert J.shape == (6, model.nv)
        expected = np.stack([velocity_from_pose_rate(T[b], Tdot[b, ..., k], frame) for k in range(model.nv)], 1)
        assert_rel(J, expected, 1e-6, f"body {b}")


@random_models
@pytest.mark.parametrize("frame", FRAMES)
def test_jdot_v_is_derivative_of_j_along_the_motion(model, frame):
    q, v, _ = states(model, frame)
    for b in range(model.nbodies):
        expected = directional_derivative(lambda x: rd.jacobian(model, x, b, frame=frame) @ v, model, q, v)
        assert_rel(rd.jacobian_dot_times_v(model, q, v, b, frame=frame), expected, 1e-6, f"body {b}")


@random_models
def test_frames_are_related_by_the_body_pose(model):
    q, v, _ = states(model)
    b = model.nbodies - 1
    T = rd.forward_kinematics(model, q)[b]
    R, p = T[:3, :3], T[:3, 3]
    world, local, lwa = (rd.jacobian(model, q, b, frame=f) @ v for f in FRAMES)
    assert_rel(lwa, np.concatenate([R @ local[:3], R @ local[3:]]), 1e-9)
    assert_rel(world, np.concatenate([lwa[:3] - np.cross(lwa[3:], p), lwa[3:]]), 1e-9)


@random_models
def test_kinetic_energy_from_body_velocities(model):
    """sum_b V_b . I_b V_b / 2 with the local Jacobians == kinetic_energy."""
    q, v, _ = states(model)
    energy = 0.0
    for b in range(model.nbodies):
        m, h, t = model.theta[b, 0], model.theta[b, 1:4], model.theta[b, 4:]
        I = np.array([[t[0], t[1], t[3]], [t[1], t[2], t[4]], [t[3], t[4], t[5]]])
        lin, ang = np.split(rd.jacobian(model, q, b, frame="local") @ v, 2)
        energy += 0.5 * (m * lin @ lin + ang @ I @ ang) + lin @ np.cross(ang, h)
    assert rd.kinetic_energy(model, q, v) == pytest.approx(energy, rel=1e-9)


@pytest.mark.parametrize("frame", FRAMES)
@pytest.mark.parametrize("floating_base", [False, True])
def test_merged_frame_and_names(frame, floating_base):
    """A link merged by a fixed joint: Jacobian and Jdot v against finite differences of its pose;
    a body named by link name equals the body index."""
    model = small_tree_builder().build(floating_base=floating_base)
    q, v, _ = states(model, frame)
    T = rd.frame_pose(model, q, "sensor")
    Tdot = columns_by_differences(_pose_fn(model, "sensor"), model, q)
    expected = np.stack([velocity_from_pose_rate(T, Tdot[..., k], frame) for k in range(model.nv)], 1)
    assert_rel(rd.jacobian(model, q, "sensor", frame=frame), expected, 1e-6)
    jdv = directional_derivative(lambda x: rd.jacobian(model, x, "sensor", frame=frame) @ v, model, q, v)
    assert_rel(rd.jacobian_dot_times_v(model, q, v, "sensor", frame=frame), jdv, 1e-6)
    b = model.link_names.index("lower")
    assert_rel(rd.jacobian(model, q, "lower", frame=frame), rd.jacobian(model, q, b, frame=frame), 0.0)


def test_bad_body_and_frame():
    model = small_tree_builder().build()
    q = np.zeros(model.nq)
    with pytest.raises(ValueError, match="frame must be one of"):
        rd.jacobian(model, q, 0, frame="body")
    with pytest.raises(ValueError, match="frame must be one of"):
        rd.jacobian_dot_times_v(model, q, q, 0, frame="spatial")
    with pytest.raises(ValueError, match="unknown link or frame 'nowhere'"):
        rd.jacobian(model, q, "nowhere")
    with pytest.raises(ValueError, match="out of range"):
        rd.jacobian(model, q, model.nbodies)
    with pytest.raises(ValueError, match="fixed to the world"):
        rd.jacobian(model, q, "base")


def test_batch():
    for model in (random_model(8, seed=51, floating_base=True), random_model(5, seed=52)):
        for frame in FRAMES:
            check_batch(functools.partial(rd.jacobian, body=model.nbodies - 1, frame=frame), model, ("q",))
            check_batch(functools.partial(rd.jacobian_dot_times_v, body=1, frame=frame), model, ("q", "v"))


@pytest.mark.parametrize("frame", FRAMES)
@input_checks
def test_bad_input(frame, aspect):
    check_input_validation(functools.partial(rd.jacobian, body=2, frame=frame), ("q",), aspect)
    check_input_validation(functools.partial(rd.jacobian_dot_times_v, body=2, frame=frame), ("q", "v"), aspect)
