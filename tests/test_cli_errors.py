"""Every subcommand against bad inputs and unusable output paths: exit status 2, one line on
stderr naming the culprit, no traceback, no output file left behind."""

from __future__ import annotations

import os

import numpy as np
import pytest

from robodyn.cli import main

JOINTS = [f"panda_joint{k}" for k in range(1, 8)] + ["panda_finger_joint1", "panda_finger_joint2"]


def _inputs(tmp_path):
    """Bad input files by kind."""
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(bytes(range(256)) * 4)
    columns = tmp_path / "columns.csv"
    columns.write_text("a,b\n1,2\n3,4\n5,6\n")
    header = "t," + ",".join(f"q:{j}" for j in JOINTS)
    nan = tmp_path / "nan.csv"
    nan.write_text(header + "\n" + "\n".join(f"{k * 0.1}," + ",".join(["nan"] * 9) for k in range(4)) + "\n")
    log_header = "t," + ",".join(f"q:{j}" for j in JOINTS) + "," + ",".join(f"tau:{j}" for j in JOINTS)
    log_nan = tmp_path / "log_nan.csv"
    log_nan.write_text(log_header + "\n" + "\n".join(f"{k * 0.1}," + ",".join(["nan"] * 18) for k in range(4)) + "\n")
    huge = tmp_path / "huge.csv"
    huge.write_text(header + "\n" + "\n".join(f"{k * 0.1}," + ",".join(["1e308"] * 9) for k in range(4)) + "\n")
    return {"missing": tmp_path / "missing.csv", "directory": tmp_path, "empty": empty, "binary": binary,
            "columns": columns, "nan": nan, "log_nan": log_nan, "huge": huge}


INPUT_CASES = [
    ("torques", ["torques", "panda", "{file}"], ["missing", "directory", "empty", "binary", "columns", "nan", "huge"]),
    ("identify", ["identify", "panda", "{file}"], ["missing", "directory", "empty", "binary", "columns", "log_nan"]),
    ("simulate --reference", ["simulate", "panda", "--controller", "computed-torque", "--duration", "0.01",
                              "--reference", "{file}"], ["missing", "directory", "empty", "binary", "columns", "nan"]),
    ("view --trajectory", ["view", "panda", "--trajectory", "{file}", "--video", "{file}.gif"],
     ["missing", "directory", "empty", "binary", "columns", "nan", "huge"]),
]


@pytest.mark.parametrize("name, argv, kinds", INPUT_CASES, ids=[c[0] for c in INPUT_CASES])
def test_bad_inputs_give_one_line_and_status_2(capsys, tmp_path, name, argv, kinds):
    files = _inputs(tmp_path)
    for kind in kinds:
        path = files[kind]
        code = main([a.replace("{file}", str(path)) for a in argv])
        out, err = capsys.readouterr()
        lines = err.strip().splitlines()
        assert code == 2, (kind, err)
        assert len(lines) == 1 and lines[0].startswith("robodyn: error: "), (kind, err)
        assert "Traceback" not in err
        assert path.name in lines[0] or str(path) in lines[0], (kind, err)


OUTPUT_CASES = [
    (["simulate", "panda", "--duration", "0.01", "--csv", "{out}"], "--csv"),
    (["simulate", "panda", "--duration", "0.01", "--plot", "{out}"], "--plot"),
    (["simulate", "panda", "--duration", "0.01", "--gif", "{out}"], "--gif"),
    (["torques", "panda", "{traj}", "--plot", "{out}"], "--plot"),
    (["excite", "panda", "--out", "{out}"], "--out"),
    (["identify", "panda", "{traj}", "--out", "{out}"], "--out"),
    (["identify", "panda", "{traj}", "--report", "{out}"], "--report"),
    (["derive", "pendulum", "--latex", "{out}"], "--latex"),
    (["derive", "pendulum", "--c", "{out}"], "--c"),
    (["view", "panda", "--png", "{out}"], "--png"),
    (["view", "panda", "--trajectory", "{traj}", "--video", "{out}"], "--video"),
]


@pytest.mark.parametrize("argv, option", OUTPUT_CASES, ids=[" ".join(c[0][:1] + [c[1]]) for c in OUTPUT_CASES])
def test_unusable_outputs_refused_before_the_work(capsys, tmp_path, argv, option):
    """A missing directory, a read-only one, or (for files) an existing directory: refused at
    once, naming the option, and nothing is written."""
    traj = tmp_path / "traj.csv"  # never read: the output is checked first
    readonly = tmp_path / "readonly"
    readonly.mkdir()
    readonly.chmod(0o555)
    is_file_option = option != "--report" and option != "--c"
    targets = [tmp_path / "no" / "such" / "x.out", readonly / "x.out"]
    if is_file_option:
        targets.append(tmp_path)
    if os.geteuid() == 0:  # root writes into read-only directories: that case cannot fail here
        targets.remove(readonly / "x.out")
    for out in targets:
        before = sorted(tmp_path.rglob("*"))
        code = main([a.replace("{out}", str(out)).replace("{traj}", str(traj)) for a in argv])
        _, err = capsys.readouterr()
        lines = err.strip().splitlines()
        assert code == 2, (out, err)
        assert len(lines) == 1 and lines[0].startswith(f"robodyn: error: {option} "), (out, err)
        assert sorted(tmp_path.rglob("*")) == before  # nothing written


def test_unexpected_error_is_one_line_and_debug_shows_the_traceback(capsys, monkeypatch):
    from robodyn.cli import model as commands

    def broken(model, seed=0):
        raise RuntimeError("a defect")

    monkeypatch.setattr(commands, "sample_state", broken)
    assert main(["demo", "pendulum"]) == 1
    err = capsys.readouterr().err
    assert err.strip() == "robodyn: internal error: RuntimeError: a defect (rerun with --debug for the traceback)"
    with pytest.raises(RuntimeError, match="a defect"):
        main(["--debug", "demo", "pendulum"])


def test_interrupt_exits_130(capsys, monkeypatch):
    from robodyn.cli import model as commands

    def interrupted(model, seed=0):
        raise KeyboardInterrupt

    monkeypatch.setattr(commands, "sample_state", interrupted)
    assert main(["demo", "pendulum"]) == 130
    assert capsys.readouterr().err.strip() == "robodyn: interrupted"


def test_results_of_a_good_run_are_written(tmp_path, capsys):
    """The checks let a usable output through."""
    out = tmp_path / "traj.csv"
    assert main(["simulate", "pendulum", "--duration", "0.01", "--csv", str(out)]) == 0
    assert out.exists() and np.isfinite(np.loadtxt(out, delimiter=",", skiprows=1)).all()


MODEL_COMMANDS = [["info"], ["demo"], ["bench", "--no-compare"], ["simulate", "--duration", "0.01"],
                  ["torques", "t.csv"], ["excite", "--out", "x.csv"], ["identify", "d.csv"], ["derive"],
                  ["view", "--png", "v.png"]]


@pytest.mark.parametrize("command", MODEL_COMMANDS, ids=[c[0] for c in MODEL_COMMANDS])
def test_bad_model_arguments(capsys, tmp_path, monkeypatch, command):
    """Every command that takes a MODEL: a missing, directory, binary or empty URDF, or an
    unknown name, is one line naming it, status 2."""
    monkeypatch.chdir(tmp_path)
    binary = tmp_path / "bin.urdf"
    binary.write_bytes(b"\xff\xfe\x00binary")
    empty = tmp_path / "empty.urdf"
    empty.write_text("")
    (tmp_path / "dir.urdf").mkdir()
    for spec in (str(tmp_path / "missing.urdf"), str(tmp_path / "dir.urdf"), str(binary), str(empty), "nosuchrobot"):
        argv = [command[0], spec, *command[1:]]
        code = main(argv)
        _, err = capsys.readouterr()
        lines = err.strip().splitlines()
        assert code == 2, (argv, err)
        assert len(lines) == 1 and lines[0].startswith("robodyn: error: ") and "Traceback" not in err, (argv, err)
        assert spec.rsplit("/", 1)[-1] in lines[0], (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bin.urdf", "dir.urdf", "empty.urdf"]  # nothing written


def test_a_write_that_fails_after_the_work_saves_the_result_elsewhere(capsys, tmp_path, monkeypatch):
    """The disk fills up (or the directory goes away) after the simulation ran: the CSV goes
    to a new temporary directory, stdout and the one error line say where, status 2."""
    import robodyn.files as files

    target = tmp_path / "traj.csv"
    real_replace = os.replace

    def full_disk(src, dst):
        if str(dst) == str(target):
            raise OSError(28, "No space left on device")
        real_replace(src, dst)

    monkeypatch.setattr(files.os, "replace", full_disk)
    code = main(["simulate", "pendulum", "--duration", "0.01", "--csv", str(target)])
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert f"--csv {target}: No space left on device; saved to " in lines[0]
    rescued = lines[0].rsplit("saved to ", 1)[1].removesuffix(" instead")
    assert f"wrote {rescued}" in out
    assert not target.exists() and sorted(p.name for p in tmp_path.iterdir()) == []
    t = np.loadtxt(rescued, delimiter=",", skiprows=1)[:, 0]
    np.testing.assert_allclose(t, np.arange(11) * 0.001)  # the whole run
