"""Atomic output files: a writer that fails halfway leaves the previous file untouched and no
partial or temporary file behind."""

import csv

import numpy as np
import pytest

import robodyn as rd
from robodyn.files import atomic_path, write_text


def test_success_replaces_the_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old")
    with atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".csv" and tmp != target
        tmp.write_text("new")
        assert target.read_text() == "old"  # not yet replaced
    assert target.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


def test_failure_keeps_the_old_file_and_removes_the_partial_one(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]
    write_text(target, "text")
    assert target.read_text() == "text"


_CSV_WRITER = csv.writer


class _FailingWriter:
    """A csv writer that writes the header, then fails on the rows."""

    def __init__(self, f, **kw):
        self.inner = _CSV_WRITER(f, **kw)

    def writerow(self, row):
        self.inner.writerow(row)

    def writerows(self, rows):
        raise OSError(28, "No space left on device")


def test_trajectory_csv_interrupted_leaves_nothing(tmp_path, monkeypatch):
    model = rd.models.load("pendulum")
    traj = rd.simulate(model, np.array([0.3]), np.zeros(1), 0.01, 0.001)
    good = tmp_path / "good.csv"
    traj.to_csv(good)
    assert good.read_text().count("\n") == traj.t.shape[0] + 1
    import robodyn.io.log as T

    monkeypatch.setattr(T.csv, "writer", _FailingWriter)
    with pytest.raises(OSError):
        traj.to_csv(tmp_path / "bad.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.csv"]


def test_plots_and_urdf_written_whole(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    from robodyn import plots

    model = rd.models.load("pendulum")
    rd.write_urdf(model, tmp_path / "robot.urdf")
    assert rd.load_urdf(tmp_path / "robot.urdf").nv == 1
    plots._save(Figure(), tmp_path / "fig.png")
    assert (tmp_path / "fig.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # the suffix picked the format

    def broken(self, path, **kw):
        open(path, "wb").write(b"partial")
        raise RuntimeError("renderer failed")

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(RuntimeError):
        plots._save(Figure(), tmp_path / "other.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig.png", "robot.urdf"]
