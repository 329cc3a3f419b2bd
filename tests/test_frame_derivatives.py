"""Derivatives of frame velocities and accelerations (robodyn.frame_velocity_derivatives,
robodyn.frame_acceleration_derivatives): against Richardson differences of jacobian and
jacobian_dot_times_v on random trees (every frame, bodies and a frame with an offset), against
Pinocchio's getFrameVelocityDerivatives / getFrameAccelerationDerivatives on URDFs, batches and
bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import FD_TOL, assert_rel, random_models, richardson, states
from urdf_subset import load_pair, pairs

FRAMES = ("world", "local", "local_world_aligned")
PIN_FRAMES = {"world": pin.ReferenceFrame.WORLD, "local": pin.ReferenceFrame.LOCAL,
              "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED}


def velocity(model, q, v, body, frame):
    return rd.jacobian(model, q, body, frame) @ v


def acceleration(model, q, v, a, body, frame):
    return rd.jacobian(model, q, body, frame) @ a + rd.jacobian_dot_times_v(model, q, v, body, frame)


@random_models
@pytest.mark.parametrize("frame", FRAMES)
def test_against_differences(model, frame):
    q, v, a = states(model, "frames", frame)
    for body in sorted({0, model.nbodies // 2, model.nbodies - 1}):
        dq, dv = rd.frame_velocity_derivatives(model, q, v, body, frame)
        assert_rel(dq, richardson(lambda d: velocity(model, rd.integrate(model, q, d), v, body, frame), model.nv),
                   FD_TOL, f"dV/dq of body {body}")
        assert_rel(dv, rd.jacobian(model, q, body, frame), 1e-14)
        aq, av, aa = rd.frame_acceleration_derivatives(model, q, v, a, body, frame)
        assert_rel(aq, richardson(lambda d: acceleration(model, rd.integrate(model, q, d), v, a, body, frame),
                                  model.nv), FD_TOL, f"dA/dq of body {body}")
        assert_rel(av, richardson(lambda d: acceleration(model, q, v + d, a, body, frame), model.nv), FD_TOL,
                   f"dA/dv of body {body}")
        assert_rel(aa, rd.jacobian(model, q, body, frame), 1e-14)


@pytest.mark.parametrize("frame", FRAMES)
def test_a_frame_with_an_offset(frame):
    """Panda's hand: a frame fixed on link 7 with a rotation and an offset."""
    model = load_pair("panda_description/urdf/panda.urdf", False).model
    q, v, a = states(model, "hand", frame)
    dq, _ = rd.frame_velocity_derivatives(model, q, v, "panda_hand", frame)
    assert_rel(dq, richardson(lambda d: velocity(model, rd.integrate(model, q, d), v, "panda_hand", frame),
                              model.nv), FD_TOL)
    aq, av, _ = rd.frame_acceleration_derivatives(model, q, v, a, "panda_hand", frame)
    assert_rel(aq, richardson(lambda d: acceleration(model, rd.integrate(model, q, d), v, a, "panda_hand", frame),
                              model.nv), FD_TOL)
    assert_rel(av, richardson(lambda d: acceleration(model, q, v + d, a, "panda_hand", frame), model.nv), FD_TOL)


@pytest.mark.parametrize("path, floating_base", pairs())
def test_against_pinocchio(path, floating_base):
    """Velocities and spatial accelerations in ``world`` and ``local``. In
    ``local_world_aligned`` robodyn differentiates the velocity of the moving frame origin (the
    derivative of ``jacobian(q) v``, and the classical acceleration); Pinocchio's is the world
    derivative re-expressed at the origin held fixed, ``[dV_lin + dV_ang x p; dV_ang]``, which
    is checked against robodyn's world derivative."""
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    q, v, a = states(model, "pinocchio")
    pin.computeForwardKinematicsDerivatives(pm, data, pair.pin_q(q), v, a)
    name = model.link_names[-1]
    fid = pm.getFrameId(name)
    for frame in ("world", "local"):
        rf = PIN_FRAMES[frame]
        mine = rd.frame_velocity_derivatives(model, q, v, name, frame)
        for what, x, y in zip(("dV/dq", "dV/dv"), mine, pin.getFrameVelocityDerivatives(pm, data, fid, rf)):
            assert_rel(x, y, 1e-9, f"{frame} {what}")
        mine = rd.frame_acceleration_derivatives(model, q, v, a, name, frame)
        theirs = pin.getFrameAccelerationDerivatives(pm, data, fid, rf)[1:]
        for what, x, y in zip(("dA/dq", "dA/dv", "dA/da"), mine, theirs):
            assert_rel(x, y, 1e-9, f"{frame} {what}")
    world = rd.frame_velocity_derivatives(model, q, v, name, "world")[0]
    p = rd.frame_pose(model, q, name)[:3, 3]
    at_origin = np.vstack([world[:3] + np.cross(world[3:].T, p).T, world[3:]])
    theirs = pin.getFrameVelocityDerivatives(pm, data, fid, PIN_FRAMES["local_world_aligned"])
    assert_rel(at_origin, theirs[0], 1e-9, "local_world_aligned dV/dq, origin held fixed")
    assert_rel(rd.frame_velocity_derivatives(model, q, v, name, "local_world_aligned")[1], theirs[1], 1e-9)


def test_batch_and_bad_input():
    model = rd.random.random_model(5, seed=3, floating_base=True)
    Q, V, A = states(model, "frame-batch", size=(2, 3))
    body = model.nbodies - 1
    for frame in FRAMES:
        vel = rd.frame_velocity_derivatives(model, Q, V, body, frame)
        acc = rd.frame_acceleration_derivatives(model, Q, V, A, body, frame)
        for i in np.ndindex(2, 3):
            for x, y in zip(vel + acc, rd.frame_velocity_derivatives(model, Q[i], V[i], body, frame)
                            + rd.frame_acceleration_derivatives(model, Q[i], V[i], A[i], body, frame)):
                assert x.shape == (2, 3, 6, model.nv)
                assert_rel(x[i], y, 1e-12)
    q, v, a = Q[0, 0], V[0, 0], A[0, 0]
    with pytest.raises(ValueError, match="frame must be one of"):
        rd.frame_velocity_derivatives(model, q, v, body, "base")
    with pytest.raises(ValueError, match=r"\bv contains NaN or Inf"):
        rd.frame_acceleration_derivatives(model, q, np.full(model.nv, np.nan), a, body)
    with pytest.raises(ValueError, match=rf"a: expected shape \(\.\.\., {model.nv}\)"):
        rd.frame_acceleration_derivatives(model, q, v, a[:-1], body)
    with pytest.raises(ValueError, match="no_such_link"):
        rd.frame_velocity_derivatives(model, q, v, "no_such_link")
