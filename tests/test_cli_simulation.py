"""The simulate and torques commands: every output file written and non-empty, CSV output
readable by torques, errors."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.simulation import read_trajectory


def test_simulate_then_torques(tmp_path, capsys):
    png, gif, csv = tmp_path / "out.png", tmp_path / "out.gif", tmp_path / "out.csv"
    assert main(["simulate", "planar_2r", "--controller", "computed-torque", "--duration", "0.4",
                 "--plot", str(png), "--gif", str(gif), "--csv", str(csv), "--fps", "10"]) == 0
    out = capsys.readouterr().out
    assert "tracking error" in out and "Lyapunov" in out
    for f in (png, gif, csv):
        assert f.stat().st_size > 0, f
    model = rd.models.load("planar_2r")
    t, q, v, a = read_trajectory(csv, model)
    assert t.shape == (401,) and q.shape == (401, 2)
    contributions = tmp_path / "contributions.png"
    assert main(["torques", "planar_2r", str(csv), "--plot", str(contributions)]) == 0
    assert contributions.stat().st_size > 0
    assert "max|coriolis|" in capsys.readouterr().out
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
    assert png.stat().st_size > 0


def test_torques_of_a_hand_written_file(tmp_path):
    t = np.linspace(0, 1, 51)
    path = tmp_path / "q.csv"
    np.savetxt(path, np.column_stack([t, np.sin(t), t ** 2]), delimiter=",", header="t,q:joint1,q:joint2",
               comments="")
    assert main(["torques", "double_pendulum", str(path), "--plot", str(tmp_path / "c.png")]) == 0
    assert (tmp_path / "c.png").stat().st_size > 0


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
    png = tmp_path / "contacts.png"
    with pytest.warns(rd.RobodynWarning, match="<contact>"):
        assert main(["simulate", urdf, "--ground", "--duration", "2", "--contact-plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "controller stand" in out and "semi_implicit_euler" in out
    assert "contacts: 4 on the ground (FL_FOOT, FR_FOOT, HL_FOOT, HR_FOOT); at the end 4 touch" in out
    with pytest.warns(rd.RobodynWarning, match="<contact>"):
        model = rd.load_urdf(urdf, floating_base=True)
    weight = float(out.split("normal forces sum to ")[1].split(" N")[0])
    assert weight == pytest.approx(model.total_mass * 9.81, rel=1e-4)
    assert png.stat().st_size > 0


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
