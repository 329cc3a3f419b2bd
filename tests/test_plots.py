"""Plots, checked through the arrays they draw: the torque contributions of the two-link arm
against the closed form (alpha, beta, delta), trajectories, energies, stick figures."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import robodyn as rd
from robodyn import control, plots
from robodyn.models.planar import PLANAR_2R

from helpers import G, rng_for


def two_link_closed_form(q, v, a):
    """M qdd, C qd and g of planar_2r (Murray, Li, Sastry ch. 4; Spong et al. ch. 7)."""
    m1, m2, l1, l2 = PLANAR_2R["m1"], PLANAR_2R["m2"], PLANAR_2R["l1"], PLANAR_2R["l2"]
    r1, r2 = l1 / 2, l2 / 2
    I1, I2 = m1 * l1 ** 2 / 12, m2 * l2 ** 2 / 12
    alpha = I1 + I2 + m1 * r1 ** 2 + m2 * (l1 ** 2 + r2 ** 2)
    beta = m2 * l1 * r2
    delta = I2 + m2 * r2 ** 2
    q1, q2 = q[:, 0], q[:, 1]
    d1, d2 = v[:, 0], v[:, 1]
    c2, s2 = np.cos(q2), np.sin(q2)
    inertial = np.stack([(alpha + 2 * beta * c2) * a[:, 0] + (delta + beta * c2) * a[:, 1],
                         (delta + beta * c2) * a[:, 0] + delta * a[:, 1]], axis=1)
    coriolis = np.stack([-beta * s2 * (2 * d1 * d2 + d2 ** 2), beta * s2 * d1 ** 2], axis=1)
    gravity = np.stack([(m1 * r1 + m2 * l1) * G * np.cos(q1) + m2 * r2 * G * np.cos(q1 + q2),
                        m2 * r2 * G * np.cos(q1 + q2)], axis=1)
    return inertial, coriolis, gravity


def test_torque_contributions_of_the_two_link_arm_match_the_closed_form(tmp_path):
    model = rd.models.load("planar_2r")
    ref = control.quintic([-0.5, 1.0], [1.2, -0.8], 1.0)
    t = np.linspace(0.0, 1.0, 101)
    q, v, a = (np.array([ref(s)[k] for s in t]) for k in range(3))
    path = tmp_path / "contributions.png"
    data = plots.plot_torques(model, t, q, v, a, path)
    assert path.stat().st_size > 0
    inertial, coriolis, gravity = two_link_closed_form(q, v, a)
    scale = np.abs(data["total"]).max()
    for key, expected in (("inertial", inertial), ("coriolis", coriolis), ("gravity", gravity)):
        np.testing.assert_allclose(data[key], expected, rtol=0, atol=1e-12 * scale, err_msg=key)
    np.testing.assert_allclose(data["total"], inertial + coriolis + gravity, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(data["t"], t)
    assert np.abs(coriolis).max() > 1.0  # the motion is fast enough for every term to matter


def test_contributions_add_up_on_a_random_tree():
    model = rd.random.random_model(6, seed=2, branching=0.5)
    q, v, a = rd.random.random_state(model, rng_for("contributions"), 5)
    data = plots.torque_contributions(model, q, v, a)
    np.testing.assert_allclose(data["inertial"] + data["coriolis"] + data["gravity"], data["total"],
                               rtol=0, atol=1e-10 * np.abs(data["total"]).max())
    np.testing.assert_allclose(data["coriolis"], np.einsum("nij,nj->ni", rd.coriolis_matrix(model, q, v), v),
                               rtol=0, atol=1e-10 * np.abs(data["coriolis"]).max())


@pytest.fixture(scope="module")
def tracked():
    model = rd.models.load("planar_2r")
    ct = control.ComputedTorque(model, control.quintic([0.0, 0.0], [1.0, 0.5], 0.3), 100.0, 20.0)
    return rd.simulate(model, [0.05, 0.0], [0.0, 0.0], 0.4, 2e-3, controller=ct)


def test_trajectory_energy_and_simulation_plots(tracked, tmp_path):
    traj = tracked
    data = plots.plot_trajectory(traj, tmp_path / "traj.png")
    np.testing.assert_array_equal(data["q"], traj.q)
    np.testing.assert_array_equal(data["error"], traj.q - traj.q_desired)
    data = plots.plot_energy(traj, tmp_path / "energy.png")
    np.testing.assert_array_equal(data["energy"], traj.kinetic + traj.potential)
    np.testing.assert_array_equal(data["lyapunov"], traj.lyapunov)
    data = plots.plot_simulation(traj, tmp_path / "all.png")
    np.testing.assert_array_equal(data["tau"], traj.tau)
    for name in ("traj.png", "energy.png", "all.png"):
        assert (tmp_path / name).read_bytes()[:4] == b"\x89PNG"


def test_planar_stick_figure(tracked, tmp_path):
    from PIL import Image

    model = tracked.model
    path = tmp_path / "arm.gif"
    data = plots.animate(model, tracked.t, tracked.q, path, fps=10)
    assert data["axes"] == ("x", "z")  # the arm moves in the world x-z plane
    assert data["t"].shape == (5,)  # 0.4 s at 10 frames per second
    k = np.searchsorted(tracked.t, data["t"][-1])
    tip = rd.frame_pose(model, tracked.q[k], "frame2")[:3, 3]
    assert any(np.allclose(p, tip[[0, 2]], atol=1e-12) for p in data["points"][-1])
    with Image.open(path) as gif:
        assert gif.n_frames == data["t"].shape[0]


def test_spatial_stick_figure(tmp_path):
    panda = rd.models.load("panda")
    q = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7]) + np.linspace(0, 0.5, 3)[:, None]
    data = plots.animate(panda, np.array([0.0, 0.5, 1.0]), q, tmp_path / "panda.gif", fps=2)
    assert data["axes"] == ("x", "y", "z") and data["points"].shape[-1] == 3
    T = rd.forward_kinematics(panda, q)
    np.testing.assert_allclose(data["points"][:, 1:8], T[:, :, :3, 3], rtol=0, atol=1e-15)
    assert (tmp_path / "panda.gif").stat().st_size > 0


def test_animate_bad_input():
    model = rd.models.load("planar_2r")
    with pytest.raises(ValueError, match=r"t: expected shape \(3,\)"):
        plots.animate(model, np.zeros(2), np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"fps: expected a positive integer"):
        plots.animate(model, np.zeros(3), np.zeros((3, 2)), fps=0)


def test_import_robodyn_does_not_load_matplotlib():
    code = "import sys, robodyn; robodyn.simulate; robodyn.control; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
