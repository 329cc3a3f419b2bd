"""One tabular format and one name per concept: the output of every command is the input of
the next (``excite`` -> ``simulate --csv`` -> ``identify``), trajectories round-trip through CSV
and Parquet, the older log spelling and the old keyword, field and term names still work with
a deprecation warning, and coordinate names come from ``Model.q_names`` / ``Model.dof_names``."""

from __future__ import annotations

import csv
import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn import control
from robodyn import identification as ident
from robodyn.cli import main
from robodyn.contact import Contacts, Plane, Sphere
from robodyn.errors import RobodynDeprecationWarning, RobodynWarning
from robodyn.io.log import read_log, read_trajectory, write_log
from robodyn.simulation import Trajectory

from helpers import rng_for


def _columns(path):
    with open(path, newline="") as f:
        return next(csv.reader(f))


def test_simulate_csv_identifies_with_noise(tmp_path, capsys):
    """excite -> simulate --csv (computed torque tracking the excitation) -> noise on the torques
    -> identify: the identified URDF has the model's base parameters (inertial and friction)."""
    traj, run, noisy, urdf = (tmp_path / n for n in ("traj.csv", "run.csv", "noisy.csv", "identified.urdf"))
    assert main(["excite", "elbow_3r", "--duration", "6", "--out", str(traj), "--harmonics", "2",
                 "--samples", "30", "--maxiter", "3", "--rate", "50"]) == 0
    assert main(["simulate", "elbow_3r", "--controller", "computed-torque", "--reference", str(traj),
                 "--duration", "6", "--dt", "0.002", "--csv", str(run)]) == 0
    model = rd.models.load("elbow_3r")
    log = read_log(run, model, require_tau=True)
    assert log.v is not None and log.a is not None and "energy" in log.extra
    sigma = 0.01 * np.abs(log.tau).max()
    tau = log.tau + sigma * rng_for("vocabulary-noise").standard_normal(log.tau.shape)
    write_log(noisy, model, log.t, log.q, v=log.v, a=log.a, tau=tau)
    capsys.readouterr()
    assert main(["identify", "elbow_3r", str(noisy), "--method", "physical", "--out", str(urdf)]) == 0
    base = ident.base_parameters(model, damping=True, coulomb=True)
    back = rd.load_urdf(urdf)
    stacked = lambda m: np.concatenate([m.inertial_parameters(), m.damping, m.coulomb])  # noqa: E731
    expected, found = base.project(stacked(model)), base.project(stacked(back))
    # the identified model predicts the clean torques to the noise level, and each base
    # parameter is recovered to a small fraction of the largest one
    predicted = rd.rnea(back, log.q, log.v, log.a)
    assert np.sqrt(np.mean((predicted - log.tau) ** 2)) < 0.15 * sigma  # about 0.05 sigma
    assert np.max(np.abs(found - expected)) < 1e-2 * np.abs(expected).max(), (found, expected)  # about 3e-3
    # a pure-noise prediction would not pass: the check can fail
    assert np.sqrt(np.mean(log.tau ** 2)) > 10 * sigma


def floating_arm():
    """A floating base with one revolute joint ``arm``."""
    b = rd.ModelBuilder()
    b.add_link("base", mass=1.0, inertia=0.1 * np.eye(3))
    b.add_joint("arm", "revolute", "base", "link", axis=(0, 0, 1))
    b.add_link("link", mass=1.0, com=(0.5, 0, 0), inertia=0.01 * np.eye(3))
    return b.build(floating_base=True)


def test_write_read_round_trip_csv_and_parquet(tmp_path):
    model = floating_arm()
    rng = rng_for("log-round-trip")
    n = 7
    t = np.arange(n) * 0.01
    q = rng.standard_normal((n, model.nq))
    v, a, tau = (rng.standard_normal((n, model.nv)) for _ in range(3))
    extra = {"energy": rng.standard_normal(n), "label:x": rng.standard_normal(n)}
    for name in ("log.csv", "log.parquet"):
        path = write_log(tmp_path / name, model, t, q, v=v, a=a, tau=tau, extra=extra)
        log = read_log(path, model, require_tau=True)
        for x, y in ((log.t, t), (log.q, q), (log.v, v), (log.a, a), (log.tau, tau)):
            np.testing.assert_array_equal(x, y)  # full precision, bit for bit
        assert set(log.extra) == set(extra) and all(np.array_equal(log.extra[k], extra[k]) for k in extra)
    header = _columns(tmp_path / "log.csv")
    assert header[:1 + model.nq] == ["t"] + [f"q:{n}" for n in model.q_names]
    assert header[1 + model.nq:1 + model.nq + model.nv] == [f"v:{n}" for n in model.dof_names]
    with pytest.raises(ValueError, match=r"tau: expected shape \(7, "):
        write_log(tmp_path / "bad.csv", model, t, q, tau=tau[:, :-1])
    with pytest.raises(ValueError, match="repeats a column"):
        write_log(tmp_path / "bad.csv", model, t, q, extra={"t": t})
    q[2, 0] = np.nan  # a Parquet file's rows are numbered from 1 in the messages
    with pytest.raises(ValueError, match=r"1 rows with missing or non-finite values at lines \[3\]"):
        read_log(write_log(tmp_path / "nan.parquet", model, t, q), model)
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({}), tmp_path / "no-columns.parquet")
    with pytest.raises(ValueError, match=r"no-columns.parquet: missing columns \['t', "):
        read_log(tmp_path / "no-columns.parquet", model)
    for column in (["a"] * n, [{"x": 1.0}] * n):  # text, and a structure
        pq.write_table(pa.table({"t": t, "q:arm": column}), tmp_path / "text.parquet")
        with pytest.raises(ValueError, match=r"text.parquet: non-numeric column"):
            read_log(tmp_path / "text.parquet", model)
    with pytest.raises(TypeError):
        write_log(tmp_path / "bad.csv", model, t, q, v)  # v, a, tau and extra are keywords only
    log = read_log(path, model)
    with pytest.raises(AttributeError):  # a frozen dataclass
        log.t = t


def test_names_come_from_one_table():
    m = floating_arm()
    free = m.body_joint_names[0]
    assert m.q_names == [f"{free}:{c}" for c in ("x", "y", "z", "qx", "qy", "qz", "qw")] + ["arm"]
    assert m.dof_names == [f"{free}:{c}" for c in ("vx", "vy", "vz", "wx", "wy", "wz")] + ["arm"]
    assert rd.algorithms.regressor.extra_columns(m, damping=True)[-1] == "damping[arm]"


def test_trajectory_round_trip_with_controller_and_contacts(tmp_path):
    model = rd.models.load("planar_2r")
    ctrl = control.PIDGravity(model, np.array([0.3, -0.2]), kp=50.0, ki=5.0, kd=10.0)
    traj = rd.simulate(model, np.zeros(2), np.zeros(2), 0.05, 1e-3, controller=ctrl)
    b = rd.ModelBuilder()
    b.add_link("body", mass=1.0, inertia=0.004 * np.eye(3))
    ball = b.build(floating_base=True)
    contacts = Contacts([Sphere("body", 0.1)], surfaces=[Plane(friction=0.5)])
    drop = rd.simulate(ball, [0, 0, 0.105, 0, 0, 0, 1], [0.3, 0, -0.5, 0, 0, 0], 0.05, 1e-3, contacts=contacts)
    for run, m, name in ((traj, model, "pid.csv"), (drop, ball, "drop.parquet")):
        run.to_csv(tmp_path / name)
        back = Trajectory.from_csv(tmp_path / name, m)
        for field in ("t", "q", "v", "a", "tau", "kinetic", "potential", "energy", "lyapunov", "q_desired",
                      "v_desired", "controller_state", "contact_force", "contact_normal", "contact_distance",
                      "contact_friction", "solver_iterations", "solver_residual", "constraint_force"):
            x, y = getattr(back, field), getattr(run, field)
            assert (x is None) == (y is None), field
            if x is not None:
                np.testing.assert_array_equal(x, y, err_msg=field)
        assert back.contact_names == run.contact_names
    assert drop.contact_force is not None and np.abs(drop.contact_force).max() > 1.0  # the ball touched
    pair = drop.contact_names[0]
    assert f"contact:{pair}:fz" in read_log(tmp_path / "drop.parquet", ball).extra
    assert traj.controller_state is not None


def test_the_old_log_spelling_is_read_with_a_warning(tmp_path):
    model = rd.models.load("planar_2r")
    rng = rng_for("old-log")
    t = np.arange(5) * 0.01
    q, v, a, tau = (rng.standard_normal((5, 2)) for _ in range(4))
    old = tmp_path / "old.csv"
    header = ["time"] + [f"{k}_{j}" for k in ("q", "qd", "qdd", "tau") for j in model.joint_names]
    with open(old, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(np.hstack([t[:, None], q, v, a, tau]).tolist())
    with pytest.warns(RobodynDeprecationWarning, match=r"time, q_<joint>.*t, q:<joint>") as caught:
        log = read_log(old, model, require_tau=True)
    assert caught[0].filename == __file__  # the warning points at the caller's line
    for x, y in ((log.t, t), (log.q, q), (log.v, v), (log.a, a), (log.tau, tau)):
        np.testing.assert_array_equal(x, y)
    with pytest.warns(RobodynDeprecationWarning):
        assert read_trajectory(old, model)[2] is not None
    # a file with t is in the new spelling: a column spelt the old way is an extra, without a warning;
    # without t and without the old names there is nothing to rename (and no warning)
    new = tmp_path / "new.csv"
    write_log(new, model, t, q, extra={"tau_joint1": tau[:, 0]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = read_log(new, model)
        assert log.tau is None and list(log.extra) == ["tau_joint1"]
        new.write_text("seconds,q:joint1,q:joint2\n0,0,0\n1,1,1\n")
        with pytest.raises(ValueError, match=r"missing columns \['t'\]"):
            read_log(new, model)


def test_text_columns(tmp_path):
    model = rd.models.load("planar_2r")
    path = tmp_path / "notes.csv"
    path.write_text("t,q:joint1,q:joint2,note\n0,0,0,start\n0.1,1,1,\n0.2,2,2,end\n")
    with pytest.warns(RobodynWarning, match=r"columns \['note'\] hold text and are not read") as caught:
        log = read_log(path, model)
    assert caught[0].filename == __file__  # the warning points at the caller's line
    assert log.extra == {} and log.q.shape == (3, 2)
    path.write_text("t,q:joint1,q:joint2\n0,0,0\n0.1,x,1\n0.2,2,2\n")
    with pytest.raises(ValueError, match=r"line 3, column 'q:joint1': not a number: 'x'"):
        read_log(path, model)


def test_parquet_needs_pyarrow_and_says_so(tmp_path, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_pyarrow(name, *args, **kw):
        if name.startswith("pyarrow"):
            raise ImportError(name)
        return real(name, *args, **kw)

    monkeypatch.setattr(builtins, "__import__", no_pyarrow)
    model = rd.models.load("planar_2r")
    with pytest.raises(ValueError, match=r'pip install "robodyn\[parquet\]"'):
        write_log(tmp_path / "x.parquet", model, [0.0, 1.0], np.zeros((2, 2)))
    assert not (tmp_path / "x.parquet").exists()


# -- the old names: same results, one warning each ----------------------------------------------
def test_old_keywords_give_the_same_results_with_a_warning(tmp_path):
    model = rd.models.load("panda")
    rng = rng_for("old-keywords")
    q, v, a = rng.standard_normal(7), rng.standard_normal(7), rng.standard_normal(7)
    f = rng.standard_normal((model.nbodies, 6))
    for fn, args in ((rd.rnea, (q, v, a)), (rd.aba, (q, v, a)), (rd.rnea_derivatives, (q, v, a)),
                     (rd.aba_derivatives, (q, v, a))):
        new = fn(model, *args, f, frame="world")
        with pytest.warns(RobodynDeprecationWarning, match=r"'f_ext_frame' is deprecated, use 'frame'"):
            old = fn(model, *args, f, f_ext_frame="world")
        for x, y in zip(np.atleast_1d(new) if not isinstance(new, tuple) else new,
                        np.atleast_1d(old) if not isinstance(old, tuple) else old):
            np.testing.assert_array_equal(x, y)
        with pytest.raises(TypeError, match="got both 'f_ext_frame'"):
            fn(model, *args, f, frame="world", f_ext_frame="world")
    with pytest.warns(RobodynDeprecationWarning, match="'viscous' is deprecated, use 'damping'"):
        old = rd.regressor(model, q, v, a, viscous=True)
    np.testing.assert_array_equal(old, rd.regressor(model, q, v, a, damping=True))
    with pytest.raises(TypeError, match="got both 'viscous'"):
        rd.regressor(model, q, v, a, viscous=True, damping=True)
    t, path = np.arange(3) * 0.1, tmp_path / "old-keywords.csv"
    with pytest.warns(RobodynDeprecationWarning) as caught:
        write_log(path, model, t, np.tile(q, (3, 1)), qd=np.tile(v, (3, 1)), qdd=np.tile(a, (3, 1)))
    assert sorted(str(w.message) for w in caught) == ["write_log(): 'qd' is deprecated, use 'v'",
                                                      "write_log(): 'qdd' is deprecated, use 'a'"]
    log = read_log(path, model)
    np.testing.assert_array_equal(log.v, np.tile(v, (3, 1)))
    np.testing.assert_array_equal(log.a, np.tile(a, (3, 1)))
    with pytest.warns(RobodynDeprecationWarning, match="'viscous' is deprecated"):
        assert ident.base_parameters(rd.models.load("planar_2r"), viscous=True).count == \
            ident.base_parameters(rd.models.load("planar_2r"), damping=True).count
    ball = rd.ModelBuilder()
    ball.add_link("body", mass=1.0, inertia=0.01 * np.eye(3))
    ball = ball.build(floating_base=True)
    wrench = np.array([[1.0, 0, 0, 0, 0, 0]])
    new = rd.simulate(ball, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.01, 1e-3, f_ext=wrench, frame="world")
    with pytest.warns(RobodynDeprecationWarning, match="simulate"):
        old = rd.simulate(ball, [0, 0, 0, 0, 0, 0, 1], np.zeros(6), 0.01, 1e-3, f_ext=wrench, f_ext_frame="world")
    np.testing.assert_array_equal(new.q, old.q)


def test_old_model_fields_with_a_warning():
    model = rd.models.load("planar_2r")
    with pytest.warns(RobodynDeprecationWarning, match=r"'Model.inertia' is deprecated, use 'Model.theta'"):
        np.testing.assert_array_equal(model.inertia, model.theta)
    with pytest.warns(RobodynDeprecationWarning, match="'inertia' is deprecated, use 'theta'"):
        heavy = model.replace(inertia=2 * model.theta)
    np.testing.assert_array_equal(heavy.theta, 2 * model.theta)
    kw = dict(parent=model.parent, joint_type=model.joint_type, joint_axis=model.joint_axis,
              X_tree_R=model.X_tree_R, X_tree_p=model.X_tree_p, link_names=model.link_names,
              body_joint_names=model.body_joint_names)
    with pytest.warns(RobodynDeprecationWarning):
        again = rd.Model(inertia=model.theta, **kw)
    np.testing.assert_array_equal(again.theta, model.theta)
    with pytest.raises(TypeError, match="missing the keyword argument 'theta'"):
        rd.Model(**kw)
    log = ident.Log(np.arange(3.0), np.zeros((3, 2)), v=np.ones((3, 2)), a=2 * np.ones((3, 2)))
    with pytest.warns(RobodynDeprecationWarning, match="'Log.qd' is deprecated, use 'Log.v'"):
        assert log.qd is log.v
    with pytest.warns(RobodynDeprecationWarning):
        assert log.qdd is log.a


def test_old_symbolic_names_with_a_warning():
    import sympy as sp

    from robodyn import symbolic as S

    eom = S.equations_of_motion(rd.models.load("planar_2r"))
    sm = eom.model
    for old, new in (("axis", "joint_axis"), ("R_tree", "X_tree_R"), ("p_tree", "X_tree_p"), ("inertia", "theta"),
                     ("qd", "v"), ("qdd", "a")):
        with pytest.warns(RobodynDeprecationWarning, match=f"'SymbolicModel.{old}' is deprecated"):
            assert getattr(sm, old) == getattr(sm, new)
    with pytest.warns(RobodynDeprecationWarning):
        assert eom.qd == eom.v
    with pytest.warns(RobodynDeprecationWarning, match="'C_qd' is deprecated, use 'C_v'"):
        assert eom.term("C_qd") == eom.C_v
    with pytest.warns(RobodynDeprecationWarning):
        assert eom.C_qd == eom.C_v
    with pytest.warns(RobodynDeprecationWarning):
        rebuilt = S.SymbolicModel(parent=sm.parent, joint_type=sm.joint_type, axis=sm.joint_axis,
                                  R_tree=sm.X_tree_R, p_tree=sm.X_tree_p, inertia=sm.theta, gravity=sm.gravity)
    assert rebuilt.X_tree_p == sm.X_tree_p and rebuilt.theta == sm.theta
    assert all(isinstance(x, sp.Symbol) for x in eom.v + eom.a)


def test_a_link_is_a_body_and_readers_take_the_path_first(tmp_path):
    """``frame`` names the frame vectors are expressed in; the link or frame a function is
    about is ``body`` (as in ``jacobian``), and every reader takes ``(path, model)``."""
    model = rd.models.load("panda")
    x_d = [0.3, 0.0, 0.5]
    new = control.TaskSpacePD(model, "link7", x_d, kp=10.0, kd=2.0)
    with pytest.warns(RobodynDeprecationWarning, match="'frame' is deprecated, use 'body'"):
        old = control.TaskSpacePD(model, frame="link7", x_desired=x_d, kp=10.0, kd=2.0)
    q, v = np.full(7, 0.2), np.full(7, 0.1)
    np.testing.assert_array_equal(old(0.0, q, v), new(0.0, q, v))
    with pytest.warns(RobodynDeprecationWarning):
        assert old.frame == new.body == "link7"
    with pytest.raises(TypeError, match=r"missing arguments \['kd'\]"):
        control.TaskSpacePD(model, "link7", x_d, kp=10.0)
    path = write_log(tmp_path / "ref.csv", model, [0.0, 0.5, 1.0], np.zeros((3, 7)) + [[0.0], [0.1], [0.2]])
    ref = control.Sampled.from_csv(path, model)
    with pytest.warns(RobodynDeprecationWarning, match=r"Sampled.from_csv\(path, model\)"):
        old_ref = control.Sampled.from_csv(model, path)
    np.testing.assert_array_equal(old_ref(0.25)[0], ref(0.25)[0])


def test_a_parquet_path_that_is_not_parquet(tmp_path):
    bad = tmp_path / "log.parquet"
    bad.write_text("t,q:joint1\n0,0\n")
    with pytest.raises(ValueError, match=r"log.parquet: not a Parquet file"):
        read_log(bad, rd.models.load("planar_2r"))
