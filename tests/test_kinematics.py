"""Forward kinematics (robodyn.forward_kinematics, frame_pose): against an independent NumPy
composition of the model arrays, merged frames, the floating base's pose, batches and bad input."""

from __future__ import annotations

import functools

import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from conftest import small_tree_builder
from helpers import (assert_rel, check_batch, check_input_validation, input_checks, quat_to_matrix,
                     random_model, random_models, states)


def _rodrigues(axis, angle):
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def poses_by_hand(model, q):
    """oM_i = oM_parent X_tree[i] X_J(q_i), in plain NumPy."""
    out = np.zeros((model.nbodies, 4, 4))
    for i in range(model.nbodies):
        iq, axis = model.idx_q[i], model.joint_axis[i]
        R, p = np.eye(3), np.zeros(3)
        if model.joint_type[i] == J.REVOLUTE:
            R = _rodrigues(axis, q[iq])
        elif model.joint_type[i] == J.PRISMATIC:
            p = axis * q[iq]
        elif model.joint_type[i] == J.HELICAL:
            R, p = _rodrigues(axis, q[iq]), model.joint_pitch[i] * q[iq] * axis
        elif model.joint_type[i] == J.PLANAR:
            t = np.arctan2(q[iq + 3], q[iq + 2])
            R, p = _rodrigues(np.array([0.0, 0.0, 1.0]), t), np.array([q[iq], q[iq + 1], 0.0])
        elif model.joint_type[i] == J.SPHERICAL:
            R = quat_to_matrix(q[iq:iq + 4])
        else:
            R, p = quat_to_matrix(q[iq + 3:iq + 7]), q[iq:iq + 3]
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = model.X_tree_R[i] @ R, model.X_tree_R[i] @ p + model.X_tree_p[i]
        out[i] = T if model.parent[i] < 0 else out[model.parent[i]] @ T
    return out


@random_models
def test_forward_kinematics_by_hand(model):
    q, _, _ = states(model)
    T = rd.forward_kinematics(model, q)
    assert T.shape == (model.nbodies, 4, 4)
    assert_rel(T, poses_by_hand(model, q), 1e-12)
    for i in range(model.nbodies):
        assert_rel(rd.frame_pose(model, q, model.link_names[i]), T[i], 0.0)


def test_floating_base_pose_is_q():
    model = random_model(3, seed=91, floating_base=True)
    q, _, _ = states(model)
    T = rd.forward_kinematics(model, q)[0]
    assert_rel(T[:3, 3], q[:3], 0.0)
    assert_rel(T[:3, :3], quat_to_matrix(q[3:7]), 1e-15)
    assert_rel(T[3], [0, 0, 0, 1], 0.0)


@pytest.mark.parametrize("floating_base", [False, True])
def test_merged_frames(floating_base):
    """A fixed-joint link is the pose of its body times its fixed placement; the root link of a
    fixed base is the world frame."""
    model = small_tree_builder().build(floating_base=floating_base)
    q, _, _ = states(model)
    T = rd.forward_kinematics(model, q)
    b, R, p = model.frame_index("sensor")
    assert model.link_names[b] == "upper"
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = R, p
    assert_rel(rd.frame_pose(model, q, "sensor"), T[b] @ X, 1e-12)
    assert_rel(X[:3, 3], [0.05, 0, 0.4], 0.0)
    if not floating_base:
        assert_rel(rd.frame_pose(model, q, "base"), np.eye(4), 0.0)


def test_unknown_frame():
    model = small_tree_builder().build()
    with pytest.raises(ValueError, match="unknown link or frame 'hand'"):
        rd.frame_pose(model, np.zeros(model.nq), "hand")


def test_batch():
    for model in (random_model(8, seed=92, floating_base=True), small_tree_builder().build()):
        check_batch(rd.forward_kinematics, model, ("q",))
        check_batch(functools.partial(rd.frame_pose, name=model.link_names[-1]), model, ("q",))


@pytest.mark.parametrize("fn", [rd.forward_kinematics, functools.partial(rd.frame_pose, name="body2")],
                         ids=["forward_kinematics", "frame_pose"])
@input_checks
def test_bad_input(fn, aspect):
    check_input_validation(fn, ("q",), aspect)
