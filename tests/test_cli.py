"""The command line: info, demo, bench and warmup on built-in robots and URDF files, and its errors."""

from __future__ import annotations

import pathlib
import re
import sys

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.cli.model import sample_state


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_info_builtin(capsys):
    code, out, _ = run(capsys, "info", "puma560")
    assert code == 0
    assert "Model 'puma560': nq=6, nv=6" in out
    for k in range(1, 7):
        assert f"joint{k}" in out
    assert "Inertial parameters per body" in out and "Joint data" in out


def test_info_list(capsys):
    code, out, _ = run(capsys, "info", "--list")
    assert code == 0
    assert [line.split()[0] for line in out.strip().splitlines()] == rd.models.names()


def test_info_urdf(capsys, tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text("""<robot name="arm">
      <link name="base"/>
      <link name="l1"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
    </robot>""")
    code, out, _ = run(capsys, "info", str(urdf))
    assert code == 0 and "Model 'arm': nq=1, nv=1" in out and "j1" in out
    code, out, _ = run(capsys, "info", str(urdf), "--floating-base")
    assert code == 0 and "nq=8, nv=7" in out and "root_joint" in out


def test_info_and_demo_of_a_mujoco_model(capsys, tmp_path):
    xml = tmp_path / "cart.xml"
    xml.write_text('<mujoco model="cart"><worldbody><body name="cart"><joint name="slider" type="slide" '
                   'axis="1 0 0"/><geom type="box" size="0.2 0.1 0.05"/><body name="pole"><joint name="hinge" '
                   'axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 0.6" size="0.045"/></body></body>'
                   '</worldbody></mujoco>')
    code, out, _ = run(capsys, "info", str(xml))
    assert code == 0 and "Model 'cart': nq=2, nv=2" in out and "slider" in out and "hinge" in out
    code, out, _ = run(capsys, "demo", str(xml))
    assert code == 0
    code, _, err = run(capsys, "info", str(xml), "--floating-base")
    assert code == 2 and "a MuJoCo model declares its free joints" in err


def test_demo_numbers_are_the_library_numbers(capsys):
    code, out, _ = run(capsys, "demo", "planar_2r")
    assert code == 0
    model = rd.models.load("planar_2r")
    q, v, a = sample_state(model, 0)
    tau = rd.rnea(model, q, v, a, friction=False, armature=False)
    g = rd.gravity(model, q)
    rows = [line.split() for line in out.splitlines() if re.match(r"\s+joint\d", line)]
    assert len(rows) == 2
    for k, row in enumerate(rows):
        inertial, coriolis, grav, total = map(float, row[1:5])
        assert total == pytest.approx(tau[k], abs=1e-4)
        assert grav == pytest.approx(g[k], abs=1e-4)
        assert inertial + coriolis + grav == pytest.approx(total, abs=3e-4)
    residuals = [float(x) for x in re.findall(r"= ([0-9.e+-]+)$", out, re.M)]
    assert residuals and max(residuals) < 1e-9


def test_demo_default_is_panda(capsys):
    code, out, _ = run(capsys, "demo")
    assert code == 0 and "robodyn demo on 'panda'" in out and "Mass matrix" in out


def test_bench_without_comparison(capsys):
    code, out, _ = run(capsys, "bench", "pendulum", "--batch", "50", "--no-compare")
    assert code == 0
    for name in ("rnea", "aba", "crba", "coriolis_matrix", "rnea (batch)"):
        assert re.search(rf"^\s+{re.escape(name)}\s+\d+\.\d+", out, re.M), name


def test_bench_compares_with_pinocchio(capsys):
    code, out, _ = run(capsys, "bench", "double_pendulum", "--batch", "50")
    assert code == 0
    row = next(line for line in out.splitlines() if line.strip().startswith("rnea "))
    robodyn_us, pin_us, ratio = map(float, row.split()[1:4])
    assert ratio == pytest.approx(robodyn_us / pin_us, rel=0.01)


def test_to_pinocchio_matches(capsys):
    import pinocchio as pin

    from robodyn.interop import to_pinocchio
    from robodyn.random import random_model, random_state

    for floating in (False, True):
        model = random_model(6, seed=4, floating_base=floating)
        pm = to_pinocchio(model)
        q, v, a = random_state(model, np.random.default_rng(0))
        np.testing.assert_allclose(pin.rnea(pm, pm.createData(), q, v, a), rd.rnea(model, q, v, a), rtol=1e-10, atol=1e-10)


def test_benchmark_agreement_check_sees_a_difference():
    """``bench.agreement`` (what ``benchmarks/compare.py`` checks before it reports) is tiny on
    the same robot and large when the Pinocchio model differs by one mass."""
    import pinocchio as pin

    from robodyn.bench import agreement
    from robodyn.interop import to_pinocchio
    from robodyn.random import random_model

    # a chain: Pinocchio's CRBA needs the bodies in depth-first order, which a random tree lacks
    model = random_model(6, seed=5, floating_base=True, branching=0.0)
    errors = agreement(model, to_pinocchio(model), 40)
    assert set(errors) == {"rnea", "aba", "crba", "coriolis_matrix"} and max(errors.values()) < 1e-11
    pm = to_pinocchio(model)
    I = pm.inertias[3]
    pm.inertias[3] = pin.Inertia(2 * I.mass + 1, I.lever, I.inertia)
    assert min(agreement(model, pm, 40).values()) > 1e-6
    with pytest.raises(ValueError, match="depth-first"):  # parents [-1, 0, 0, 0, 3, 1, 5]
        to_pinocchio(random_model(6, seed=5, floating_base=True))


def test_bench_of_a_tree_pinocchio_cannot_order_times_robodyn_alone(capsys):
    from robodyn.bench import run_bench
    from robodyn.random import random_model

    assert run_bench(random_model(6, seed=5, floating_base=True), "tree", batch=10) == 0
    out = capsys.readouterr().out
    assert "robodyn timings only: to_pinocchio: body 5" in out
    assert re.search(r"^\s+aba \(batch\)\s+\d+\.\d+\s*$", out, re.M)  # no Pinocchio column


@pytest.mark.parametrize("argv, message", [
    (("info", "no_such_robot"), "unknown model 'no_such_robot'"),
    (("demo", "/nonexistent/robot.urdf"), "cannot read"),
    (("demo", "panda", "--floating-base"), "--floating-base applies to URDF files"),
])
def test_errors_exit_2_with_a_message(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert message in err


def test_output_piped_into_a_reader_that_stops_early_exits_quietly():
    """``robodyn demo | true``: no BrokenPipeError traceback, exit status 0."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "robodyn.cli", "demo", "pendulum"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader goes away before the output comes
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 0, err
    assert "Traceback" not in err


def test_warmup_compiles_every_step_and_draws_a_bar_on_a_terminal(capsys, monkeypatch):
    """``robodyn warmup``: every step of ``robodyn._warmup.steps()`` runs; on a terminal a
    progress bar goes to stderr."""
    from robodyn import _warmup

    total = len(_warmup.steps())
    code, out, err = run(capsys, "warmup")
    assert code == 0
    assert f"robodyn warmup: {total} steps compiled or loaded from the cache in" in out
    assert err == ""  # not a terminal: no bar
    monkeypatch.setattr(_warmup, "steps", lambda: [("a", lambda: None), ("b", lambda: None)])
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    code, out, err = run(capsys, "warmup", "--processes", "1")  # (the stand-in steps are this process's)
    assert code == 0 and "2 steps" in out
    assert "[" + "#" * 30 + "] 100%" in err
    code, out, err = run(capsys, "warmup", "--processes", "0")
    assert code == 2 and "--processes 0: expected a number of processes >= 1" in err


def test_demo_says_when_rnea_adds_friction_and_armature(capsys):
    """The slides' recipe "rnea gives M a + C v + g" holds for the rigid bodies only: on a
    robot with joint friction and rotor inertia (PUMA 560) the demo prints what rnea's
    defaults add, and the numbers it prints are those of rnea and of model.rigid()."""
    code, out, _ = run(capsys, "demo", "puma560")
    assert code == 0 and "NOTE rnea(model, q, v, a) with its defaults also adds" in out
    model = rd.models.load("puma560")
    q, v, a = sample_state(model, 0)
    full = rd.rnea(model, q, v, a)
    rigid = rd.rnea(model.rigid(), q, v, a)
    np.testing.assert_array_equal(rigid, rd.rnea(model, q, v, a, friction=False, armature=False))
    more = float(re.search(r"up to ([0-9.e+-]+) N m more", out).group(1))
    assert more == pytest.approx(np.abs(full - rigid).max(), rel=1e-3) and more > 1.0
    code, out, _ = run(capsys, "demo", "planar_2r")
    assert "no joint friction or armature in this model" in out


def test_a_free_simulation_moves(capsys):
    """Without a controller the run starts away from the default pose (an equilibrium of the
    pendulum), so something moves; energy is conserved."""
    code, out, _ = run(capsys, "simulate", "pendulum", "--duration", "0.5")
    assert code == 0
    start, end, drift = (float(x) for x in re.search(r"energy: start (\S+) J, end (\S+) J, max \|E - E0\| (\S+) J",
                                                      out).groups())
    model = rd.models.load("pendulum")
    assert start == pytest.approx(float(rd.potential_energy(model, np.array([0.5]))), rel=1e-5)
    assert drift < 1e-8 * abs(start)


def test_physical_option(capsys):
    """--physical: an unphysical body is refused (the message names the options), kept with
    'warn', repaired with 'repair' (the warning gives the moments before and after)."""
    urdf = str(pathlib.Path(__file__).parent / "fixtures" / "triangle_inequality.urdf")
    code, _, err = run(capsys, "info", urdf)
    assert code != 0 and "physical='repair'" in err and "Traceback" not in err
    with pytest.warns(rd.RobodynWarning, match=r"\[0.1, 0.1, 0.5\] repaired to \[0.233333, 0.233333, 0.233333\]"):
        code, out, _ = run(capsys, "info", urdf, "--physical", "repair")
    assert code == 0 and "nq=1, nv=1" in out
    with pytest.warns(rd.RobodynWarning, match="kept as given"):
        assert run(capsys, "info", urdf, "--physical", "warn")[0] == 0
