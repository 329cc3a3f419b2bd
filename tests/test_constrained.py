"""Constrained dynamics (robodyn.constrained_dynamics): the KKT system on random trees, the
constraint kinematics against the Jacobians and finite differences, a point-mass pendulum on a
rod against the one-joint pendulum, a four-bar linkage simulated for 5 s, redundant
constraints, batches and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import robodyn as rd
from helpers import (G, assert_rel, directional_derivative, integrate, massless_leaf_model, pendulum, random_model,
                     rk4, rng_for, states)
from robodyn.algorithms.constrained import constraint_jacobian, frame_kinematics

TREES = [random_model(12, seed=11, branching=0.3), random_model(10, seed=12, floating_base=True, branching=0.3)]
TREE_IDS = ["fixed", "floating"]


def _constraints(model, q):
    """One constraint of each type on ``model`` (at least 10 bodies), the point one consistent
    at ``q``: 8 independent rows."""
    names = model.link_names
    T = rd.frame_pose(model, q, names[-1])
    point = np.array([0.1, -0.2, 0.05])
    return [
        rd.PointConstraint(names[-1], point, T[:3, 3] + T[:3, :3] @ point),
        rd.CouplingConstraint(model.joint_names[-2], model.joint_names[-3], ratio=-1.5, offset=0.2),
        rd.LoopConstraint(names[5], (0.1, 0.0, 0.0), names[8], (0.0, 0.2, 0.1)),
        rd.DistanceConstraint(names[3], (0.0, 0.1, 0.0), None, (0.5, 0.5, 0.5), length=1.3),
    ]


def _kkt(model, q, v, tau, constraints, alpha, beta):
    """Dense solve of [[M, J^T], [J, 0]] [a; -lambda] = [tau - h; -Jdot v - 2 alpha J v - beta^2 phi]."""
    J, Jdv, phi = (x[0] for x in constraint_jacobian(model, q, v, constraints))
    M, h = rd.crba(model, q), rd.rnea(model, q, v, np.zeros(model.nv))
    m = J.shape[0]
    K = np.block([[M, J.T], [J, np.zeros((m, m))]])
    sol = np.linalg.solve(K, np.concatenate([tau - h, -Jdv - 2 * alpha * J @ v - beta ** 2 * phi]))
    return sol[:model.nv], -sol[model.nv:]


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
@pytest.mark.parametrize("baumgarte", [(0.0, 0.0), (3.0, 7.0)])
def test_matches_the_kkt_system(model, baumgarte):
    q, v, tau = states(model, baumgarte)
    cons = _constraints(model, q)
    q2 = integrate(model, q, v, 0.05)  # off the constraint manifold: the Baumgarte terms act
    for qq in (q, q2):
        res = rd.constrained_dynamics(model, qq, v, tau, cons, baumgarte=baumgarte)
        a, lam = _kkt(model, qq, v, tau, cons, *baumgarte)
        assert res.rank == 8
        assert [f.shape for f in res.forces] == [(3,), (1,), (3,), (1,)]
        assert_rel(res.a, a, 1e-9, "a")
        assert_rel(np.concatenate(res.forces), lam, 1e-9, "forces")


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
def test_with_friction_armature_and_no_constraints(model):
    m = model.replace(damping=np.full(model.nv, 0.3), coulomb=np.full(model.nv, 0.2),
                      armature=np.full(model.nv, 0.05))
    q, v, tau = states(m, "friction")
    res = rd.constrained_dynamics(m, q, v, tau, [])
    assert res.forces == () and res.rank == 0
    assert_rel(res.a, rd.aba(m, q, v, tau), 1e-9)
    for kw in ({"friction": False}, {"armature": False}):
        assert_rel(rd.constrained_dynamics(m, q, v, tau, [], **kw).a, rd.aba(m, q, v, tau, **kw), 1e-9, str(kw))
    # the constrained accelerations satisfy M a + h = tau + J^T lambda with friction and armature
    cons = _constraints(m, q)
    res = rd.constrained_dynamics(m, q, v, tau, cons)
    J = constraint_jacobian(m, q, v, cons)[0][0]
    assert_rel(rd.rnea(m, q, v, res.a), tau + J.T @ np.concatenate(res.forces), 1e-9)


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
def test_constraint_kinematics(model):
    """J v is the time derivative of phi, Jdot v + J a that of J v (central differences along
    the motion; the second derivative on the fixed base only, where ``integrate`` follows
    ``q(t) = q + v t + a t^2 / 2`` exactly), and the frame rows agree with rd.jacobian and
    rd.jacobian_dot_times_v."""
    q, v, a = states(model, "kinematics")
    cons = _constraints(model, q) + [rd.WeldConstraint("body5", rd.frame_pose(model, q, "body5"))]
    J, Jdv, _ = (x[0] for x in constraint_jacobian(model, q, v, cons))
    dphi = directional_derivative(lambda qq: constraint_jacobian(model, qq, v, cons)[2][0], model, q, v, 1e-6)
    assert_rel(J @ v, dphi, 1e-7, "J v = d phi / dt")
    if not model.floating_base:
        h = 1e-5
        Jt = [constraint_jacobian(model, integrate(model, q, v + s * h * a / 2, s * h), v, cons)[0][0]
              for s in (1, -1)]
        d_Jv = (Jt[0] @ (v + h * a) - Jt[1] @ (v - h * a)) / (2 * h)
        assert_rel(J @ a + Jdv, d_Jv, 1e-7, "d(J v)/dt = J a + Jdot v")
    k = frame_kinematics(model, q, v, "body5")
    Jw = rd.jacobian(model, q, "body5", "local_world_aligned")
    assert_rel(np.concatenate([k.J_lin[0], k.J_ang[0]]), Jw, 1e-12)
    assert_rel(np.concatenate([k.acc_lin[0], k.acc_ang[0]]),
               rd.jacobian_dot_times_v(model, q, v, "body5", "local_world_aligned"), 1e-12)


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
def test_batch_matches_single_states(model):
    rng = rng_for(model.name, "batch")
    q, v, tau = rd.random.random_state(model, rng, (2, 3))
    cons = _constraints(model, q[0, 0])
    res = rd.constrained_dynamics(model, q, v, tau, cons, baumgarte=(1.0, 2.0))
    assert res.a.shape == (2, 3, model.nv) and res.rank.shape == (2, 3) and res.forces[1].shape == (2, 3, 1)
    for i in np.ndindex(2, 3):
        one = rd.constrained_dynamics(model, q[i], v[i], tau[i], cons, baumgarte=(1.0, 2.0))
        assert_rel(res.a[i], one.a, 1e-12)
        assert_rel(np.concatenate([f[i] for f in res.forces]), np.concatenate(one.forces), 1e-12)
        assert res.rank[i] == one.rank


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
def test_unchecked_nan_propagates_to_its_own_state(model):
    """``check_finite=False``: a state with NaN gets NaN (a NaN configuration rank 0), not an
    error from the Schur complement's eigensolver, and the other states their own results."""
    rng = rng_for(model.name, "nan")
    q, v, tau = rd.random.random_state(model, rng, (4,))
    cons = _constraints(model, q[0])
    q[1, -1], tau[2, 0] = np.nan, np.nan
    res = rd.constrained_dynamics(model, q, v, tau, cons, check_finite=False)
    for i in (1, 2):
        assert np.isnan(res.a[i]).all() and all(np.isnan(f[i]).all() for f in res.forces)
    assert res.rank[1] == 0 and res.rank[2] == rd.constrained_dynamics(model, q[2], v[2], np.zeros(model.nv), cons).rank
    for i in (0, 3):
        one = rd.constrained_dynamics(model, q[i], v[i], tau[i], cons)
        assert_rel(res.a[i], one.a, 1e-12)
        assert res.rank[i] == one.rank

# -- the pendulum: a point mass on two prismatic joints held by a rod -------------------------
M_BOB, L_ROD = 2.0, 0.7


def _point_mass_xz() -> rd.Model:
    """A point mass on prismatic joints along x and z (the plane of the pendulum)."""
    b = rd.ModelBuilder("point-mass")
    b.add_link("world")
    b.add_link("slider")
    b.add_link("bob", mass=M_BOB)
    b.add_joint("x", "prismatic", "world", "slider", axis=(1, 0, 0))
    b.add_joint("z", "prismatic", "slider", "bob", axis=(0, 0, 1))
    return b.build()


ROD = rd.DistanceConstraint("bob", (0, 0, 0), None, (0, 0, 0), length=L_ROD)


def test_point_mass_on_a_rod_is_the_pendulum():
    """The 2-dof point mass with the rod (KKT unknowns x'', z'', lambda, i.e. the reaction
    (R_x, R_z) = lambda (x, z) / L) moves as the one-joint pendulum ``x = L sin(theta)``,
    ``z = L cos(theta)`` (theta = 0 upright), with the rod force of the closed form
    ``lambda = m g cos(theta) - m L theta'^2`` (positive pushes the bob outwards)."""
    point, pend = _point_mass_xz(), pendulum(M_BOB, L_ROD)
    for theta, omega in ((0.3, 0.0), (2.0, -1.5), (-2.8, 3.0)):
        s, c = np.sin(theta), np.cos(theta)
        q, v = L_ROD * np.array([s, c]), L_ROD * omega * np.array([c, -s])
        res = rd.constrained_dynamics(point, q, v, np.zeros(2), [ROD])
        thdd = rd.aba(pend, np.array([theta]), np.array([omega]), np.zeros(1))[0]
        assert_rel(thdd, G / L_ROD * s, 1e-12, "pendulum closed form")
        expected = L_ROD * np.array([thdd * c - omega ** 2 * s, -thdd * s - omega ** 2 * c])
        assert_rel(res.a, expected, 1e-12, f"a at theta={theta}")
        assert_rel(res.forces[0], [M_BOB * G * c - M_BOB * L_ROD * omega ** 2], 1e-12, "rod force")
        R = res.forces[0][0] * q / L_ROD  # the 2D reaction on the bob
        assert_rel(M_BOB * res.a, R + np.array([0.0, -M_BOB * G]), 1e-12, "Newton")

    # the same motion over 1.5 s (both integrated by RK4 with 5 ms steps)
    theta0, omega0 = 0.4, 0.0

    def f_point(x):
        return np.concatenate([x[2:], rd.constrained_dynamics(point, x[:2], x[2:], np.zeros(2), [ROD],
                                                              baumgarte=(5.0, 5.0)).a])

    def f_pend(x):
        return np.concatenate([x[1:], rd.aba(pend, x[:1], x[1:], np.zeros(1))])

    x0 = np.array([L_ROD * np.sin(theta0), L_ROD * np.cos(theta0), omega0 * L_ROD * np.cos(theta0), 0.0])
    xp, th = x0, np.array([theta0, omega0])
    for t in (0.5, 1.0, 1.5):
        xp, th = rk4(f_point, xp, 0.5, 100), rk4(f_pend, th, 0.5, 100)
        assert_rel(xp[:2], L_ROD * np.array([np.sin(th[0]), np.cos(th[0])]), 1e-6, f"position at t={t}")
        assert_rel(xp[2:], L_ROD * th[1] * np.array([np.cos(th[0]), -np.sin(th[0])]), 1e-6, f"velocity at t={t}")


def test_pinned_rigid_body_is_the_pendulum():
    """A rigid body on a planar (x, z, angle) joint chain pinned at a point by a 3D point
    constraint, whose out-of-plane row is zero (rank 2 of 3): the one-joint pendulum."""
    b = rd.ModelBuilder("planar-body")
    b.add_link("world")
    b.add_link("sx")
    b.add_link("sz")
    b.add_link("body", mass=M_BOB, com=(0, 0, L_ROD), inertia=np.diag([0.01, 0.02, 0.01]))
    b.add_joint("x", "prismatic", "world", "sx", axis=(1, 0, 0))
    b.add_joint("z", "prismatic", "sx", "sz", axis=(0, 0, 1))
    b.add_joint("angle", "revolute", "sz", "body", axis=(0, 1, 0))
    planar = b.build()
    b2 = rd.ModelBuilder("pendulum-body")
    b2.add_link("world")
    b2.add_link("body", mass=M_BOB, com=(0, 0, L_ROD), inertia=np.diag([0.01, 0.02, 0.01]))
    b2.add_joint("angle", "revolute", "world", "body", axis=(0, 1, 0))
    pend = b2.build()
    pin = rd.PointConstraint("body", (0, 0, 0), (0, 0, 0))
    for theta, omega, tau in ((0.3, 0.0, 0.0), (2.0, -1.5, 0.7)):
        res = rd.constrained_dynamics(planar, [0, 0, theta], [0, 0, omega], [0, 0, tau], [pin])
        assert res.rank == 2
        thdd = rd.aba(pend, np.array([theta]), np.array([omega]), np.array([tau]))[0]
        assert_rel(res.a, [0.0, 0.0, thdd], 1e-12)
        assert abs(res.forces[0][1]) < 1e-12  # minimum-norm force: nothing along the redundant row


# -- four-bar linkage ------------------------------------------------------------------------
CRANK, COUPLER, ROCKER, GROUND = 0.3, 0.8, 0.6, 0.7


def _four_bar() -> tuple[rd.Model, rd.LoopConstraint]:
    """A planar four-bar linkage (joints about z, gravity -y) as a tree (crank - coupler, and
    the rocker on the ground), closed by joining the coupler's end to the rocker's end."""
    b = rd.ModelBuilder("four-bar", gravity=(0.0, -G, 0.0))
    b.add_link("ground")
    for name, length, mass in (("crank", CRANK, 1.0), ("coupler", COUPLER, 2.0), ("rocker", ROCKER, 1.5)):
        b.add_link(name, mass=mass, com=(length / 2, 0, 0),
                   inertia=np.diag([1e-4, mass * length ** 2 / 12, mass * length ** 2 / 12]))
    b.add_joint("crank_joint", "revolute", "ground", "crank", axis=(0, 0, 1))
    b.add_joint("coupler_joint", "revolute", "crank", "coupler", xyz=(CRANK, 0, 0), axis=(0, 0, 1))
    b.add_joint("rocker_joint", "revolute", "ground", "rocker", xyz=(GROUND, 0, 0), axis=(0, 0, 1))
    return b.build(), rd.LoopConstraint("coupler", (COUPLER, 0, 0), "rocker", (ROCKER, 0, 0))


def _closed_configuration(crank_angle: float) -> np.ndarray:
    """Joint angles that close the loop (intersection of two circles), elbow up."""
    P = CRANK * np.array([np.cos(crank_angle), np.sin(crank_angle)])
    O = np.array([GROUND, 0.0])
    d = O - P
    n = np.linalg.norm(d)
    along = (COUPLER ** 2 - ROCKER ** 2 + n ** 2) / (2 * n)
    X = P + along * d / n + np.sqrt(COUPLER ** 2 - along ** 2) * np.array([-d[1], d[0]]) / n
    coupler = np.arctan2(X[1] - P[1], X[0] - P[0])
    return np.array([crank_angle, coupler - crank_angle, np.arctan2(X[1], X[0] - GROUND)])


def test_four_bar_linkage_holds_together_for_5_s():
    """5 s of motion under gravity (scipy's DOP853, rtol 1e-7, Baumgarte (10, 10)): at every
    step the loop is closed within 1e-6 m, the constraint forces do no work
    (J^T lambda . v = 0) and the energy is conserved; the planar loop closed by a 3D point is
    redundant out of plane (rank 2 of 3)."""
    model, loop = _four_bar()
    q0 = _closed_configuration(1.0)
    J = constraint_jacobian(model, q0, np.zeros(3), [loop])[0][0]
    v0 = 2.0 * np.linalg.svd(J)[2][-1]  # a velocity along the loop's one degree of freedom
    assert np.abs(J @ v0).max() < 1e-14
    res = rd.constrained_dynamics(model, q0, v0, np.zeros(3), [loop])
    assert abs((J.T @ res.forces[0]) @ v0) < 1e-13 * np.abs(res.forces[0]).max()

    def dynamics(x):
        return rd.constrained_dynamics(model, x[:3], x[3:], np.zeros(3), [loop], baumgarte=(10.0, 10.0))

    sol = solve_ivp(lambda t, x: np.concatenate([x[3:], dynamics(x).a]), (0.0, 5.0), np.concatenate([q0, v0]),
                    method="DOP853", rtol=1e-7, atol=1e-9)
    assert sol.status == 0 and sol.t[-1] == 5.0 and len(sol.t) > 100
    energy = []
    for x in sol.y.T:
        q, v = x[:3], x[3:]
        Jc, _, phi = (y[0] for y in constraint_jacobian(model, q, v, [loop]))
        res = dynamics(x)
        assert res.rank == 2
        assert np.abs(phi).max() < 1e-6, np.abs(phi).max()
        f_joint = Jc.T @ res.forces[0]  # the joint forces of the loop; their power, relative:
        assert abs(f_joint @ v) < 1e-7 * np.linalg.norm(f_joint) * np.linalg.norm(v)
        energy.append(rd.kinetic_energy(model, q, v) + rd.potential_energy(model, q))
    assert np.ptp(energy) < 1e-5 * max(1.0, abs(energy[0]))
    assert np.ptp(sol.y[0]) > 1.0  # it did move


def test_duplicated_constraint_is_redundant():
    """The same constraint twice: rank unchanged, same accelerations, the force shared."""
    model = TREES[0]
    q, v, tau = states(model, "redundant")
    c = _constraints(model, q)[0]
    once = rd.constrained_dynamics(model, q, v, tau, [c])
    twice = rd.constrained_dynamics(model, q, v, tau, [c, c])
    assert once.rank == 3 and twice.rank == 3
    assert_rel(twice.a, once.a, 1e-9)
    assert_rel(twice.forces[0], once.forces[0] / 2, 1e-9)
    assert_rel(twice.forces[1], once.forces[0] / 2, 1e-9)


def test_gear_coupling_and_weld():
    """A coupling keeps v_b = ratio v_a at acceleration level; a weld holds the body still."""
    model = TREES[0]
    q, v, tau = states(model, "gear")
    ja, jb = model.joint_names[1], model.joint_names[3]
    v[3] = -2.0 * v[1]
    res = rd.constrained_dynamics(model, q, v, tau, [rd.CouplingConstraint(ja, jb, ratio=-2.0)])
    assert_rel(res.a[3], -2.0 * res.a[1], 1e-12)
    assert_rel(rd.rnea(model, q, v, res.a), tau + np.eye(model.nv)[3] * res.forces[0][0]
               + np.eye(model.nv)[1] * 2.0 * res.forces[0][0], 1e-9)
    # weld body0 (first joint) at rest: its joint does not accelerate
    w = rd.WeldConstraint("body0", rd.frame_pose(model, q, "body0"))
    v0 = v.copy()
    v0[0] = 0.0
    res = rd.constrained_dynamics(model, q, v0, tau, [w])
    assert abs(res.a[0]) < 1e-9 * max(1, np.abs(res.a).max()) and res.rank == 1


# -- bad input ---------------------------------------------------------------------------------
def test_bad_constraint_specifications():
    with pytest.raises(ValueError, match=r"PointConstraint.point: expected 3 finite numbers"):
        rd.PointConstraint("a", (0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match=r"PointConstraint.target: expected 3 finite numbers"):
        rd.PointConstraint("a", (0, 0, 0), (0, np.nan, 0))
    with pytest.raises(ValueError, match=r"PointConstraint.body: expected a link or frame name"):
        rd.PointConstraint(1.5, (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match=r"WeldConstraint.target: expected a finite 4 x 4 pose"):
        rd.WeldConstraint("a", np.eye(3))
    with pytest.raises(ValueError, match=r"WeldConstraint.target: not a homogeneous transform"):
        rd.WeldConstraint("a", 2 * np.eye(4))
    with pytest.raises(ValueError, match=r"LoopConstraint: body_a and body_b are the same body 'a'"):
        rd.LoopConstraint("a", (0, 0, 0), "a", (1, 0, 0))
    with pytest.raises(ValueError, match=r"DistanceConstraint.length: expected a finite number > 0"):
        rd.DistanceConstraint("a", (0, 0, 0), None, (0, 0, 0), length=0.0)
    with pytest.raises(ValueError, match=r"CouplingConstraint: joint_a and joint_b are the same joint 'j'"):
        rd.CouplingConstraint("j", "j")
    with pytest.raises(ValueError, match=r"CouplingConstraint.ratio: expected a finite number"):
        rd.CouplingConstraint("i", "j", ratio=np.inf)
    with pytest.raises(ValueError, match=r"CouplingConstraint.joint_a: expected a joint name"):
        rd.CouplingConstraint(0, "j")


def test_bad_arguments():
    model = TREES[1]
    q, v, tau = states(model, "bad")
    good = [rd.PointConstraint("body3", (0, 0, 0), (0, 0, 0))]
    call = rd.constrained_dynamics
    with pytest.raises(ValueError, match=r"unknown link or frame 'nope'"):
        call(model, q, v, tau, [rd.PointConstraint("nope", (0, 0, 0), (0, 0, 0))])
    with pytest.raises(ValueError, match=r"body index 40 out of range"):
        call(model, q, v, tau, [rd.LoopConstraint(40, (0, 0, 0), "body1", (0, 0, 0))])
    with pytest.raises(ValueError, match=r"unknown 1-dof joint 'root_joint'"):
        call(model, q, v, tau, [rd.CouplingConstraint("root_joint", "joint3")])
    with pytest.raises(ValueError, match=r"constraints\[1\]: expected one of .*got str"):
        call(model, q, v, tau, [good[0], "body3"])
    with pytest.raises(ValueError, match=r"constraints: expected a sequence of constraints, got int"):
        call(model, q, v, tau, 3)
    for bad in ((1.0,), (-1.0, 0.0), (0.0, np.nan), "ab"):
        with pytest.raises(ValueError, match=r"baumgarte: expected"):
            call(model, q, v, tau, good, baumgarte=bad)
    with pytest.raises(ValueError, match=r"rcond: expected a number in \[0, 1\)"):
        call(model, q, v, tau, good, rcond=2.0)
    with pytest.raises(ValueError, match=rf"tau: expected shape \(\.\.\., {model.nv}\), got \(3,\)"):
        call(model, q, v, tau[:3], good)
    with pytest.raises(ValueError, match=r"constrained_dynamics: tau contains NaN or Inf"):
        call(model, q, v, np.full(model.nv, np.nan), good)
    with pytest.raises(ValueError, match=r"quaternion of free joint 'root_joint'"):
        call(model, np.concatenate([q[:3], 2 * q[3:7], q[7:]]), v, tau, good)


def test_singular_mass_matrix():
    """A massless leaf: M is singular, the dynamics is undefined."""
    model = massless_leaf_model()
    with pytest.raises(ValueError, match=r"constrained_dynamics: the mass matrix is not positive definite"):
        rd.constrained_dynamics(model, np.zeros(2), np.zeros(2), np.zeros(2),
                                [rd.PointConstraint("arm", (0, 0, 0), (0, 0, 0))])
