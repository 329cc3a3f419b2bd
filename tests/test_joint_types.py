"""Spherical (ball) and helical (screw) joints: Pinocchio's JointModelSpherical and
JointModelHelicalUnaligned on random trees mixing every joint type, Euler's equations of a body
about a fixed point, a screw's closed form, a spherical pendulum's conserved quantities in
simulation, and the places these joints cannot go.

The identities of every algorithm run on random trees with these joints too (the ``-mixed``
cases of ``helpers.RANDOM_CASES``)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import assert_rel, quat_to_matrix, rng_for
from robodyn import joints as J
from robodyn.interop import from_pinocchio, to_pinocchio
from robodyn.random import random_model, random_state

MIXED = (J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL, J.PLANAR)
CASES = [(7, seed, False) for seed in (4, 6, 7)] + [(7, seed, True) for seed in (5, 8, 11)]


def mixed_model(n, seed, floating_base):
    model = random_model(n, seed=seed, floating_base=floating_base, branching=0.4, joint_types=MIXED)
    for kind in (J.SPHERICAL, J.HELICAL, J.PLANAR):
        assert np.sum(model.joint_type == kind) >= 1, J.NAMES[kind]
    return model


@pytest.mark.parametrize("n, seed, floating_base", CASES)
def test_random_trees_agree_with_pinocchio(n, seed, floating_base):
    model = mixed_model(n, seed, floating_base)
    pm = to_pinocchio(model)
    kinds = [pm.joints[j].shortname() for j in range(1, pm.njoints)]
    assert kinds.count("JointModelSpherical") == int(np.sum(model.joint_type == J.SPHERICAL))
    assert kinds.count("JointModelHelicalUnaligned") == int(np.sum(model.joint_type == J.HELICAL))
    assert kinds.count("JointModelPlanar") == int(np.sum(model.joint_type == J.PLANAR))
    pd = pm.createData()
    q, v, a = random_state(model, rng_for("spherical-pin", seed, floating_base))
    tau = rd.rnea(model, q, v, a, friction=False)
    assert_rel(tau, pin.rnea(pm, pd, q, v, a), 1e-10, "rnea")
    assert_rel(rd.aba(model, q, v, tau, friction=False), a, 1e-9, "aba")
    M = rd.crba(model, q)
    pin.crba(pm, pd, q)
    assert_rel(M, np.triu(pd.M) + np.triu(pd.M, 1).T, 1e-10, "crba")
    assert_rel(rd.inverse_mass_matrix(model, q), np.linalg.inv(M), 1e-9, "inverse_mass_matrix")
    assert_rel(rd.coriolis_matrix(model, q, v), pin.computeCoriolisMatrix(pm, pd, q, v), 1e-10, "coriolis")
    assert_rel(rd.kinetic_energy(model, q, v), pin.computeKineticEnergy(pm, pd, q, v), 1e-10, "kinetic energy")
    pin.computeJointJacobians(pm, pd, q)
    pin.updateFramePlacements(pm, pd)
    last = model.link_names[-1]
    J_pin = pin.getFrameJacobian(pm, pd, pm.getFrameId(last), pin.LOCAL)
    assert_rel(rd.jacobian(model, q, last, frame="local"), J_pin, 1e-10, "jacobian")
    dq, dv, _ = rd.rnea_derivatives(model, q, v, a)
    pin.computeRNEADerivatives(pm, pd, q, v, a)
    assert_rel(dq, pd.dtau_dq, 1e-9, "dtau_dq")
    assert_rel(dv, pd.dtau_dv, 1e-9, "dtau_dv")
    da_dq, da_dv, _ = rd.aba_derivatives(model, q, v, tau)
    pin.computeABADerivatives(pm, pd, q, v, tau)
    assert_rel(da_dq, pd.ddq_dq, 1e-8, "da_dq")
    assert_rel(da_dv, pd.ddq_dv, 1e-8, "da_dv")
    q1 = random_state(model, rng_for("spherical-q1", seed))[0]
    assert_rel(rd.difference(model, q, q1), pin.difference(pm, q, q1), 1e-10, "difference")
    Jq, Jv = rd.integrate_jacobians(model, q, 0.3 * v)
    assert_rel(Jq, pin.dIntegrate(pm, q, 0.3 * v, pin.ARG0), 1e-10, "dIntegrate/dq")
    assert_rel(Jv, pin.dIntegrate(pm, q, 0.3 * v, pin.ARG1), 1e-10, "dIntegrate/dv")
    J0, J1 = rd.difference_jacobians(model, q, q1)
    assert_rel(J0, pin.dDifference(pm, q, q1, pin.ARG0), 1e-9, "dDifference/dq0")
    assert_rel(J1, pin.dDifference(pm, q, q1, pin.ARG1), 1e-9, "dDifference/dq1")
    back = from_pinocchio(pm)
    np.testing.assert_array_equal(back.joint_type, model.joint_type)
    np.testing.assert_allclose(back.joint_pitch, model.joint_pitch, rtol=1e-15, atol=0)


def test_euler_equations_about_a_fixed_point():
    """A body on a ball joint at its pivot: ``tau = I_o w' + w x I_o w - m c x (R^T g)``
    (Euler's equations about a fixed point, gravity's moment about the pivot)."""
    rng = rng_for("euler")
    m, c = 2.5, np.array([0.1, -0.2, 0.3])
    Ic = np.array([[0.3, 0.01, 0.02], [0.01, 0.2, -0.03], [0.02, -0.03, 0.25]])
    b = rd.ModelBuilder("top")
    b.add_link("pivot")
    b.add_link("body", mass=m, com=c, inertia=Ic)
    b.add_joint("ball", "spherical", "pivot", "body", xyz=(0, 0, 1), rpy=(0.2, -0.1, 0.4))
    model = b.build()
    assert (model.nq, model.nv) == (4, 3) and model.joint_names == ()
    quat = rng.standard_normal(4)
    q, w, wd = quat / np.linalg.norm(quat), rng.standard_normal(3), rng.standard_normal(3)
    Io = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
    R = model.X_tree_R[0] @ quat_to_matrix(q)
    g_body = R.T @ model.gravity
    expected = Io @ wd + np.cross(w, Io @ w) - m * np.cross(c, g_body)
    assert_rel(rd.rnea(model, q, w, wd), expected, 1e-12, "rnea")
    assert_rel(rd.crba(model, q), Io, 1e-12, "crba")
    assert_rel(rd.aba(model, q, w, expected), wd, 1e-11, "aba")
    assert_rel(rd.kinetic_energy(model, q, w), 0.5 * w @ Io @ w, 1e-12, "kinetic energy")


def test_screw_closed_form():
    """A body on a vertical screw of pitch h, its centre of mass on the axis: kinetic energy
    ``(Izz + m h^2) qd^2 / 2``, potential ``m g h q``, so ``tau = (Izz + m h^2) qdd + m g h``."""
    m, h, Izz = 3.0, 0.05, 0.2
    b = rd.ModelBuilder("screw")
    b.add_link("nut")
    b.add_link("bolt", mass=m, com=(0, 0, 0.3), inertia=np.diag([0.1, 0.15, Izz]))
    b.add_joint("screw", "helical", "nut", "bolt", axis=(0, 0, 2), pitch=h)
    model = b.build()
    assert model.joint_names == ("screw",) and model.joint_pitch.tolist() == [h]
    g = 9.81
    for q, qd, qdd in ((0.3, 1.5, -2.0), (-4.0, 0.0, 0.7)):
        assert_rel(rd.rnea(model, [q], [qd], [qdd]), [(Izz + m * h * h) * qdd + m * g * h], 1e-12, "rnea")
        assert_rel(rd.crba(model, [q]), [[Izz + m * h * h]], 1e-12, "crba")
        assert_rel(rd.kinetic_energy(model, [q], [qd]), 0.5 * (Izz + m * h * h) * qd * qd, 1e-12, "energy")
        np.testing.assert_allclose(rd.frame_pose(model, [q], "bolt")[2, 3], h * q, rtol=1e-15, atol=1e-15)
    with pytest.raises(rd.ModelError, match="pitch 0.1 on a revolute joint"):
        bad = rd.ModelBuilder("bad")
        bad.add_link("a")
        bad.add_link("b", mass=1.0)
        bad.add_joint("j", "revolute", "a", "b", pitch=0.1)


def test_planar_body_closed_form():
    """A body moving in a horizontal plane (gravity along the normal does no work): with its
    centre of mass at c in the body frame, ``M = [[m, 0, -m cy], [0, m, m cx], [-m cy, m cx,
    Izz + m |c|^2]]`` on ``[vx, vy, wz]``, and the bias of a turning body is the centripetal
    force ``-m w^2 c`` (body frame) plus the Coriolis term of the sliding velocity."""
    m, c, Izz = 2.0, np.array([0.3, -0.1, 0.05]), 0.2
    b = rd.ModelBuilder("puck")
    b.add_link("table")
    b.add_link("puck", mass=m, com=c, inertia=np.diag([0.1, 0.1, Izz]))
    b.add_joint("slide", "planar", "table", "puck", xyz=(0, 0, 1))
    model = b.build()
    assert (model.nq, model.nv) == (4, 3) and model.joint_names == ()
    t = 0.8
    q = np.array([0.5, -0.4, np.cos(t), np.sin(t)])
    M = np.array([[m, 0, -m * c[1]], [0, m, m * c[0]], [-m * c[1], m * c[0], Izz + m * (c[0] ** 2 + c[1] ** 2)]])
    assert_rel(rd.crba(model, q), M, 1e-12, "crba")
    vx, vy, w = 0.7, -0.3, 1.5
    # d/dt of the body-frame momentum: (p_lin)' + w x p_lin, with p_lin = m (v + w x c)
    vel_c = np.array([vx - w * c[1], vy + w * c[0], 0.0])  # velocity of the centre of mass, body axes
    force = m * np.cross([0, 0, w], vel_c)
    torque = np.cross(c, force)[2]
    assert_rel(rd.nonlinear_effects(model, q, [vx, vy, w]), [force[0], force[1], torque], 1e-12, "bias")
    with pytest.raises(ValueError, match=r"rnea: q: \(cos, sin\) of planar joint 'slide' \(q\[2:4\]\) has norm 2"):
        rd.rnea(model, [0, 0, 2.0, 0], np.zeros(3), np.zeros(3))


def test_universal_joint_is_pinocchios():
    """A universal joint, built as two revolute joints on a massless cross, has the dynamics of
    Pinocchio's JointModelUniversal (same q and v)."""
    rng = rng_for("universal")
    a1, a2 = np.array([1.0, 0, 0]), np.array([0, 0.6, 0.8])
    placement = pin.SE3(pin.utils.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.1, 0.2, 0.3]))
    inertia = pin.Inertia(1.5, np.array([0.1, -0.05, 0.2]), np.diag([0.02, 0.03, 0.04]))
    pm = pin.Model()
    j = pm.addJoint(0, pin.JointModelUniversal(a1, a2), placement, "cardan")
    pm.appendBodyToJoint(j, inertia, pin.SE3.Identity())
    b = rd.ModelBuilder("cardan")
    b.add_link("base")
    b.add_link("shaft", mass=1.5, com=inertia.lever, inertia=inertia.inertia)
    b.add_joint("cardan", "universal", "base", "shaft", xyz=placement.translation, rotation=placement.rotation,
                axis=a1, axis2=a2, lower=(-1, -2), upper=(1, 2), damping=0.3)
    model = b.build()
    assert model.joint_names == ("cardan[1]", "cardan[2]") and model.link_names == ("shaft:cardan", "shaft")
    assert model.lower.tolist() == [-1, -2] and model.damping.tolist() == [0.3, 0.3]
    q, v, a = rng.standard_normal(2), rng.standard_normal(2), rng.standard_normal(2)
    pd = pm.createData()
    assert_rel(rd.rnea(model, q, v, a, friction=False), pin.rnea(pm, pd, q, v, a), 1e-12, "rnea")
    assert_rel(rd.crba(model, q), pin.crba(pm, pd, q), 1e-12, "crba")
    with pytest.raises(rd.ModelError, match="are parallel"):
        b.add_joint("bad", "universal", "base", "shaft", axis=a1, axis2=2 * a1)
    with pytest.raises(rd.ModelError, match="needs axis2"):
        b.add_joint("bad", "universal", "base", "shaft")


def spherical_pendulum():
    b = rd.ModelBuilder("spherical_pendulum")
    b.add_link("pivot")
    b.add_link("bob", mass=1.5, com=(0, 0, -0.8), inertia=np.diag([0.02, 0.03, 0.01]))
    b.add_joint("ball", "spherical", "pivot", "bob")
    return b.build()


def test_spherical_pendulum_conserves_energy_and_vertical_angular_momentum():
    model = spherical_pendulum()
    rng = rng_for("pendulum")
    quat = rng.standard_normal(4)
    q0, v0 = quat / np.linalg.norm(quat), 2.0 * rng.standard_normal(3)
    traj = rd.simulate(model, q0, v0, 1.0, 1e-3)

    def vertical_momentum(q, w):  # world z component of the angular momentum about the pivot
        R = quat_to_matrix(q)
        return (R @ (rd.crba(model, q) @ w))[2]

    L0 = vertical_momentum(traj.q[0], traj.v[0])
    for k in (250, 500, 1000):
        assert abs(vertical_momentum(traj.q[k], traj.v[k]) - L0) <= 1e-8 * max(1.0, abs(L0))
    assert np.ptp(traj.energy) <= 1e-8 * np.abs(traj.kinetic).max()
    np.testing.assert_allclose(np.linalg.norm(traj.q, axis=1), 1.0, rtol=0, atol=1e-14)


def test_coordinate_names_and_display():
    model = spherical_pendulum()
    assert model.q_names == ["ball:qx", "ball:qy", "ball:qz", "ball:qw"]
    assert model.dof_names == ["ball:wx", "ball:wy", "ball:wz"]
    assert "spherical" in str(model)
    assert (model.lower == -np.inf).all() and (model.upper == np.inf).all()


def test_quaternion_errors_name_the_spherical_joint():
    model = spherical_pendulum()
    with pytest.raises(ValueError, match=r"rnea: q: quaternion of spherical joint 'ball' \(q\[0:4\]\) has norm 2"):
        rd.rnea(model, [0, 0, 0, 2.0], np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match=r"integrate: q: quaternion q\[0:4\] has norm 2"):
        rd.integrate(model, [0, 0, 0, 2.0], np.zeros(3))


def test_where_these_joints_cannot_go():
    model = spherical_pendulum()
    with pytest.raises(ValueError, match="joint 'ball' is spherical, which URDF cannot express"):
        rd.write_urdf(model)
    with pytest.raises(rd.ModelError, match="has a spherical joint; robodyn.symbolic derives"):
        rd.symbolic.from_model(model)
    screw = rd.ModelBuilder("screw")
    screw.add_link("nut")
    screw.add_link("bolt", mass=1.0, inertia=np.eye(3) * 0.01)
    screw.add_joint("screw", "helical", "nut", "bolt", pitch=0.01)
    screw = screw.build()
    with pytest.raises(ValueError, match="joint 'screw' is helical, which URDF cannot express"):
        rd.write_urdf(screw)
    with pytest.raises(ValueError, match="joint 'screw' is helical, which MJCF cannot express"):
        rd.write_mjcf(screw)
    with pytest.raises(rd.ModelError, match="has a helical joint; robodyn.symbolic derives"):
        rd.symbolic.from_model(screw)
    with pytest.raises(rd.ModelError, match=r"body 0: joint_pitch 0.1 on a revolute joint"):
        rd.models.load("pendulum").replace(joint_pitch=[0.1])
