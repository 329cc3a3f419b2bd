"""Built-in robots (robodyn.models): registry, masses, kinematics against published poses
and closed forms, and the textbook mass matrices and gravity vectors.

The oracles here use nothing of robodyn's dynamics: poses come from products of
``rd.dh_transform`` and from closed-form geometry, and ``M(q)`` and ``g(q)`` from finite
differences of the centres of mass (``M = sum m Jv^T Jv + Jw^T I Jw``, ``g = dV/dq``).
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from robodyn.models import elbow_3r, panda, puma560, scara, ur5

G = 9.81
RNG = np.random.default_rng(20240611)

DOF = {"pendulum": 1, "double_pendulum": 2, "planar_2r": 2, "elbow_3r": 3, "scara": 4, "puma560": 6,
       "panda": 7, "ur5": 6}

# Masses as published (typed here again, independently of the model sources).
PUBLISHED_MASS = {
    "pendulum": 1.0,
    "double_pendulum": 1.0 + 1.0,
    "planar_2r": 10.0 + 5.0,
    "elbow_3r": 5.0 + 4.0 + 2.0,
    "scara": 6.0 + 4.0 + 1.0 + 0.5,
    # Corke & Armstrong-Helouvry 1994 (link 1 has no published mass)
    "puma560": 0.0 + 17.4 + 4.8 + 0.82 + 0.34 + 0.09,
    # Gaz et al. 2019
    "panda": 4.970684 + 0.646926 + 3.228604 + 3.587895 + 1.225946 + 1.666555 + 0.735522,
    # Universal Robots, UR5 DH / dynamics table
    "ur5": 3.7 + 8.393 + 2.33 + 1.219 + 1.219 + 0.1879,
}

DH_ROBOTS = {"elbow_3r": (elbow_3r, "standard"), "scara": (scara, "standard"),
             "puma560": (puma560, "standard"), "panda": (panda, "modified"), "ur5": (ur5, "standard")}


# -- independent kinematics and dynamics from the model arrays ------------------------------
def _rotation(axis, angle):
    """Rodrigues' formula."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def body_poses(model, q):
    """World (R, p) of every body: parent pose, then X_tree, then the joint motion."""
    poses = []
    for i in range(model.nbodies):
        R, p = model.X_tree_R[i], model.X_tree_p[i]
        qi, axis = q[model.idx_q[i]], model.joint_axis[i]
        if model.joint_type[i] == J.REVOLUTE:
            R = R @ _rotation(axis, qi)
        else:
            assert model.joint_type[i] == J.PRISMATIC
            p = p + R @ axis * qi
        if model.parent[i] >= 0:
            Rp, pp = poses[model.parent[i]]
            R, p = Rp @ R, pp + Rp @ p
        poses.append((R, p))
    return poses


def frame_pose(model, q, name):
    body, R, p = model.frame_index(name)
    if body < 0:
        return R, p
    Rb, pb = body_poses(model, q)[body]
    return Rb @ R, pb + Rb @ p


def dh_product(links, q, convention, base=np.eye(4)):
    T = np.array(base, dtype=float)
    for link, qi in zip(links, q):
        T = T @ rd.dh_transform(link, qi, convention)
    return T


def mass_and_com(theta):
    """Mass, centre of mass and inertia about it (body frame) of 10 inertial parameters."""
    m = theta[0]
    Io = np.array([[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]])
    if m == 0:
        return 0.0, np.zeros(3), Io
    c = theta[1:4] / m
    return m, c, Io - m * (c @ c * np.eye(3) - np.outer(c, c))


def com_world(model, q):
    return [p + R @ mass_and_com(th)[1] for (R, p), th in zip(body_poses(model, q), model.theta)]


def mass_matrix_fd(model, q, h=1e-6):
    """M(q) from the kinetic energy, Jacobians by central differences (plus armature)."""
    n = model.nv
    Jv = np.zeros((model.nbodies, 3, n))
    Jw = np.zeros((model.nbodies, 3, n))
    for k in range(n):
        dq = np.zeros(n)
        dq[k] = h
        plus, minus = body_poses(model, q + dq), body_poses(model, q - dq)
        cp, cm = com_world(model, q + dq), com_world(model, q - dq)
        for b in range(model.nbodies):
            Jv[b, :, k] = (cp[b] - cm[b]) / (2 * h)
            W = (plus[b][0] - minus[b][0]) / (2 * h) @ plus[b][0].T  # skew(omega)
            Jw[b, :, k] = [W[2, 1], W[0, 2], W[1, 0]]
    M = np.diag(model.armature).astype(float)
    for b, (R, _) in enumerate(body_poses(model, q)):
        m, _, Ic = mass_and_com(model.theta[b])
        M += m * Jv[b].T @ Jv[b] + Jw[b].T @ (R @ Ic @ R.T) @ Jw[b]
    return M


def gravity_fd(model, q, h=1e-6):
    """g(q) = dV/dq with V = -sum m gravity . c."""
    masses = model.theta[:, 0]

    def V(x):
        return -sum(m * model.gravity @ c for m, c in zip(masses, com_world(model, x)))

    return np.array([(V(q + h * e) - V(q - h * e)) / (2 * h) for e in np.eye(model.nv)])


# -- registry ---------------------------------------------------------------------------------
def test_names_lists_every_robot():
    assert rd.models.names() == list(DOF)


@pytest.mark.parametrize("name", list(DOF))
def test_load(name):
    model = rd.models.load(name)
    assert isinstance(model, rd.Model)
    assert model.name == name
    assert (model.nq, model.nv) == (DOF[name], DOF[name])
    assert len(model.joint_names) == DOF[name]
    assert model.physical == "error"  # every body passed the consistency checks
    np.testing.assert_array_equal(model.gravity, [0.0, 0.0, -9.81])
    assert rd.models.load(name) is model


@pytest.mark.parametrize("bad", ["Panda", "kuka", "", 3])
def test_unknown_name_lists_known_ones(bad):
    with pytest.raises(ValueError, match="known: pendulum, double_pendulum, .*ur5"):
        rd.models.load(bad)


@pytest.mark.parametrize("name", list(DOF))
def test_total_mass_is_sum_of_published_link_masses(name):
    assert rd.models.load(name).total_mass == pytest.approx(PUBLISHED_MASS[name], abs=1e-12)


# -- kinematics -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(DH_ROBOTS))
def test_model_frames_are_the_dh_product(name):
    module, convention = DH_ROBOTS[name]
    model, links = rd.models.load(name), module.links()
    for q in RNG.uniform(-2, 2, (3, model.nq)):
        for i in range(model.nq + 1):
            R, p = frame_pose(model, q, f"frame{i}")
            T = dh_product(links[:i], q[:i], convention)
            np.testing.assert_allclose(R, T[:3, :3], atol=1e-12)
            np.testing.assert_allclose(p, T[:3, 3], atol=1e-12)


@pytest.mark.parametrize("name", list(DH_ROBOTS))
def test_link_inertials_survive_loading(name):
    """Mass, centre of mass and inertia of each link, read back in its DH frame."""
    module, _ = DH_ROBOTS[name]
    model = rd.models.load(name)
    for i, link in enumerate(module.links(), start=1):
        body, R, p = model.frame_index(f"frame{i}")
        m, c, Ic = mass_and_com(model.theta[body])
        assert m == pytest.approx(link.mass, abs=1e-12)
        if m > 0:
            np.testing.assert_allclose(R.T @ (c - p), link.com, atol=1e-12)
        np.testing.assert_allclose(R.T @ Ic @ R, link.inertia, atol=1e-12)


def test_ur5_zero_pose():
    """UR's zero: arm stretched along -x; flange at (a2 + a3, -(d4 + d6), d1 - d5)."""
    T = dh_product(ur5.links(), np.zeros(6), "standard")
    a2, a3, d1, d4, d5, d6 = -0.425, -0.39225, 0.089159, 0.10915, 0.09465, 0.0823
    np.testing.assert_allclose(T[:3, 3], [a2 + a3, -(d4 + d6), d1 - d5], atol=1e-12)
    np.testing.assert_allclose(frame_pose(rd.models.load("ur5"), np.zeros(6), "frame6")[1], T[:3, 3], atol=1e-12)


def test_panda_zero_pose_flange():
    """Franka's zero pose: flange at (0.088, 0, 0.926), z axis pointing down."""
    T = dh_product(panda.links(), np.zeros(7), "modified")
    T = T @ rd.dh_transform(rd.DHLink(a=0.0, alpha=0.0, d=0.107), 0.0, "modified")
    np.testing.assert_allclose(T[:3, 3], [0.088, 0.0, 0.926], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-12)
    R, p = frame_pose(rd.models.load("panda"), np.zeros(7), "flange")
    np.testing.assert_allclose(p, [0.088, 0.0, 0.926], atol=1e-12)
    np.testing.assert_allclose(R, T[:3, :3], atol=1e-12)


@pytest.mark.parametrize("q, wrist", [
    # Corke, Robotics, Vision and Control: p560.fkine(qz) and fkine(qr) translations
    # (0.4521, -0.15005, 0.4318) and (0.0203, -0.15005, 0.8636), plus the 0.672 m base height
    ([0, 0, 0, 0, 0, 0], [0.4521, -0.15005, 0.4318 + 0.672]),
    ([0, np.pi / 2, -np.pi / 2, 0, 0, 0], [0.0203, -0.15005, 0.8636 + 0.672]),
])
def test_puma560_published_poses(q, wrist):
    np.testing.assert_allclose(dh_product(puma560.links(), q, "standard")[:3, 3], wrist, atol=1e-12)


def test_closed_form_positions():
    q = RNG.uniform(-2, 2, 4)
    s, c = np.sin, np.cos
    m = rd.models.load("pendulum")
    np.testing.assert_allclose(frame_pose(m, q[:1], "frame1")[1], [s(q[0]), 0, c(q[0])], atol=1e-12)
    m = rd.models.load("double_pendulum")
    np.testing.assert_allclose(frame_pose(m, q[:2], "frame2")[1],
                               [s(q[0]) + s(q[0] + q[1]), 0, c(q[0]) + c(q[0] + q[1])], atol=1e-12)
    m = rd.models.load("planar_2r")
    np.testing.assert_allclose(frame_pose(m, q[:2], "frame2")[1],
                               [c(q[0]) + c(q[0] + q[1]), 0, s(q[0]) + s(q[0] + q[1])], atol=1e-12)
    m = rd.models.load("elbow_3r")  # d1 = 0.4, a2 = 0.4, a3 = 0.35
    r = 0.4 * c(q[1]) + 0.35 * c(q[1] + q[2])
    np.testing.assert_allclose(frame_pose(m, q[:3], "frame3")[1],
                               [r * c(q[0]), r * s(q[0]), 0.4 + 0.4 * s(q[1]) + 0.35 * s(q[1] + q[2])], atol=1e-12)
    m = rd.models.load("scara")  # d1 = 0.4, a1 = 0.325, a2 = 0.275, q3 down
    R, p = frame_pose(m, q, "frame4")
    np.testing.assert_allclose(p, [0.325 * c(q[0]) + 0.275 * c(q[0] + q[1]),
                                   0.325 * s(q[0]) + 0.275 * s(q[0] + q[1]), 0.4 - q[2]], atol=1e-12)
    np.testing.assert_allclose(R[:, 2], [0, 0, -1], atol=1e-12)


# -- dynamics of the textbook robots (finite differences, no robodyn algorithm) ---------------
@pytest.mark.parametrize("q", RNG.uniform(-3, 3, (3, 2)))
def test_pendulum_equation(q):
    """m L^2 qdd = tau + m g L sin(theta), theta = 0 upright: M = m L^2, g(q) = -m g L sin q."""
    model = rd.models.load("pendulum")
    np.testing.assert_allclose(mass_matrix_fd(model, q[:1]), [[1.0]], atol=1e-7)
    np.testing.assert_allclose(gravity_fd(model, q[:1]), [-G * np.sin(q[0])], atol=1e-7)


@pytest.mark.parametrize("q", RNG.uniform(-3, 3, (3, 2)))
def test_double_pendulum_closed_form(q):
    m1 = m2 = L1 = L2 = 1.0
    c2, s1, s12 = np.cos(q[1]), np.sin(q[0]), np.sin(q[0] + q[1])
    M = [[(m1 + m2) * L1**2 + m2 * L2**2 + 2 * m2 * L1 * L2 * c2, m2 * L2**2 + m2 * L1 * L2 * c2],
         [m2 * L2**2 + m2 * L1 * L2 * c2, m2 * L2**2]]
    g = [-G * ((m1 + m2) * L1 * s1 + m2 * L2 * s12), -G * m2 * L2 * s12]
    model = rd.models.load("double_pendulum")
    np.testing.assert_allclose(mass_matrix_fd(model, q), M, atol=1e-7)
    np.testing.assert_allclose(gravity_fd(model, q), g, atol=1e-7)


@pytest.mark.parametrize("q", RNG.uniform(-3, 3, (3, 2)))
def test_planar_2r_alpha_beta_delta(q):
    m1, m2, l1, l2 = 10.0, 5.0, 1.0, 1.0
    r1, r2, I1, I2 = l1 / 2, l2 / 2, m1 * l1**2 / 12, m2 * l2**2 / 12
    alpha = I1 + I2 + m1 * r1**2 + m2 * (l1**2 + r2**2)
    beta = m2 * l1 * r2
    delta = I2 + m2 * r2**2
    assert (alpha, beta, delta) == pytest.approx((10.0, 2.5, 5.0 / 3.0))
    c2 = np.cos(q[1])
    M = [[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]]
    g = [(m1 * r1 + m2 * l1) * G * np.cos(q[0]) + m2 * r2 * G * np.cos(q[0] + q[1]),
         m2 * r2 * G * np.cos(q[0] + q[1])]
    model = rd.models.load("planar_2r")
    np.testing.assert_allclose(mass_matrix_fd(model, q), M, atol=1e-6)
    np.testing.assert_allclose(gravity_fd(model, q), g, atol=1e-6)


def test_scara_gravity_acts_on_the_quill_only():
    model = rd.models.load("scara")
    q = np.array([0.3, -1.0, 0.1, 2.0])
    np.testing.assert_allclose(gravity_fd(model, q), [0, 0, -(1.0 + 0.5) * G, 0], atol=1e-6)


@pytest.mark.parametrize("name", list(DH_ROBOTS))
def test_mass_matrix_positive_definite(name):
    model = rd.models.load(name)
    q = RNG.uniform(-1, 1, model.nq)
    M = mass_matrix_fd(model, q)
    np.testing.assert_allclose(M, M.T, atol=1e-6)
    assert np.linalg.eigvalsh(M)[0] > 0


# -- PUMA 560 motor data reflected to the joints ------------------------------------------------
# Corke's Puma560.py, typed again: G, Jm, B, Tc+, Tc- per joint.
PUMA_MOTORS = [
    (-62.6111, 200e-6, 1.48e-3, 0.395, -0.435),
    (107.815, 200e-6, 0.817e-3, 0.126, -0.071),
    (-53.7063, 200e-6, 1.38e-3, 0.132, -0.105),
    (76.0364, 33e-6, 71.2e-6, 11.2e-3, -16.9e-3),
    (71.923, 33e-6, 82.6e-6, 9.26e-3, -14.5e-3),
    (76.686, 33e-6, 36.7e-6, 3.96e-3, -10.5e-3),
]


def test_puma560_motor_data_reflected_like_corke():
    model = rd.models.load("puma560")
    Gr, Jm, B, tcp, tcn = np.array(PUMA_MOTORS).T
    link1_inertia = np.array([0.35, 0, 0, 0, 0, 0])  # Lyy of link 1, moved to joint 1's armature
    np.testing.assert_allclose(model.armature, Gr**2 * Jm + link1_inertia, rtol=1e-12)
    np.testing.assert_allclose(model.damping, Gr**2 * B, rtol=1e-12)
    np.testing.assert_allclose(model.coulomb, np.abs(Gr) * (tcp - tcn) / 2, rtol=1e-12)
    np.testing.assert_allclose(np.rad2deg(model.lower), [-160, -45, -225, -110, -100, -266])
    np.testing.assert_allclose(np.rad2deg(model.upper), [160, 225, 45, 170, 100, 266])
