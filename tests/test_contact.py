"""Contacts: simulation of robots touching the world (robodyn.contact, simulate(contacts=...)).

Checked three ways: identities with the other algorithms (the contact forces close the
equation of motion, rnea(q, v, a) = tau + sum J_c^T f_c, on seeded random trees mixing every
joint type), physics with closed forms (a box on an incline sticks below atan(mu) and slides
with g (sin - mu cos) above; a ball rebounds to e^2 h; a quadruped stands on its weight), and
MuJoCo on the same scenes.
"""

from __future__ import annotations

import functools
import sys
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
from robodyn import joints as J
from robodyn import plots
from robodyn.control import JointPD, laws
from robodyn.algorithms.constrained import frame_kinematics
from robodyn.contact import BodySphere, Box, Capsule, Contacts, Plane, Point, Sphere, StaticBox, shapes_from_urdf
from robodyn.random import random_model, random_state

from conftest import example_robot_data_dir

G = 9.81


def free_body(mass, inertia):
    b = rd.ModelBuilder()
    b.add_link("body", mass=mass, inertia=inertia)
    return b.build(floating_base=True)


def box_inertia(mass, size):
    x, y, z = size
    return mass / 12 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])


BALL_R, BALL_M = 0.1, 1.0
BALL = free_body(BALL_M, 0.4 * BALL_M * BALL_R ** 2 * np.eye(3))
SIZE, BOX_M = np.array([0.2, 0.1, 0.05]), 2.0
BOX = free_body(BOX_M, box_inertia(BOX_M, SIZE))


def ball_drop(height, restitution, duration, dt=1e-3, **settings):
    q0 = np.array([0.0, 0.0, height + BALL_R, 0, 0, 0, 1])
    contacts = Contacts([Sphere("body", BALL_R)], surfaces=[Plane(restitution=restitution)], **settings)
    return rd.simulate(BALL, q0, np.zeros(6), duration, dt, contacts=contacts)


def incline(angle, mu, duration=1.0, dt=1e-3, controller=None):
    """The box resting on a plane tilted by ``angle`` about y (rising along +x): returns the
    trajectory and the downhill direction."""
    n = np.array([-np.sin(angle), 0.0, np.cos(angle)])
    R = Rotation.from_rotvec([0.0, -angle, 0.0]).as_matrix()
    assert np.allclose(R[:, 2], n)
    q0 = np.concatenate([n * SIZE[2] / 2, Rotation.from_matrix(R).as_quat()])
    contacts = Contacts([Box("body", SIZE)], surfaces=[Plane(normal=n, friction=mu)])
    traj = rd.simulate(BOX, q0, np.zeros(6), duration, dt, controller, contacts=contacts)
    return traj, -np.array([np.cos(angle), 0.0, np.sin(angle)])


# --- physics: closed forms -------------------------------------------------------------------

def test_ball_rebounds_to_e_squared_h_and_never_gains_energy():
    h, e = 1.0, 0.8
    traj = ball_drop(h, e, 2.5)
    z = traj.q[:, 2] - BALL_R
    apex = [z[k] for k in range(1, len(z) - 1) if z[k - 1] < z[k] >= z[k + 1]]
    assert len(apex) >= 2
    assert apex[0] == pytest.approx(e ** 2 * h, rel=0.01)
    assert apex[1] == pytest.approx(e ** 4 * h, rel=0.01)
    # the energy never grows (free flight by symplectic Euler, impacts dissipate)
    assert np.all(np.diff(traj.energy) <= 1e-9 * traj.energy[0])
    lost = traj.energy[0] - traj.energy[-1]
    assert lost > 0.5 * (1 - e ** 2) * traj.energy[0]
    assert traj.contact_distance.min() > -1e-9  # no penetration


def test_inelastic_ball_comes_to_rest_on_its_weight():
    traj = ball_drop(0.5, 0.0, 1.0)
    z = traj.q[:, 2] - BALL_R
    landed = np.flatnonzero(z < 1e-9)[0]
    assert np.all(np.abs(z[landed:]) < 1e-9)  # lands on the surface and stays, without sinking
    assert np.all(np.abs(traj.v[landed + 1:]) < 1e-9)
    assert np.allclose(traj.contact_force[landed + 1:, 0], [0, 0, BALL_M * G], rtol=1e-7, atol=1e-6)
    # a bouncing ball also comes to rest: impacts slower than bounce_speed are inelastic
    traj = ball_drop(0.3, 0.5, 3.0)
    assert abs(traj.q[-1, 2] - BALL_R) < 1e-9 and np.abs(traj.v[-1]).max() < 1e-9


def world_velocity(traj):
    """The ball's centre velocity and angular velocity in world axes (the state's are in the body frame)."""
    R = Rotation.from_quat(traj.q[:, 3:7]).as_matrix()
    return np.einsum("kij,kj->ki", R, traj.v[:, :3]), np.einsum("kij,kj->ki", R, traj.v[:, 3:])


def mujoco_ball(mu, v0, duration, dt=1e-3):
    xml = f"""<mujoco><option timestep="{dt}" cone="elliptic" integrator="Euler"/>
      <worldbody><geom type="plane" size="5 5 .1" friction="{mu} 0 0"/>
        <body pos="0 0 {BALL_R}"><freejoint/><geom type="sphere" size="{BALL_R}" mass="{BALL_M}"
          friction="{mu} 0 0"/></body></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qvel[0] = v0
    for _ in range(int(round(duration / dt))):
        mujoco.mj_step(m, d)
    return d.qvel.copy()


def test_a_ball_thrown_sliding_rolls_at_five_sevenths_of_its_speed():
    """Sliding, friction mu m g slows the centre and spins the ball up until it rolls, at
    t = 2 v0 / (7 mu g), with v = 5 v0 / 7 and w = v / r (a solid sphere, I = 2 m r^2 / 5);
    then it rolls for ever (no rolling resistance) without gaining energy. MuJoCo agrees."""
    mu, v0 = 0.3, 2.0
    q0 = np.array([0.0, 0.0, BALL_R, 0, 0, 0, 1])
    contacts = Contacts([Sphere("body", BALL_R)], surfaces=[Plane(friction=mu)])
    traj = rd.simulate(BALL, q0, np.array([v0, 0, 0, 0, 0, 0]), 1.5, 1e-3, contacts=contacts)
    v, w = world_velocity(traj)
    t_roll = 2 * v0 / (7 * mu * G)
    rolling = traj.t > t_roll + 2e-3
    np.testing.assert_allclose(v[rolling], np.broadcast_to([5 * v0 / 7, 0, 0], v[rolling].shape), atol=1e-6)
    np.testing.assert_allclose(w[rolling, 1], 5 * v0 / 7 / BALL_R, rtol=1e-6)
    sliding = traj.t < t_roll - 2e-3
    np.testing.assert_allclose(traj.contact_force[sliding, 0], np.broadcast_to([-mu * BALL_M * G, 0, BALL_M * G],
                                                                               (sliding.sum(), 3)), rtol=1e-6)
    assert np.abs(traj.energy[rolling] - traj.energy[rolling][0]).max() < 1e-6
    np.testing.assert_allclose(mujoco_ball(mu, v0, 1.5)[[0, 4]], [5 * v0 / 7, 5 * v0 / 7 / BALL_R], rtol=2e-3)


def test_box_on_an_incline_sticks_below_atan_mu_and_slides_above():
    mu = 0.5
    for deg in (10.0, 20.0, 25.0):
        traj, _ = incline(np.radians(deg), mu)
        drift = np.linalg.norm(traj.q[:, :3] - traj.q[0, :3], axis=1).max()
        assert drift < 1e-6, (deg, drift)
        f = traj.contact_force[-1].sum(axis=0)
        np.testing.assert_allclose(f, [0, 0, BOX_M * G], rtol=1e-7, atol=1e-6)  # the plane carries the weight
    for deg in (30.0, 40.0):
        a = np.radians(deg)
        traj, down = incline(a, mu)
        s = (traj.q[:, :3] - traj.q[0, :3]) @ down
        t = traj.t
        accel = np.polyfit(t, s, 2)[0] * 2
        assert accel == pytest.approx(G * (np.sin(a) - mu * np.cos(a)), rel=0.01)
        f = traj.contact_force[-1].sum(axis=0)
        n = np.array([-np.sin(a), 0.0, np.cos(a)])
        fn = f @ n
        assert np.linalg.norm(f - fn * n) == pytest.approx(mu * fn, rel=1e-9)  # on the cone's boundary
        assert fn == pytest.approx(BOX_M * G * np.cos(a), rel=1e-7)


def test_friction_threshold_is_atan_mu():
    mu = 0.4
    lo, hi = 0.0, 45.0
    for _ in range(8):
        mid = 0.5 * (lo + hi)
        traj, _ = incline(np.radians(mid), mu, duration=0.3)
        if np.linalg.norm(traj.q[-1, :3] - traj.q[0, :3]) > 1e-6:
            hi = mid
        else:
            lo = mid
    assert 0.5 * (lo + hi) == pytest.approx(np.degrees(np.arctan(mu)), abs=0.5)


def test_capsule_and_point_rest_on_their_lowest_points():
    capsule = Contacts([Capsule("body", 0.05, 0.3, rpy=(0.0, np.pi / 2, 0.0))])  # lying along x
    q0 = np.array([0.0, 0.0, 0.2, 0, 0, 0, 1])
    traj = rd.simulate(BOX, q0, np.zeros(6), 1.0, 1e-3, contacts=capsule)
    assert traj.q[-1, 2] == pytest.approx(0.05, abs=1e-9)
    assert traj.contact_force[-1, :, 2].sum() == pytest.approx(BOX_M * G, rel=1e-7)
    assert traj.contact_names == ("body:capsule[-]@ground", "body:capsule[+]@ground")
    tip = Contacts([Point("body", (0.0, 0.0, -0.1), name="tip")])
    traj = rd.simulate(BOX, q0, np.zeros(6), 0.5, 1e-3, contacts=tip)
    assert traj.contact_names == ("tip@ground",)
    assert traj.q[-1, 2] == pytest.approx(0.1, abs=1e-9)


def test_a_deep_start_is_pushed_out_at_a_bounded_speed():
    q0 = np.array([0.0, 0.0, BALL_R - 0.3, 0, 0, 0, 1])  # 0.3 m inside the ground
    contacts = Contacts([Sphere("body", BALL_R)], max_correction=0.5)
    traj = rd.simulate(BALL, q0, np.zeros(6), 1.0, 1e-3, contacts=contacts)
    assert np.all(np.isfinite(traj.q)) and np.abs(traj.v[:, 2]).max() <= 0.5 + 1e-9
    assert abs(traj.q[-1, 2] - BALL_R) < 1e-3


def test_static_boxes_are_tables_walls_and_steps():
    table = StaticBox((1.0, 1.0, 0.4), center=(0, 0, 0.2), friction=0.5, name="table")
    contacts = Contacts([Sphere("body", BALL_R)], surfaces=[Plane(), table])
    traj = rd.simulate(BALL, [0.2, 0, 1.0, 0, 0, 0, 1], np.zeros(6), 1.0, 1e-3, contacts=contacts)
    assert traj.contact_names == ("body:sphere@ground", "body:sphere@table")
    assert traj.q[-1, 2] == pytest.approx(0.4 + BALL_R, abs=1e-9)  # on the table top
    np.testing.assert_allclose(traj.contact_force[-1], [[0, 0, 0], [0, 0, BALL_M * G]], atol=1e-6)
    np.testing.assert_allclose(traj.contact_normal[-1, 1], [0, 0, 1])
    # rolling off its edge onto the floor
    traj = rd.simulate(BALL, [0.3, 0, 0.4 + BALL_R, 0, 0, 0, 1], [1.0, 0, 0, 0, 0, 0], 1.5, 1e-3, contacts=contacts)
    assert traj.q[-1, 0] > 0.5 + BALL_R and traj.q[-1, 2] == pytest.approx(BALL_R, abs=1e-9)
    edge = traj.contact_normal[:, 1][traj.normal_force[:, 1] > 0]
    assert edge[-1, 0] > 0.5  # it left over the edge, the normal turning towards +x
    # a wall turned by 30 degrees about z: thrown at it, the ball stops against its face
    wall = StaticBox((0.1, 2.0, 1.0), center=(1.0, 0, 0.5), rpy=(0, 0, np.pi / 6), friction=0.0)
    n = np.array([-np.cos(np.pi / 6), -np.sin(np.pi / 6), 0.0])
    traj = rd.simulate(BALL, [0, 0, BALL_R, 0, 0, 0, 1], [2.0, 0, 0, 0, 0, 0], 1.5, 1e-3,
                       contacts=Contacts([Sphere("body", BALL_R)], surfaces=[Plane(friction=0.0), wall]))
    hit = traj.normal_force[:, 1] > 0
    assert hit.any() and np.allclose(traj.contact_normal[hit, 1], n, atol=1e-12)
    centre_to_face = (traj.q[:, :3] - wall.center) @ n - 0.05
    assert centre_to_face.min() > BALL_R - 1e-9  # never through the wall
    # a start deep inside a step leaves through its nearest face, at a bounded speed
    step = StaticBox((1.0, 1.0, 0.2), center=(0, 0, 0.1))
    traj = rd.simulate(BALL, [0, 0, 0.15, 0, 0, 0, 1], np.zeros(6), 1.0, 1e-3,
                       contacts=Contacts([Sphere("body", BALL_R)], surfaces=[step], max_correction=0.3))
    assert np.abs(traj.v[:, 2]).max() <= 0.3 + 1e-9 and traj.q[-1, 2] == pytest.approx(0.2 + BALL_R, abs=1e-6)


def two_balls():
    b = rd.ModelBuilder(gravity=(0, 0, -G))
    b.add_link("world")
    for n in ("a", "b"):
        b.add_link(n, mass=1.0, inertia=0.4 * BALL_R ** 2 * np.eye(3))
        b.add_joint(n + "_free", "free", "world", n)
    return b.build()


def test_spheres_on_bodies_stack_and_collide():
    model = two_balls()
    contacts = Contacts([Sphere("a", BALL_R), Sphere("b", BALL_R)],
                        surfaces=[Plane(friction=0.5), BodySphere("b", BALL_R, friction=0.5)])
    assert contacts.pack(model)[3] == ("a:sphere@ground", "a:sphere@b:sphere", "b:sphere@ground",
                                       "b:sphere@b:sphere")
    q0 = np.array([0, 0, 0.6, 0, 0, 0, 1, 0, 0, BALL_R, 0, 0, 0, 1.0])
    traj = rd.simulate(model, q0, np.zeros(12), 1.0, 1e-3, contacts=contacts)
    assert traj.q[-1, 2] == pytest.approx(3 * BALL_R, abs=1e-9) and traj.q[-1, 9] == pytest.approx(BALL_R, abs=1e-9)
    np.testing.assert_allclose(traj.contact_force[-1, :3], [[0, 0, 0], [0, 0, G], [0, 0, 2 * G]], atol=1e-6)
    assert np.all(np.isinf(traj.contact_distance[:, 3]))  # a body never touches itself
    # head-on, weightless, restitution e: equal masses leave with v (1 - e) / 2 and v (1 + e) / 2
    e, v = 0.6, 2.0
    weightless = model.replace(gravity=np.zeros(3))
    contacts = Contacts([Sphere("a", BALL_R)], surfaces=[BodySphere("b", BALL_R, friction=0.0, restitution=e)])
    q0 = np.array([-0.5, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1.0])
    v0 = np.zeros(12)
    v0[0] = v
    traj = rd.simulate(weightless, q0, v0, 0.5, 1e-3, contacts=contacts)
    np.testing.assert_allclose([traj.v[-1, 0], traj.v[-1, 6]], [v * (1 - e) / 2, v * (1 + e) / 2], rtol=1e-6)
    momentum = traj.v[:, 0] + traj.v[:, 6]
    np.testing.assert_allclose(momentum, v, rtol=1e-9)  # the pair's forces are equal and opposite


# --- identities with the other algorithms ---------------------------------------------------

@pytest.mark.parametrize("seed,types", [(3, (J.REVOLUTE, J.PRISMATIC)), (5, (J.REVOLUTE, J.SPHERICAL, J.HELICAL,
                                                                              J.PLANAR, J.PRISMATIC))],
                         ids=["one-dof", "mixed"])
def test_contact_forces_close_the_equation_of_motion_on_random_trees(seed, types):
    model = random_model(6, seed=seed, floating_base=True, branching=0.4, joint_types=types)
    rng = np.random.default_rng(seed)
    q0, v0 = random_state(model, rng)[:2]
    q0[:3] = 0.0
    q0[2] = 1.5
    v0 *= 0.3
    shapes = [Sphere(i, 0.05) for i in range(model.nbodies)]
    mu = 0.7
    contacts = Contacts(shapes, surfaces=[Plane(height=0.2, friction=mu)])
    traj = rd.simulate(model, q0, v0, 0.8, 1e-3, contacts=contacts)
    f = traj.contact_force
    assert np.count_nonzero(f[:, :, 2] > 1e-6) > 50  # it did touch
    n = np.array([0.0, 0.0, 1.0])
    fn, ft = f @ n, np.linalg.norm(f[..., :2], axis=-1)
    assert fn.min() >= 0.0 and np.all(ft <= mu * fn * (1 + 1e-9) + 1e-12)
    assert np.all(f[traj.contact_distance > contacts.margin + 0.02] == 0.0)  # no force at a distance
    for s in range(0, len(traj.t), 40):
        q, v = traj.q[s], traj.v[s]
        lhs = rd.rnea(model, q, v, traj.a[s]) - traj.tau[s]
        rhs = np.zeros(model.nv)
        poses = rd.forward_kinematics(model, q)
        for i in range(model.nbodies):
            if f[s, i, 2] == 0.0:
                continue
            x = poses[i, :3, 3] - 0.05 * n  # the sphere's lowest point
            r = poses[i, :3, :3].T @ (x - poses[i, :3, 3])
            Jl = frame_kinematics(model, q, v, i, r).J_lin[0]
            rhs += Jl.T @ f[s, i]
        np.testing.assert_allclose(lhs, rhs, rtol=1e-7, atol=1e-7 * (1 + np.abs(rhs).max()))


def test_python_and_compiled_steps_agree():
    contacts = Contacts([Box("body", SIZE)], surfaces=[Plane(normal=(0.1, 0.0, 1.0), friction=0.3)])
    q0 = np.concatenate([[0, 0, 0.3], Rotation.from_rotvec([0.3, 0.2, 0.1]).as_quat()])
    v0 = np.array([0.5, 0.0, 0.0, 1.0, -2.0, 0.5])
    a = rd.simulate(BOX, q0, v0, 0.6, 1e-3, contacts=contacts)
    b = rd.simulate(BOX, q0, v0, 0.6, 1e-3, lambda t, q, v: np.zeros(6), contacts=contacts)
    for key in ("q", "v", "a", "contact_force", "contact_distance", "solver_residual"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key), err_msg=key)
    assert np.count_nonzero(a.contact_force[:, :, 2]) > 100


# --- a quadruped standing -------------------------------------------------------------------

SOLO_FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
STANCE = np.array([0, 0.8, -1.6] * 2 + [0, -0.8, 1.6] * 2)


@functools.cache
def solo12():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)  # the URDF's <contact> elements
        return rd.load_urdf(example_robot_data_dir() / "solo_description/robots/solo12.urdf", floating_base=True)


def test_solo12_dropped_on_the_ground_stands_on_its_weight():
    model = solo12()
    mu = 0.9
    contacts = Contacts([Sphere(f, 0.0175) for f in SOLO_FEET], surfaces=[Plane(friction=mu)])
    stance = STANCE
    q0 = np.concatenate([[0, 0, 0.5], [0, 0, 0, 1], stance])  # feet about 0.25 m above the floor

    def standing(t, q, v):  # joint PD about the stance, the base unactuated
        tau = np.zeros(model.nv)
        tau[6:] = 8.0 * (stance - q[7:]) - 0.3 * v[6:]
        return tau

    traj = rd.simulate(model, q0, np.zeros(model.nv), 2.0, 1e-3, standing, contacts=contacts)
    assert traj.contact_distance[0].min() > 0.2
    rest = traj.t >= 1.5
    assert np.abs(traj.v[rest]).max() < 1e-6  # settled
    f = traj.contact_force[rest]
    np.testing.assert_allclose(f[:, :, 2].sum(axis=1), model.total_mass * G, rtol=1e-3)
    assert np.all(f[:, :, 2] > 0) and np.all(np.hypot(f[..., 0], f[..., 1]) <= mu * f[..., 2])
    feet = np.array([[rd.frame_pose(model, q, foot)[:3, 3] for foot in SOLO_FEET] for q in traj.q[rest]])
    assert np.abs(feet - feet[0]).max() < 1e-6  # no slip
    assert np.abs(feet[..., 2] - 0.0175).max() < 1e-6  # on the floor, not in it


def test_solo12_example_stands():
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import solo12_standing as ex

    model, traj = ex.run(example_robot_data_dir() / "solo_description/robots/solo12.urdf", duration=1.0)
    assert traj.normal_force[-1].sum() == pytest.approx(model.total_mass * G, rel=1e-6)
    assert np.all(traj.friction_force[-1] < 0.9 * traj.normal_force[-1])


def test_joint_pd_is_compiled_and_leaves_a_floating_base_unactuated():
    model = solo12()
    q0 = np.concatenate([[0, 0, 0.5], [0, 0, 0, 1], STANCE])
    ctrl = JointPD(model, q0, kp=8.0, kd=0.3, tau_ff=np.full(12, 0.1))
    rng = np.random.default_rng(1)
    q, v = rd.random.random_state(model, rng)[:2]
    tau = ctrl(0.0, q, v)
    np.testing.assert_array_equal(tau[:6], 0.0)
    np.testing.assert_allclose(tau[6:], 0.1 + 8.0 * (STANCE - q[7:]) - 0.3 * v[6:], rtol=1e-12)
    assert ctrl.kernel_law()[0] == laws.JOINT_PD
    np.testing.assert_array_equal(JointPD(model, STANCE, 8.0, 0.3).q_d, STANCE)  # the joints alone
    contacts = Contacts([Sphere(f, 0.0175) for f in SOLO_FEET])
    compiled = rd.simulate(model, q0, np.zeros(model.nv), 0.5, 1e-3, ctrl, contacts=contacts)
    python = rd.simulate(model, q0, np.zeros(model.nv), 0.5, 1e-3, lambda t, q, v: ctrl(t, q, v), contacts=contacts)
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(compiled.contact_force, python.contact_force, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(compiled.tau[:, :6], 0.0)
    with pytest.raises(ValueError, match="q_desired: expected"):
        JointPD(model, np.zeros(5), 1.0, 1.0)
    with pytest.raises(ValueError, match="kp: gains must be finite and > 0"):
        JointPD(model, STANCE, -1.0, 1.0)
    with pytest.raises(ValueError, match="tau_ff: expected"):
        JointPD(model, STANCE, 1.0, 1.0, tau_ff=np.zeros(3))
    spherical = random_model(3, seed=0, joint_types=(J.SPHERICAL,))
    with pytest.raises(ValueError, match="every joint but a root free joint must have one dof"):
        JointPD(spherical, np.zeros(spherical.nq), 1.0, 1.0)


def test_plot_contacts_draws_the_forces_and_the_cones_used(tmp_path):
    traj, _ = incline(np.radians(35.0), 0.5, duration=0.2)
    data = plots.plot_contacts(traj, tmp_path / "contacts.png")
    assert (tmp_path / "contacts.png").stat().st_size > 0
    assert data["names"] == traj.contact_names and len(data["names"]) == 8
    np.testing.assert_allclose(np.nansum(data["normal"][-1]), BOX_M * G * np.cos(np.radians(35.0)), rtol=1e-7)
    used = data["cone_usage"][-1]
    np.testing.assert_allclose(used[np.isfinite(used)], 1.0, rtol=1e-9)  # sliding: on the cones
    with pytest.raises(ValueError, match="has no contacts"):
        plots.plot_contacts(rd.simulate(BOX, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.01, 1e-3))


URDF_WITH_COLLISIONS = """<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/></inertial>
    <collision><origin xyz="0 0 -0.1"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0.1 0 0" rpy="0 0 0.5"/><geometry><box size="0.2 0.1 0.05"/></geometry></collision>
    <collision><geometry><cylinder radius="0.02" length="0.3"/></geometry></collision>
    <collision><geometry><mesh filename="package://r/m.stl"/></geometry></collision>
  </link>
  <link name="foot"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
  <joint name="fix" type="fixed"><parent link="base"/><child link="foot"/><origin xyz="0 0 -0.3"/></joint>
</robot>"""


def test_shapes_from_urdf_collisions():
    with pytest.warns(rd.RobodynWarning, match=r"1 mesh collision geometries not read \(links base\)"):
        shapes = shapes_from_urdf(URDF_WITH_COLLISIONS)
    sphere, box, capsule, foot = shapes
    assert isinstance(sphere, Sphere) and sphere.radius == 0.05 and sphere.center.tolist() == [0, 0, -0.1]
    assert isinstance(box, Box) and box.size.tolist() == [0.2, 0.1, 0.05]
    assert box.center.tolist() == [0.1, 0, 0] and box.rpy.tolist() == [0, 0, 0.5]
    assert isinstance(capsule, Capsule) and capsule.radius == 0.02 and capsule.length == pytest.approx(0.26)
    assert [s.name for s in shapes] == ["base:sphere0", "base:box1", "base:cylinder2", "foot:sphere0"]
    assert foot.body == "foot"  # a link merged into base by a fixed joint: a frame of the model
    assert [s.name for s in shapes_from_urdf(URDF_WITH_COLLISIONS, links=["foot"])] == ["foot:sphere0"]
    # dropped on the ground, the free body rests on the foot sphere (the lowest shape)
    model = rd.load_urdf(URDF_WITH_COLLISIONS, floating_base=True)
    traj = rd.simulate(model, [0, 0, 1.0, 0, 0, 0, 1], np.zeros(6), 1.0, 1e-3,
                       contacts=Contacts(shapes_from_urdf(URDF_WITH_COLLISIONS, links=["foot"])))
    assert traj.q[-1, 2] == pytest.approx(0.33, abs=1e-9)
    with pytest.raises(rd.ModelError, match="a cylinder"):
        shapes_from_urdf(URDF_WITH_COLLISIONS, cylinders="error")
    with pytest.raises(rd.ModelError, match=r"a mesh \(package://r/m.stl\)"):
        shapes_from_urdf(URDF_WITH_COLLISIONS, meshes="error")
    for geometry, match in (("", "expected one geometry in <geometry>, got 0"),
                            ('<cone radius="1"/>', "unknown geometry <cone>"),
                            ('<sphere radius="-1"/>', "sizes must be > 0"), ('<box size="1 1"/>', "needs 3 number")):
        xml = f'<robot name="r"><link name="a"><collision><geometry>{geometry}</geometry></collision></link></robot>'
        with pytest.raises(rd.ModelError, match=match):
            shapes_from_urdf(xml)


def test_anymal_stands_on_its_urdf_foot_spheres():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        path = example_robot_data_dir() / "anymal_b_simple_description/robots/anymal.urdf"
        model = rd.load_urdf(path, floating_base=True)
    feet = ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"]
    shapes = shapes_from_urdf(path, links=feet)
    assert [type(s) for s in shapes] == [Sphere] * 4 and {s.radius for s in shapes} == {0.031}
    q0 = rd.random.random_configuration(model, np.random.default_rng(0)) * 0
    q0[6] = 1.0
    q0[2] = 0.7
    traj = rd.simulate(model, q0, np.zeros(model.nv), 1.5, 1e-3, JointPD(model, q0, 200.0, 5.0),
                       contacts=Contacts(shapes))
    np.testing.assert_allclose(traj.normal_force[-1].sum(), model.total_mass * G, rtol=1e-6)
    assert np.abs(traj.v[-1]).max() < 1e-3  # settling


def test_animate_draws_the_surfaces_and_the_contact_points(tmp_path):
    table = StaticBox((1.0, 1.0, 0.4), center=(0, 0, 0.2))
    contacts = Contacts([Sphere("body", BALL_R)], surfaces=[Plane(), table])
    traj = rd.simulate(BALL, [0.3, 0, 0.4 + BALL_R, 0, 0, 0, 1], [1.0, 0, 0, 0, 0, 0], 1.0, 1e-3, contacts=contacts)
    data = plots.animate(BALL, traj.t, traj.q, tmp_path / "ball.gif", fps=10, contacts=contacts)
    assert (tmp_path / "ball.gif").stat().st_size > 0 and data["axes"] == ("x", "z")
    np.testing.assert_allclose(data["contact_points"][:, 0], traj.q[::100][:, [0, 2]], atol=1e-12)
    model = solo12()
    q0 = np.concatenate([[0, 0, 0.5], [0, 0, 0, 1], STANCE])
    feet = Contacts([Sphere(f, 0.0175) for f in SOLO_FEET])
    data = plots.animate(model, [0.0, 0.1], [q0, q0], tmp_path / "solo.gif", fps=10, contacts=feet)
    assert data["contact_points"].shape == (2, 4, 3)
    np.testing.assert_allclose(data["contact_points"][0], [rd.frame_pose(model, q0, f)[:3, 3] for f in SOLO_FEET])


# --- MuJoCo on the same scenes ---------------------------------------------------------------

def mujoco_box(angle_deg, mu, duration=1.0, dt=1e-3):
    """The box on MuJoCo's plane with gravity tilted by ``angle`` (elliptic cones, Euler):
    the displacement along the slope after ``duration`` and the resting normal force."""
    a = np.radians(angle_deg)
    g = G * np.array([np.sin(a), 0.0, -np.cos(a)])
    half = SIZE / 2
    xml = f"""<mujoco><option timestep="{dt}" gravity="{g[0]} {g[1]} {g[2]}" cone="elliptic" integrator="Euler"/>
      <worldbody><geom type="plane" size="5 5 .1" friction="{mu} 0 0"/>
        <body pos="0 0 {half[2]}"><freejoint/>
          <geom type="box" size="{half[0]} {half[1]} {half[2]}" mass="{BOX_M}" friction="{mu} 0 0"/></body>
      </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    for _ in range(int(round(duration / dt))):
        mujoco.mj_step(m, d)
    return d.qpos[0], d.qfrc_constraint[:3].copy()


def test_box_on_a_plane_agrees_with_mujoco():
    """Sliding: MuJoCo's soft contacts and robodyn's rigid ones give the same Coulomb force,
    so the displacements agree to 0.5 %. Sticking: MuJoCo's friction is soft (its constraint
    impedance lets a loaded contact creep, here about 1 mm in 1 s at 20 degrees); robodyn's
    does not creep. Resting: both carry the weight."""
    mu = 0.5
    for deg in (30.0, 40.0):
        x_mj, _ = mujoco_box(deg, mu)
        traj, down = incline(np.radians(deg), mu)
        assert (traj.q[-1, :3] - traj.q[0, :3]) @ down == pytest.approx(x_mj, rel=5e-3)
    x_mj, _ = mujoco_box(20.0, mu)
    traj, down = incline(np.radians(20.0), mu)
    assert abs((traj.q[-1, :3] - traj.q[0, :3]) @ down) < 1e-6 < abs(x_mj) < 5e-3
    _, f_mj = mujoco_box(0.0, mu)
    traj, _ = incline(0.0, mu)
    np.testing.assert_allclose(traj.contact_force[-1].sum(axis=0), f_mj, rtol=1e-6, atol=1e-6)


# --- bad input and the solver's reports --------------------------------------------------------

@pytest.mark.parametrize("make,match", [
    (lambda: Plane(friction=-0.1), "friction: must be >= 0"),
    (lambda: Plane(restitution=1.5), "restitution: must lie in"),
    (lambda: Plane(normal=(0, 0, 0)), "normal: must not be zero"),
    (lambda: Plane(height=np.nan), "NaN"),
    (lambda: Sphere("body", 0.0), "radius: must be > 0"),
    (lambda: Sphere("body", 0.1, center=(0, np.nan, 0)), "center: contains NaN"),
    (lambda: Box("body", (0.1, 0.0, 0.1)), "every edge must be > 0"),
    (lambda: StaticBox((1.0, -1.0, 1.0)), "StaticBox.size: every edge must be > 0"),
    (lambda: StaticBox((1.0, 1.0, 1.0), center=(0, np.inf, 0)), "StaticBox.center: contains NaN or Inf"),
    (lambda: StaticBox((1.0, 1.0, 1.0), friction=-1), "StaticBox.friction: must be >= 0"),
    (lambda: BodySphere("body", 0.0), "BodySphere.radius: must be > 0"),
    (lambda: BodySphere("body", 0.1, restitution=2), "BodySphere.restitution: must lie in"),
    (lambda: Capsule("body", -0.1, 0.2), "radius: must be > 0"),
    (lambda: Sphere(1.5, 0.1), "expected a link or frame name"),
    (lambda: Contacts([]), "at least one shape"),
    (lambda: Contacts(["body"]), r"shapes\[0\]: expected a Sphere"),
    (lambda: Contacts([Sphere("body", 0.1)], surfaces=["ground"]),
     r"surfaces\[0\]: expected a Plane, StaticBox or BodySphere"),
    (lambda: Contacts([Sphere("body", 0.1)], max_iterations=0), "max_iterations"),
    (lambda: Contacts([Sphere("body", 0.1)], tolerance=-1), "tolerance: must be > 0"),
    (lambda: Contacts([Sphere("body", 0.1)], stabilization=2), "stabilization: must lie in"),
])
def test_bad_geometry_is_refused(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_bad_use_is_refused():
    contacts = Contacts([Sphere("nowhere", 0.1)])
    with pytest.raises(ValueError, match=r"shapes\[0\]: unknown link or frame 'nowhere'"):
        rd.simulate(BALL, [0, 0, 1, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, contacts=contacts)
    contacts = Contacts([Sphere("body", 0.1)])
    with pytest.raises(ValueError, match="with contacts the time stepping is 'semi_implicit_euler'"):
        rd.simulate(BALL, [0, 0, 1, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, integrator="rk4", contacts=contacts)
    with pytest.raises(ValueError, match="contacts: expected a robodyn.contact.Contacts"):
        rd.simulate(BALL, [0, 0, 1, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, contacts=[Sphere("body", 0.1)])
    with pytest.raises(ValueError, match="q0: contains NaN"):
        rd.simulate(BALL, [0, 0, np.nan, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3, contacts=contacts)
    with pytest.raises(ValueError, match="simulate at t = 0.05.*NaN"):
        rd.simulate(BALL, [0, 0, 1, 0, 0, 0, 1], np.zeros(6), 0.1, 1e-3,
                    lambda t, q, v: np.full(6, np.nan if t > 0.0499 else 0.0), contacts=contacts)


def test_a_solve_that_does_not_converge_is_reported():
    contacts = Contacts([Box("body", SIZE)], surfaces=[Plane(friction=0.5)], max_iterations=2, warn_above=1e-9)
    q0 = np.concatenate([[0, 0, 0.2], Rotation.from_rotvec([0.4, 0.3, 0.0]).as_quat()])
    with pytest.warns(rd.RobodynWarning, match=r"contact solver stopped above 1e-09 m/s in \d+ of 501 steps"):
        traj = rd.simulate(BOX, q0, np.zeros(6), 0.5, 1e-3, contacts=contacts)
    assert np.all(np.isfinite(traj.q)) and traj.solver_residual.max() > 1e-9
    assert traj.solver_iterations.max() == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        traj = rd.simulate(BOX, q0, np.zeros(6), 0.5, 1e-3, contacts=Contacts([Box("body", SIZE)]))
    assert traj.solver_residual.max() < 1e-6


def test_contact_scenes_example(capsys):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import contact_scenes as ex

    _, _, ball = ex.bouncing_ball(duration=2.0)
    ratios = [float(x) for x in capsys.readouterr().out.split("=")[1].strip(" []\n").replace("np.float64(", "")
              .replace(")", "").split(",")]
    assert len(ratios) >= 3 and np.allclose(ratios[:3], 1.0, atol=0.01)
    for degrees, expected in ((35.0, G * (np.sin(np.radians(35)) - 0.5 * np.cos(np.radians(35)))), (20.0, 0.0)):
        _, _, traj = ex.box_on_incline(degrees)
        accel = float(capsys.readouterr().out.split("acceleration ")[1].split(" m/s^2")[0])
        assert accel == pytest.approx(expected, rel=0.01, abs=1e-5)
    model, _, traj = ex.hopper()
    # a turning foot may sink by the second-order motion of a step (here about 1e-8 m); the body never falls
    assert traj.contact_distance.min() > -1e-6 and traj.q[:, 1].min() > 0.3
    touching = traj.normal_force[:, 0] > 0
    landings = int(np.count_nonzero(np.diff(touching.astype(int)) == 1))
    assert landings >= 2 and np.all(traj.normal_force[~touching, 0] == 0.0)  # it hops, and flies between
    assert f"{landings} touchdowns" in capsys.readouterr().out
