"""The simulate and torques commands: the numbers written (the CSV obeys the equation of motion
and the energy it reports, the printed torques are those of the file's motion), images that
show something, CSV output readable by torques, errors."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.io.log import read_log
from robodyn.simulation import read_trajectory

from helpers import assert_rel


def assert_image_shows_something(path, frames: int = 1):
    """A PNG or GIF whose pixels are not all one colour (and, for a GIF, at least ``frames``
    frames, not all equal)."""
    from PIL import Image, ImageSequence

    with Image.open(path) as im:
        pictures = [np.asarray(f.convert("RGB"), dtype=float) for f in ImageSequence.Iterator(im)]
    assert len(pictures) >= frames, f"{path}: {len(pictures)} frames"
    assert all(p.std() > 1.0 for p in pictures), f"{path}: a blank picture"
    if frames > 1:
        assert any(np.abs(p - pictures[0]).max() > 0 for p in pictures[1:]), f"{path}: every frame the same"


def test_simulate_then_torques(tmp_path, capsys):
    png, gif, csv = tmp_path / "out.png", tmp_path / "out.gif", tmp_path / "out.csv"
    assert main(["simulate", "planar_2r", "--controller", "computed-torque", "--duration", "0.4",
                 "--plot", str(png), "--gif", str(gif), "--csv", str(csv), "--fps", "10"]) == 0
    out = capsys.readouterr().out
    assert "tracking error" in out and "Lyapunov" in out
    assert_image_shows_something(png)
    assert_image_shows_something(gif, frames=4)
    model = rd.models.load("planar_2r")
    log = read_log(csv, model, require_tau=True)
    assert log.t.shape == (401,) and log.q.shape == (401, 2)
    np.testing.assert_allclose(log.t, np.arange(401) * 1e-3, rtol=0, atol=1e-12)
    # the numbers obey the dynamics: tau = rnea(q, v, a) sample by sample, v is the rate of q,
    # the energy column is the kinetic plus potential energy of the written state
    assert_rel(rd.rnea(model, log.q, log.v, log.a), log.tau, 1e-9, "tau = rnea(q, v, a)")
    assert_rel((log.q[2:] - log.q[:-2]) / 2e-3, log.v[1:-1], 1e-3, "v = dq/dt")
    energy = rd.kinetic_energy(model, log.q, log.v) + rd.potential_energy(model, log.q)
    assert_rel(log.extra["energy"], energy, 1e-12, "energy")
    assert np.ptp(log.q[:, 0]) > 0.1  # the robot moved
    t, q, v, a = read_trajectory(csv, model)
    contributions = tmp_path / "contributions.png"
    assert main(["torques", "planar_2r", str(csv), "--plot", str(contributions)]) == 0
    assert_image_shows_something(contributions)
    out = capsys.readouterr().out
    assert "max|coriolis|" in out
    total = np.abs(rd.rnea(model, q, v, a, friction=False)).max(axis=0)
    rows = {w[0]: float(w[-1]) for w in map(str.split, out.splitlines()) if w and w[0] in model.dof_names}
    assert_rel(np.array([rows[n] for n in model.dof_names]), total, 1e-3, "printed max|total|")
    # the CSV as a reference to track
    tracked = tmp_path / "tracked.csv"
    assert main(["simulate", "planar_2r", "--controller", "computed-torque", "--duration", "0.2", "--reference",
                 str(csv), "--csv", str(tracked)]) == 0
    _, q_tracked, _, _ = read_trajectory(tracked, model)
    np.testing.assert_allclose(q_tracked, q[:201], rtol=0, atol=1e-6)


@pytest.mark.parametrize("controller", ["none", "pd-gravity"])
def test_simulate_controllers(controller, tmp_path):
    png = tmp_path / "out.png"
    assert main(["simulate", "double_pendulum", "--controller", controller, "--duration", "0.2",
                 "--integrator", "semi_implicit_euler", "--q0", "0.3,-0.2", "--plot", str(png)]) == 0
    assert_image_shows_something(png)


def test_torques_of_a_hand_written_file(tmp_path):
    t = np.linspace(0, 1, 51)
    path = tmp_path / "q.csv"
    np.savetxt(path, np.column_stack([t, np.sin(t), t ** 2]), delimiter=",", header="t,q:joint1,q:joint2",
               comments="")
    assert main(["torques", "double_pendulum", str(path), "--plot", str(tmp_path / "c.png")]) == 0
    assert_image_shows_something(tmp_path / "c.png")


def test_errors(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["simulate", "planar_2r", "--controller", "lqr"])
    assert e.value.code == 2
    assert main(["simulate", "planar_2r", "--q0", "1,2,3"]) == 2
    assert "--q0: expected 2 comma-separated numbers, got 3" in capsys.readouterr().err
    assert main(["simulate", "planar_2r", "--reference", "x.csv"]) == 2
    assert "--reference applies to --controller computed-torque" in capsys.readouterr().err
    assert main(["simulate", "planar_2r", "--dt", "0"]) == 2
    assert "dt: must be finite and > 0" in capsys.readouterr().err
    (tmp_path / "bad.csv").write_text("t,q:joint1\n0,1\n1,2\n")
    assert main(["torques", "planar_2r", str(tmp_path / "bad.csv")]) == 2
    assert "missing columns" in capsys.readouterr().err


def test_simulate_a_quadruped_dropped_on_the_ground(tmp_path, capsys):
    from conftest import example_robot_data_dir

    urdf = str(example_robot_data_dir() / "solo_description/robots/solo12.urdf")
    png, csv = tmp_path / "contacts.png", tmp_path / "run.csv"
    with pytest.warns(rd.RobodynWarning, match="<contact>"):
        assert main(["simulate", urdf, "--ground", "--duration", "2", "--contact-plot", str(png),
                     "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert "controller stand" in out and "semi_implicit_euler" in out
    assert "contacts: 4 on the ground (FL_FOOT, FR_FOOT, HL_FOOT, HR_FOOT); at the end 4 touch" in out
    with pytest.warns(rd.RobodynWarning, match="<contact>"):
        model = rd.load_urdf(urdf, floating_base=True)
    weight = float(out.split("normal forces sum to ")[1].split(" N")[0])
    assert weight == pytest.approx(model.total_mass * 9.81, rel=1e-4)
    assert_image_shows_something(png)
    run = rd.simulation.Trajectory.from_csv(csv, model)  # the contact forces are in the file
    assert [name.split(":")[0] for name in run.contact_names] == ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    assert run.normal_force[-1].sum() == pytest.approx(weight, rel=1e-3)


def test_ground_options_and_their_errors(capsys):
    # a fixed-base arm whose hand touches the floor: the contacts given by name
    assert main(["simulate", "panda", "--ground", "--contacts", "link7", "--duration", "0.3", "--controller",
                 "none", "--friction", "0.5"]) == 0
    assert "contacts: 1 on the ground (link7)" in capsys.readouterr().out
    assert main(["simulate", "panda", "--contact-plot", "x.png"]) == 2
    assert "--contact-plot applies to --ground" in capsys.readouterr().err
    assert main(["simulate", "panda", "--ground", "--contacts", "nowhere"]) == 2
    assert "--ground: Contacts.shapes[0]: unknown link or frame 'nowhere'" in capsys.readouterr().err
    assert main(["simulate", "panda", "--ground", "--friction", "-1"]) == 2
    assert "--ground: Plane.friction: must be >= 0" in capsys.readouterr().err
    assert main(["simulate", "panda", "--ground", "--contact-radius", "0"]) == 2
    assert "--ground: Sphere.radius: must be > 0" in capsys.readouterr().err
    assert main(["simulate", "panda", "--ground", "--integrator", "rk4"]) == 2
    assert "with contacts the time stepping is 'semi_implicit_euler'" in capsys.readouterr().err
