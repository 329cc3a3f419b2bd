"""integrate / difference: agreement with Pinocchio (random trees and floating-base URDFs),
identities, the exponential map's derivative, batches and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from robodyn import joints as J
from robodyn.random import random_configuration, random_model

from conftest import example_robot_data_dir
from helpers import RANDOM_IDS, RANDOM_MODELS, configuration_rate, random_models, richardson, rng_for

FLOATING_URDFS = ["solo_description/robots/solo12.urdf", "anymal_b_simple_description/robots/anymal.urdf",
                  "talos_data/robots/talos_reduced.urdf"]


def pin_model_with_same_joints(model: rd.Model) -> pin.Model:
    """A Pinocchio model with the same joint types in the same order: integrate and
    difference depend on nothing else."""
    pm = pin.Model()
    for i in range(model.nbodies):
        jt = model.joint_type[i]
        joint = {J.FREE: pin.JointModelFreeFlyer, J.REVOLUTE: pin.JointModelRX, J.PRISMATIC: pin.JointModelPX,
                 J.SPHERICAL: pin.JointModelSpherical, J.HELICAL: lambda: pin.JointModelHelicalUnaligned(np.array([1.0, 0, 0]), 0.2),
                 J.PLANAR: pin.JointModelPlanar}[jt]()
        pm.addJoint(0, joint, pin.SE3.Identity(), f"joint{i}")
    return pm


def signed_like(model: rd.Model, q, ref):
    """``q`` with each quaternion's sign made that of ``ref``'s (the same rotation)."""
    q = np.array(q, dtype=float)
    for i in np.flatnonzero(J.QUAT_OFFSET[model.joint_type] >= 0):
        k = model.idx_q[i] + J.QUAT_OFFSET[model.joint_type[i]]
        q[..., k:k + 4] *= np.sign(np.sum(q[..., k:k + 4] * ref[..., k:k + 4], axis=-1, keepdims=True))
    return q


@random_models
def test_random_trees_agree_with_pinocchio(model):
    pm = pin_model_with_same_joints(model)
    rng = rng_for(model.name, "integrate")
    for scale in (1e-7, 1.0, 3.0):  # small steps (series branch) and large rotations
        q, q1 = random_configuration(model, rng), random_configuration(model, rng)
        v = scale * rng.standard_normal(model.nv)
        expected = pin.integrate(pm, q, v)  # Pinocchio's spherical joint keeps the product's sign
        np.testing.assert_allclose(signed_like(model, rd.integrate(model, q, v), expected), expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(rd.difference(model, q, q1), pin.difference(pm, q, q1), rtol=0, atol=1e-10)


def floating_pair(path):
    """robodyn's and Pinocchio's floating-base models of an example-robot-data URDF."""
    full = str(example_robot_data_dir() / path)
    pm = pin.buildModelFromUrdf(full, pin.JointModelFreeFlyer())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        model = rd.load_urdf(full, floating_base=True, physical="warn", mimic="independent")
    return model, pm


@pytest.mark.parametrize("path", FLOATING_URDFS)
def test_floating_base_urdfs_agree_with_pinocchio(path):
    model, pm = floating_pair(path)
    assert (model.nq, model.nv) == (pm.nq, pm.nv) and list(model.body_joint_names) == list(pm.names[1:])
    rng = rng_for(path)
    q, q1 = random_configuration(model, rng), random_configuration(model, rng)
    v = rng.standard_normal(model.nv)
    np.testing.assert_allclose(rd.integrate(model, q, v), pin.integrate(pm, q, v), rtol=0, atol=1e-12)
    np.testing.assert_allclose(rd.difference(model, q, q1), pin.difference(pm, q, q1), rtol=0, atol=1e-10)


@random_models
def test_difference_inverts_integrate(model):
    rng = rng_for(model.name, "inverse")
    q = random_configuration(model, rng, 4)
    v = rng.uniform(-1.0, 1.0, (4, model.nv))  # rotations below pi
    np.testing.assert_allclose(rd.difference(model, q, rd.integrate(model, q, v)), v, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rd.integrate(model, q, np.zeros(model.nv)), q, rtol=0, atol=1e-15)
    q1 = random_configuration(model, rng, 4)
    back = signed_like(model, rd.integrate(model, q, rd.difference(model, q, q1)), q1)  # quaternions up to sign
    np.testing.assert_allclose(back, q1, rtol=0, atol=1e-12)


@random_models
def test_curve_leaves_with_velocity_v(model):
    """d/dt integrate(q, v t) at t = 0 is the configuration rate of v (R v_lin, quat (w, 0) / 2)."""
    rng = rng_for(model.name, "rate")
    q = random_configuration(model, rng)
    v = rng.standard_normal(model.nv)
    h = 1e-6
    rate = (rd.integrate(model, q, v * h) - rd.integrate(model, q, -v * h)) / (2 * h)
    np.testing.assert_allclose(rate, configuration_rate(model, q, v), rtol=0, atol=1e-8)


def test_constant_body_twist_is_followed_exactly():
    """integrate(q, v t) is the motion of constant body twist v: two half steps make one."""
    model = random_model(3, seed=4, floating_base=True)
    rng = rng_for("twist")
    q, v = random_configuration(model, rng), rng.standard_normal(model.nv)
    np.testing.assert_allclose(rd.integrate(model, rd.integrate(model, q, v / 2), v / 2), rd.integrate(model, q, v),
                               rtol=0, atol=1e-12)


def test_batches_broadcast():
    model = RANDOM_MODELS[RANDOM_IDS.index("n7-seed5-floating-br0.3")]
    rng = rng_for("batch")
    q, v = random_configuration(model, rng, (2, 3)), rng.standard_normal((2, 3, model.nv))
    out = rd.integrate(model, q, v)
    assert out.shape == (2, 3, model.nq)
    np.testing.assert_allclose(out[1, 2], rd.integrate(model, q[1, 2], v[1, 2]), rtol=0, atol=1e-15)
    d = rd.difference(model, q[0, 0], q)
    assert d.shape == (2, 3, model.nv)
    np.testing.assert_allclose(d[1, 1], rd.difference(model, q[0, 0], q[1, 1]), rtol=0, atol=1e-15)


def test_bad_input():
    model = RANDOM_MODELS[RANDOM_IDS.index("n3-seed3-floating-br0.9")]
    q = random_configuration(model, rng_for("bad"))
    v = np.zeros(model.nv)
    with pytest.raises(ValueError, match=rf"v: expected shape \(\.\.\., {model.nv}\), got \(2,\)"):
        rd.integrate(model, q, np.zeros(2))
    with pytest.raises(ValueError, match=rf"q1: expected shape \(\.\.\., {model.nq}\)"):
        rd.difference(model, q, q[:-1])
    with pytest.raises(ValueError, match=r"v contains NaN"):
        rd.integrate(model, q, np.full(model.nv, np.nan))
    with pytest.raises(ValueError, match=r"q0 contains NaN"):
        rd.difference(model, np.full(model.nq, np.inf), q)
    bad = q.copy()
    bad[3:7] *= 2.0
    with pytest.raises(ValueError, match=r"quaternion q\[3:7\] has norm 2, not 1"):
        rd.integrate(model, bad, v)
    with pytest.raises(ValueError, match=r"do not broadcast"):
        rd.difference(model, np.stack([q, q]), np.stack([q, q, q]))


# -- Jacobians of integrate and difference ------------------------------------------------------
def _pin_jacobians(pm, q, v, q1):
    arg0, arg1 = pin.ArgumentPosition.ARG0, pin.ArgumentPosition.ARG1
    return (pin.dIntegrate(pm, q, v, arg0), pin.dIntegrate(pm, q, v, arg1), pin.dDifference(pm, q, q1, arg0),
            pin.dDifference(pm, q, q1, arg1))


@random_models
def test_jacobians_agree_with_pinocchio(model):
    pm = pin_model_with_same_joints(model)
    rng = rng_for(model.name, "jacobians")
    for scale in (0.0, 1e-7, 1.0, 3.0):  # the series branches and large rotations
        q, q1 = random_configuration(model, rng), random_configuration(model, rng)
        v = scale * rng.standard_normal(model.nv)
        if scale == 0.0:
            q1 = q.copy()
        mine = rd.integrate_jacobians(model, q, v) + rd.difference_jacobians(model, q, q1)
        for name, x, y in zip(("dq", "dv", "d0", "d1"), mine, _pin_jacobians(pm, q, v, q1)):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-11, err_msg=name)


@random_models
def test_jacobians_are_the_differences(model):
    """Richardson-extrapolated central differences along the tangent directions: error
    O(h^4) times the fifth derivative (up to ~1e-9 at h = 1e-3 for twists of a few radians)
    plus eps / h ~ 1e-13; the tolerance leaves a factor of 10."""
    rng = rng_for(model.name, "jacobian-differences")
    q, q1 = random_configuration(model, rng), random_configuration(model, rng)
    v = rng.standard_normal(model.nv)
    n = model.nv

    out, d = rd.integrate(model, q, v), rd.difference(model, q, q1)
    Jq, Jv = rd.integrate_jacobians(model, q, v)
    J0, J1 = rd.difference_jacobians(model, q, q1)
    fd = [richardson(lambda e: rd.difference(model, out, rd.integrate(model, rd.integrate(model, q, e), v)), n),
          richardson(lambda e: rd.difference(model, out, rd.integrate(model, q, v + e)), n),
          richardson(lambda e: rd.difference(model, rd.integrate(model, q, e), q1) - d, n),
          richardson(lambda e: rd.difference(model, q, rd.integrate(model, q1, e)) - d, n)]
    for name, x, y in zip(("dq", "dv", "d0", "d1"), (Jq, Jv, J0, J1), fd):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-8, err_msg=name)


@pytest.mark.parametrize("path", FLOATING_URDFS[:1])
def test_jacobians_on_a_floating_urdf_agree_with_pinocchio(path):
    model, pm = floating_pair(path)
    rng = rng_for(path, "jacobians")
    q, q1 = random_configuration(model, rng), random_configuration(model, rng)
    v = rng.standard_normal(model.nv)
    mine = rd.integrate_jacobians(model, q, v) + rd.difference_jacobians(model, q, q1)
    for name, x, y in zip(("dq", "dv", "d0", "d1"), mine, _pin_jacobians(pm, q, v, q1)):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-11, err_msg=name)


def test_jacobians_batch_and_bad_input():
    model = RANDOM_MODELS[RANDOM_IDS.index("n7-seed5-floating-br0.3")]
    rng = rng_for("jacobian-batch")
    q, v = random_configuration(model, rng, (2, 3)), rng.standard_normal((2, 3, model.nv))
    Jq, Jv = rd.integrate_jacobians(model, q, v)
    J0, J1 = rd.difference_jacobians(model, q[0, 0], q)
    assert Jq.shape == Jv.shape == J0.shape == J1.shape == (2, 3, model.nv, model.nv)
    for i in np.ndindex(2, 3):
        for x, y in zip((Jq[i], Jv[i]), rd.integrate_jacobians(model, q[i], v[i])):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-15)
        for x, y in zip((J0[i], J1[i]), rd.difference_jacobians(model, q[0, 0], q[i])):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match=rf"v: expected shape \(\.\.\., {model.nv}\)"):
        rd.integrate_jacobians(model, q[0, 0], np.zeros(2))
    with pytest.raises(ValueError, match=r"v contains NaN"):
        rd.integrate_jacobians(model, q[0, 0], np.full(model.nv, np.nan))
    with pytest.raises(ValueError, match=r"q1 contains NaN"):
        rd.difference_jacobians(model, q[0, 0], np.full(model.nq, np.nan))
    bad = q[0, 0].copy()
    bad[3:7] *= 2.0
    with pytest.raises(ValueError, match=r"quaternion q\[3:7\] has norm 2, not 1"):
        rd.integrate_jacobians(model, bad, v[0, 0])
