"""The simulate and torques commands: every output file written and non-empty, CSV output
readable by torques, errors."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.simulation import read_csv


def test_simulate_then_torques(tmp_path, capsys):
    png, gif, csv = tmp_path / "out.png", tmp_path / "out.gif", tmp_path / "out.csv"
    assert main(["simulate", "planar_2r", "--controller", "computed-torque", "--duration", "0.4",
                 "--plot", str(png), "--gif", str(gif), "--csv", str(csv), "--fps", "10"]) == 0
    out = capsys.readouterr().out
    assert "tracking error" in out and "Lyapunov" in out
    for f in (png, gif, csv):
        assert f.stat().st_size > 0, f
    model = rd.models.load("planar_2r")
    t, q, v, a = read_csv(model, csv)
    assert t.shape == (401,) and q.shape == (401, 2)
    contributions = tmp_path / "contributions.png"
    assert main(["torques", "planar_2r", str(csv), "--plot", str(contributions)]) == 0
    assert contributions.stat().st_size > 0
    assert "max|coriolis|" in capsys.readouterr().out


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
    assert main(["simulate", "planar_2r", "--dt", "0"]) == 2
    assert "dt: must be finite and > 0" in capsys.readouterr().err
    (tmp_path / "bad.csv").write_text("t,q:joint1\n0,1\n1,2\n")
    assert main(["torques", "planar_2r", str(tmp_path / "bad.csv")]) == 2
    assert "missing columns" in capsys.readouterr().err
