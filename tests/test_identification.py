"""Identification (robodyn.identification): base-parameter counts and identities, Fourier
excitation, CSV logs and their errors, filtering and differentiation, OLS/WLS standard
deviations, the log-Cholesky parameterisation, end to end on the Panda (noise-free recovery,
noisy prediction on another trajectory, physically consistent export), and the CLI."""

from __future__ import annotations

import ast
import dataclasses
import functools
import re

import numpy as np
import pytest

import robodyn as rd
from robodyn import identification as ident
from robodyn.cli import main
from robodyn.identification.identify import METHODS, nominal_parameters
from robodyn.identification.estimation import log_cholesky, theta_jacobian, theta_of_log_cholesky
from robodyn.joints import NQ
from robodyn.model import check_inertial_parameters
from robodyn.random import random_model
from helpers import PLANAR_2R, assert_rel, planar_2r, random_models, rng_for


# -- base parameters --------------------------------------------------------------------------
def _horizontal_2r():
    """The built-in planar 2R with gravity along its joint axes (the arm moves in a horizontal plane)."""
    model = rd.models.load("planar_2r")
    axis_world = rd.forward_kinematics(model, np.zeros(2))[0, :3, :3] @ model.joint_axis[0]
    return model.replace(gravity=9.81 * axis_world)


BASE_COUNTS = [
    ("planar_2r", lambda: rd.models.load("planar_2r"), 6),
    ("planar_2r horizontal", _horizontal_2r, 4),
    ("scara", lambda: rd.models.load("scara"), 8),
    ("puma560", lambda: rd.models.load("puma560"), 36),
    ("ur5", lambda: rd.models.load("ur5"), 36),
    ("panda", lambda: rd.models.load("panda"), 43),
]


@functools.lru_cache(maxsize=None)
def panda_base():
    return ident.base_parameters(rd.models.load("panda"), damping=True, coulomb=True)


@pytest.mark.parametrize("build, count", [(b, c) for _, b, c in BASE_COUNTS], ids=[n for n, _, _ in BASE_COUNTS])
def test_base_parameter_counts(build, count):
    """Known counts (Khalil and Dombre 2002, Gautier 1991; Gaz et al. 2019 for the Panda), a
    clear singular-value gap, and friction columns adding 2 nv."""
    model = build()
    base = ident.base_parameters(model)
    assert base.count == count
    assert base.gap > 1e6
    assert ident.base_parameters(model, damping=True, coulomb=True).count == count + 2 * model.nv


def test_counts_are_structural():
    """Other (or zero) inertial parameters give the same base parameters and the same K: the
    grouping depends on the kinematics only."""
    model = rd.models.load("puma560")
    base = ident.base_parameters(model)
    rng = rng_for("structural")
    for theta in (rng.uniform(0.5, 2.0, 10 * model.nbodies) * model.inertial_parameters(),
                  np.zeros(10 * model.nbodies)):
        other = ident.base_parameters(model.replace(theta=theta.reshape(6, 10), physical="warn"))
        assert np.array_equal(other.independent, base.independent)
        assert_rel(other.K, base.K, 1e-9)


def test_planar_2r_names():
    """Horizontal 2R arm of helpers.planar_2r (l1 = 0.8) with gravity along the joint axes:
    Izz1 absorbs m2 l1^2 (Spong et al. 2006, section 7.4; Khalil and Dombre 2002, section 12.4)."""
    model = planar_2r(**PLANAR_2R).replace(gravity=(0.0, 0.0, -9.81))
    base = ident.base_parameters(model)
    assert base.names == ("Izz1 + 0.64*m2", "mx2", "my2", "Izz2")
    vertical = ident.base_parameters(planar_2r(**PLANAR_2R))
    assert vertical.names == ("mx1 + 0.8*m2", "my1", "Izz1 + 0.64*m2", "mx2", "my2", "Izz2")


@random_models
def test_base_regressor_reproduces_rnea(model):
    """On new random states: Y = Y_base K, and Y_base (K theta) == rnea (fixed and floating base)."""
    base = ident.base_parameters(model, damping=True, coulomb=True)
    q, v, a = ident.base.random_states(model, 3, rng_for(model.name, "base"))
    Y = rd.regressor(model, q, v, a, damping=True, coulomb=True)
    assert_rel(base.regressor(model, q, v, a) @ base.K, Y, 1e-9)
    theta = np.concatenate([model.inertial_parameters(), np.full(2 * model.nv, 0.3)])
    expected = rd.rnea(model.replace(damping=np.full(model.nv, 0.3), coulomb=np.full(model.nv, 0.3)), q, v, a)
    assert_rel(base.regressor(model, q, v, a) @ base.project(theta), expected, 1e-9)
    prior = theta * rng_for(model.name, "prior").uniform(0.5, 1.5, theta.shape)
    completed = base.completion(base.project(theta), prior)
    assert_rel(base.project(completed), base.project(theta), 1e-9)
    # the nearest to the prior: the change lies in the row space of K (orthogonal to its null space)
    change = completed - prior
    assert_rel(np.linalg.pinv(base.K) @ (base.K @ change), change, 1e-9)


def test_random_states_respect_joint_limits():
    """1-dof joints with finite limits are drawn within them, also after a free joint; the
    ones without limits (or with one only) stay in [-pi, pi]; the free joint's quaternion stays
    of unit norm."""
    model = random_model(5, seed=3, floating_base=True)
    one_dof = [i for i in range(model.nbodies) if NQ[model.joint_type[i]] == 1]
    lower, upper = np.full(model.nv, -np.inf), np.full(model.nv, np.inf)
    limited, half, free = one_dof[:-2], one_dof[-2], one_dof[-1]
    for k, i in enumerate(limited):
        lower[model.idx_v[i]], upper[model.idx_v[i]] = -0.3 + 0.1 * k, 0.2 + 0.1 * k
    lower[model.idx_v[half]] = 0.5
    model = model.replace(lower=lower, upper=upper)
    q, v, a = ident.base.random_states(model, 200, rng_for("random-states-limits"))
    assert q.shape == (200, model.nq) and v.shape == a.shape == (200, model.nv)
    for i in limited:
        x, lo, hi = q[:, model.idx_q[i]], lower[model.idx_v[i]], upper[model.idx_v[i]]
        assert np.all((lo <= x) & (x <= hi)) and x.max() - x.min() > 0.9 * (hi - lo), (i, x.min(), x.max())
    for i in (half, free):
        x = q[:, model.idx_q[i]]
        assert np.all(np.abs(x) <= np.pi) and x.min() < -2.5 and x.max() > 2.5
    assert_rel(np.linalg.norm(q[:, 3:7], axis=1), np.ones(200), 1e-12)


def _coefficients(name: str, columns) -> np.ndarray:
    """The row of K that a base parameter's name spells: ``head (+|-) [c*]column ...``."""
    tokens = name.split(" ")
    row = np.zeros(len(columns))
    row[columns.index(tokens[0])] = 1.0
    for sign, term in zip(tokens[1::2], tokens[2::2]):
        c, _, column = term.rpartition("*")
        row[columns.index(column)] = (-1.0 if sign == "-" else 1.0) * (float(c) if c else 1.0)
    return row


def test_base_parameter_names_spell_K():
    """The names carry the signs and (6 significant digits of) the coefficients of K, a
    coefficient of magnitude one without a factor."""
    puma = ident.base_parameters(rd.models.load("puma560"))
    np.testing.assert_allclose([_coefficients(n, puma.columns) for n in puma.names], puma.K, rtol=1e-5, atol=1e-12)
    elbow = ident.base_parameters(rd.models.load("elbow_3r"))
    assert {"Ixx2 - Iyy2 - 0.16*m3", "Ixz2 - 0.4*mz3", "Ixx3 - Iyy3"} <= set(elbow.names)
    arm = ident.base_parameters(planar_2r(**{**PLANAR_2R, "l1": np.sqrt(2.0)}))  # Izz1 absorbs l1^2 m2 = 2 m2
    assert arm.names[:3] == ("mx1 + 1.41421*m2", "my1", "Izz1 + 2*m2")


def test_base_parameter_summary_gap_and_singular_values():
    """The summary's lines; gap = sigma_r / sigma_{r+1} (inf at full column rank); the
    singular values are those of the regressor with its nonzero columns scaled to unit norm
    (squares summing to their number); the result is immutable."""
    base = ident.base_parameters(planar_2r(**PLANAR_2R))
    s = base.singular_values
    assert s.shape == (20,) and np.all(np.diff(s) <= 0)
    assert base.gap == s[5] / s[6]
    # nonzero columns of the vertical 2R arm: mx1, my1, Izz1, m2, mx2, my2, Izz2
    assert_rel(np.sum(s ** 2), 7.0, 1e-12)
    assert base.summary().splitlines() == [
        f"6 base parameters of 20 (relative tolerance 1e-08; singular values of the scaled regressor: "
        f"sigma_6 = {s[5]:.3g}, sigma_7 = {s[6]:.3g}, gap {base.gap:.3g})",
        "    1  mx1 + 0.8*m2", "    2  my1", "    3  Izz1 + 0.64*m2", "    4  mx2", "    5  my2", "    6  Izz2"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        base.rtol = 1e-6
    body = ident.base_parameters(random_model(0, seed=1, floating_base=True))  # one free body: all 10 identifiable
    s = body.singular_values
    assert body.count == 10 and body.gap == np.inf and np.all(s > 0.1)
    assert body.summary().splitlines()[0] == ("10 base parameters of 10 (relative tolerance 1e-08; singular values of "
                                              f"the scaled regressor: sigma_10 = {s[9]:.3g}, full rank)")


def test_base_parameter_errors():
    pendulum = rd.models.load("pendulum")
    for rtol in (2.0, 1.0, 0.0, -1e-8):
        with pytest.raises(ValueError, match=rf"rtol: expected a value in \(0, 1\), got {rtol}"):
            ident.base_parameters(pendulum, rtol=rtol)
    with pytest.raises(TypeError):
        ident.base_parameters(pendulum, True)  # the options are keywords only
    fixed = rd.ModelBuilder("no-joints")
    fixed.add_link("base", mass=1.0, inertia=np.eye(3))
    with pytest.raises(ValueError, match="the model has no joints"):
        ident.base_parameters(fixed.build())
    # rtol inside a cluster of singular values: the rank and the columns kept in order disagree;
    # the message shows the singular values around the rank (two on either side where there are)
    for rtol in (0.9, 0.5):
        with pytest.raises(ValueError, match=rf"singular values above rtol={rtol:g} but \d+ independent") as err:
            ident.base_parameters(rd.models.load("puma560"), rtol=rtol)
        msg = str(err.value)
        rank = int(re.search(r"(\d+) singular values above", msg).group(1))
        shown = ast.literal_eval(re.search(r"near the tolerance: (\[[^]]*\])", msg).group(1))
        assert len(shown) == min(rank, 2) + 2 and shown == sorted(shown, reverse=True), msg


# -- excitation -------------------------------------------------------------------------------
def test_fourier_derivatives_and_period():
    rng = rng_for("fourier")
    traj = ident.FourierTrajectory(rng.standard_normal(3), rng.standard_normal((3, 4)), rng.standard_normal((3, 4)), 2.5)
    t = np.linspace(0, 5, 7)
    q, qd, qdd = traj(t)
    h = 1e-5
    assert_rel(qd, (traj(t + h)[0] - traj(t - h)[0]) / (2 * h), 1e-8)
    assert_rel(qdd, (traj(t + h)[1] - traj(t - h)[1]) / (2 * h), 1e-8)
    assert_rel(traj(t + 2.5)[0], q, 1e-12)


@functools.lru_cache(maxsize=None)
def panda_excitation(seed: int):
    """A small optimisation (3 harmonics, 40 samples, 6 iterations) of the Panda's excitation."""
    model = rd.models.load("panda")
    return ident.optimize_excitation(model, panda_base(), period=8.0, harmonics=3, samples=40, maxiter=6, seed=seed)


def test_excitation_respects_limits_and_improves(tmp_path):
    model = rd.models.load("panda")
    result = panda_excitation(0)
    assert result.condition_number < result.initial_condition_number  # 74 -> 59 (seed 0)
    lim = ident.limits_of(model)
    t = np.arange(40) * 8.0 / 40
    q, qd, qdd = result.trajectory(t)
    tol = 1e-6
    assert np.all(q <= lim.upper + tol) and np.all(q >= lim.lower - tol)
    assert np.all(np.abs(qd) <= lim.velocity * (1 + tol)) and np.all(np.abs(qdd) <= lim.acceleration * (1 + tol))
    assert np.all(lim.lower >= model.lower) and np.all(lim.upper <= model.upper)
    csv, png = ident.write_excitation(tmp_path / "traj.csv", model, result, duration=3.0, rate=50.0)
    log = ident.read_log(csv, model, require_tau=False)
    assert len(log) == 150
    assert_rel(np.hstack([log.q, log.v, log.a]), np.hstack(result.trajectory(log.t)), 0.0)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _stacked_condition(model, base, traj, t) -> float:
    """2-norm condition number of the base regressor stacked over ``t``, by NumPy's SVD."""
    q, qd, qdd = traj(t)
    return float(np.linalg.cond(base.regressor(model, q, qd, qdd).reshape(-1, base.count)))


def test_excitation_optimiser_improves_a_poor_start(monkeypatch):
    """Started from a barely moving trajectory (the random start with every amplitude divided
    by 10: velocities and accelerations so small that the inertial columns of the regressor
    nearly vanish, condition number above 1e4), six SLSQP iterations bring the condition
    number down by a factor of about 300 (2.4e4 to 80 on the Panda, seed 0); at least 30 is
    required. The condition numbers are recomputed here by SVD, not read from the result."""
    from robodyn.identification import excitation

    model = rd.models.load("panda")
    random_start = excitation.feasible_trajectory

    def poor_start(model, **kw):
        traj = random_start(model, **kw)
        return ident.FourierTrajectory(traj.q0, traj.a / 10, traj.b / 10, traj.period)

    monkeypatch.setattr(excitation, "feasible_trajectory", poor_start)
    result = ident.optimize_excitation(model, panda_base(), period=8.0, harmonics=3, samples=40, maxiter=6, seed=0)
    t = np.arange(40) * 8.0 / 40
    start = poor_start(model, period=8.0, harmonics=3, samples=40, limits=ident.limits_of(model), seed=0)
    initial = _stacked_condition(model, panda_base(), start, t)
    final = _stacked_condition(model, panda_base(), result.trajectory, t)
    assert initial > 1e4, f"the start should be poorly exciting, condition number {initial:.3g}"
    assert_rel(result.initial_condition_number, initial, 1e-6)
    assert final * 30 <= initial, f"condition number {initial:.3g} -> {final:.3g}: less than 30x better"
    assert_rel(result.condition_number, final, 1e-6)


# -- data -------------------------------------------------------------------------------------
def _write(path, header, rows):
    path.write_text(",".join(header) + "\n" + "".join(",".join(map(str, r)) + "\n" for r in rows))
    return path


def _two_joint_columns(kinds=("q", "tau")):
    return ["t"] + [f"{k}:{j}" for k in kinds for j in ("joint1", "joint2")]


def test_log_errors(tmp_path):
    model = rd.models.load("planar_2r")
    good = [[0.01 * i, 0.1, 0.2, 1.0, 2.0] for i in range(5)]
    with pytest.raises(ValueError, match=r"missing columns \['tau:joint2'\] .*expected t, q:<coordinate>, tau:<dof> "):
        ident.read_log(_write(tmp_path / "a.csv", _two_joint_columns()[:-1], [r[:-1] for r in good]), model,
                       require_tau=True)
    with pytest.raises(ValueError, match=r"missing columns \['q:joint2'\] .*; expected t, q:<coordinate> with "):
        ident.read_log(_write(tmp_path / "a.csv", ["t", "q:joint1"], [r[:2] for r in good]), model)
    with pytest.raises(ValueError, match=r"repeated column names \['q:joint1'\]$"):
        ident.read_log(_write(tmp_path / "a.csv", _two_joint_columns() + ["q:joint1"], [r + [0] for r in good]), model)
    (tmp_path / "binary.csv").write_bytes(b"t,q:joint1\n\xff\xfe\x00\n")
    with pytest.raises(ValueError, match="binary.csv: not a CSV text file"):
        ident.read_log(tmp_path / "binary.csv", model)
    rows = [r[:] for r in good]
    rows[1][2], rows[3][4] = "nan", ""
    with pytest.raises(ValueError, match=r"2 rows with missing or non-finite values at lines \[3, 5\]"):
        ident.read_log(_write(tmp_path / "b.csv", _two_joint_columns(), rows), model)
    for n_bad, more in ((20, ""), (21, " ...")):  # the first 20 lines, "..." when there are more
        rows = [[0.01 * i, 0.1, "nan" if i < n_bad else 0.2, 1.0, 2.0] for i in range(25)]
        with pytest.raises(ValueError, match=re.escape(f"{n_bad} rows with missing or non-finite values at lines "
                                                       f"{list(range(2, 22))}{more}; remove")):
            ident.read_log(_write(tmp_path / "many.csv", _two_joint_columns(), rows), model)
    rows = [r[:] for r in good]
    rows[3][0], rows[4][0] = 0.015, 0.005  # the first of two steps back is reported
    with pytest.raises(ValueError, match=r"time not strictly increasing at line 5 \(t = 0.015 after 0.02 on line 4\)"):
        ident.read_log(_write(tmp_path / "c.csv", _two_joint_columns(), rows), model)
    with pytest.raises(ValueError, match="1 data rows, need at least 2"):
        ident.read_log(_write(tmp_path / "one.csv", _two_joint_columns(), good[:1]), model)
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(ValueError, match="empty file, expected a header row"):
        ident.read_log(tmp_path / "empty.csv", model)
    with pytest.raises(TypeError):
        ident.read_log(tmp_path / "b.csv", model, True)  # require_tau is a keyword only
    rows = [r[:] for r in good]
    rows[2][1] = "abc"
    with pytest.raises(ValueError, match=r"line 4, column 'q:joint1': not a number"):
        ident.read_log(_write(tmp_path / "d.csv", _two_joint_columns(), rows), model)
    with pytest.raises(ValueError, match=r"v given for some entries only; missing columns \['v:joint2'\]"):
        ident.read_log(_write(tmp_path / "e.csv", _two_joint_columns() + ["v:joint1"], [r + [0] for r in good]), model)
    t = np.array([0.0, 0.01, 0.02, 0.04, 0.05])
    with pytest.raises(ValueError, match="not uniformly sampled"):
        ident.preprocess(ident.Log(t, np.zeros((5, 2)), tau=np.zeros((5, 2))))


def test_preprocess_filters_differentiates_decimates():
    """A slow sine with noise: filtered positions, velocities and accelerations close to the
    analytic ones; decimation keeps every k-th sample; cutoffs that alias are refused."""
    fs, f0 = 500.0, 0.5
    t = np.arange(5000) / fs
    w = 2 * np.pi * f0
    q = np.stack([np.sin(w * t), 0.5 * np.cos(w * t)], axis=1)
    rng = rng_for("preprocess")
    log = ident.Log(t, q + 1e-5 * rng.standard_normal(q.shape), tau=q.copy())
    out = ident.preprocess(log, cutoff=5.0, decimate=4)
    k = int(np.ceil(fs / 5.0))
    assert_rel(out.t, t[k:len(t) - k:4], 0.0)
    tt = out.t
    for x, exact, tol in ((out.q, [np.sin(w * tt), 0.5 * np.cos(w * tt)], 1e-3),
                          (out.v, [w * np.cos(w * tt), -0.5 * w * np.sin(w * tt)], 5e-3),
                          (out.a, [-w * w * np.sin(w * tt), -0.5 * w * w * np.cos(w * tt)], 2e-2)):
        exact = np.stack(exact, 1)
        assert np.abs(x - exact).max() < tol * np.abs(exact).max()
    exact = ident.preprocess(ident.Log(t, q, tau=q))  # no filter: second-order differences
    assert_rel(exact.v, np.stack([w * np.cos(w * exact.t), -0.5 * w * np.sin(w * exact.t)], 1), 1e-4)
    with pytest.raises(ValueError, match="alias"):
        ident.preprocess(log, cutoff=100.0, decimate=4)
    with pytest.raises(ValueError, match="Nyquist"):
        ident.preprocess(log, cutoff=300.0)
    with pytest.raises(ValueError, match="anti-aliasing"):
        ident.preprocess(log, decimate=2)


# -- estimation -------------------------------------------------------------------------------
def test_ols_standard_deviations_match_monte_carlo():
    """The reported standard deviations of OLS and WLS match the spread of the estimates over
    200 noise draws (within 15 %), on the 2R arm (WLS: joint-dependent noise levels)."""
    model = rd.models.load("planar_2r")
    base = ident.base_parameters(model)
    q, v, a = ident.base.random_states(model, 100, rng_for("mc-states"))
    W = base.regressor(model, q, v, a).reshape(-1, base.count)
    y0 = W @ base.project(model.inertial_parameters())
    rng = rng_for("monte-carlo")
    # OLS assumes one noise level for all joints, WLS one per joint
    for method, sigma in ((ident.ols, np.full(200, 0.2)), (ident.wls, np.tile([0.05, 0.5], 100))):
        draws, stds = [], []
        for _ in range(200):
            est = method(W, y0 + sigma * rng.standard_normal(y0.shape), model.nv)
            draws.append(est.beta)
            stds.append(est.std)
        ratio = np.std(draws, axis=0) / np.mean(stds, axis=0)
        assert np.all(np.abs(ratio - 1) < 0.15), (method.__name__, ratio)


def test_log_cholesky():
    """Round trip, analytic Jacobian, and every coordinate vector gives a consistent body."""
    rng = rng_for("log-cholesky")
    for _ in range(5):
        theta = rd.random.random_inertia(rng)
        x = log_cholesky(theta, eps=0.0)
        assert_rel(theta_of_log_cholesky(x), theta, 1e-12)
        h = 1e-6
        fd = np.stack([(theta_of_log_cholesky(x + h * e) - theta_of_log_cholesky(x - h * e)) / (2 * h)
                       for e in np.eye(10)], axis=1)
        assert_rel(theta_jacobian(x), fd, 1e-8)
        check_inertial_parameters(theta_of_log_cholesky(rng.standard_normal(10)), "random coordinates")


def _panda_truth():
    model = rd.models.load("panda")
    return model.replace(damping=np.linspace(0.3, 0.6, 7), coulomb=np.linspace(0.5, 0.9, 7))


def _panda_log(truth, seed, duration, rate, noise_q=0.0, noise_tau=0.0):
    """Seed 0: the optimised excitation; other seeds: a random trajectory within the limits."""
    traj = panda_excitation(0).trajectory if seed == 0 else \
        ident.feasible_trajectory(truth, period=8.0, harmonics=3, samples=40, seed=seed)
    t, q, qd, qdd = traj.sample(duration, rate)
    tau = rd.rnea(truth, q, qd, qdd)
    rng = rng_for("panda-noise", seed)
    return ident.Log(t, q, qd, qdd, tau), ident.Log(t, q + noise_q * rng.standard_normal(q.shape),
                                                    tau=tau + noise_tau * rng.standard_normal(tau.shape))


@pytest.mark.parametrize("method", METHODS)
def test_panda_noise_free_recovers_base_parameters(method):
    """Exact states and torques along an optimised trajectory: least squares recover the base
    parameters (inertial and friction) to 1e-6 relative, each one; the physically consistent
    fit (an iterative solver) reproduces the torques to 1e-6 and the parameters to 1e-2."""
    truth = _panda_truth()
    exact, _ = _panda_log(truth, 0, 8.0, 100.0)
    result = ident.identify(truth.replace(damping=np.zeros(7), coulomb=np.zeros(7),
                                          theta=truth.theta * 1.1), exact, method=method, base=panda_base())
    expected = panda_base().project(np.concatenate([truth.inertial_parameters(), truth.damping, truth.coulomb]))
    scale = np.maximum(np.abs(expected), 1e-3 * np.abs(expected).max())
    error = np.max(np.abs(result.estimate.beta - expected) / scale)
    if method == "physical":
        assert_rel(result.predict(exact), exact.tau, 1e-6)
        assert error < 1e-2
    else:
        assert error < 1e-6


@pytest.mark.parametrize("method", ["ols", "wls", "physical"])
def test_panda_noisy_predicts_another_trajectory(method, tmp_path):
    """Encoder noise 1e-4 rad and torque noise 0.2 N m, filtered at 4 Hz and differentiated:
    the torques of a different trajectory (measured, with the same noise) are predicted with
    an RMS error below twice the noise level on every joint. The physically consistent
    estimate passes the inertia checks and its URDF loads with physical='error'."""
    truth, sigma = _panda_truth(), 0.2
    _, noisy = _panda_log(truth, 0, 16.0, 200.0, noise_q=1e-4, noise_tau=sigma)
    log = ident.preprocess(noisy, cutoff=4.0, decimate=2)
    result = ident.identify(rd.models.load("panda"), log, method=method, base=panda_base())
    other, other_noisy = _panda_log(truth, 1, 8.0, 100.0, noise_tau=sigma)
    pred = result.predict(other)
    rms = np.sqrt(np.mean((pred - other_noisy.tau) ** 2, axis=0))
    assert np.all(rms < 2 * sigma), rms
    if method == "physical":
        theta = result.estimate.theta
        for i in range(7):
            check_inertial_parameters(theta[10 * i:10 * i + 10], f"body {i}")
        path = tmp_path / "identified.urdf"
        rd.write_urdf(result.identified_model(), path)
        back = rd.load_urdf(path)
        assert_rel(rd.rnea(back, other.q, other.v, other.a), pred, 1e-9)
        paths = ident.write_report(result, log, tmp_path / "report", validation=other_noisy.__class__(
            other.t, other.q, other.v, other.a, other_noisy.tau))
        assert {p.name for p in paths} == {"report.txt", "torques.png", "residuals.png", "singular_values.png",
                                           "robot.png"}
        text = paths[0].read_text()
        assert "condition number" in text and "validation data" in text and "Izz1 + Iyy2" in text


# -- joint springs ----------------------------------------------------------------------------
def _sprung_elbow():
    """The elbow arm with friction and a spring on every joint."""
    return rd.models.load("elbow_3r").replace(damping=[0.3, 0.2, 0.1], coulomb=[0.5, 0.4, 0.3],
                                               stiffness=[4.0, 6.0, 2.5], spring_reference=[0.3, -0.5, 0.8])


@pytest.mark.parametrize("method", METHODS)
def test_sprung_arm_recovers_stiffness_and_spring_reference(method):
    """Torques of a sprung arm along a random motion, identified from a model without springs
    with ``stiffness=True, offset=True``: the stiffness ``K`` and, through the offsets
    ``-K q_ref``, the springs' reference positions come back, and the identified model
    reproduces the torques."""
    truth = _sprung_elbow()
    traj = ident.feasible_trajectory(truth, period=6.0, harmonics=3, samples=40, seed=3)
    t, q, qd, qdd = traj.sample(12.0, 50.0)
    log = ident.Log(t, q, qd, qdd, rd.rnea(truth, q, qd, qdd))
    nominal = rd.models.load("elbow_3r")
    result = ident.identify(nominal, log, method=method, stiffness=True, offset=True)
    names = [f"stiffness[{n}]" for n in nominal.dof_names]
    assert set(names) <= set(result.base.names)  # each stiffness is a base parameter by itself
    tol = 1e-4 if method == "physical" else 1e-8
    extra = result.extra()
    assert list(extra) == ["damping", "coulomb", "stiffness", "offset"]
    assert_rel(extra["stiffness"], truth.stiffness, tol, "K")
    assert_rel(extra["offset"], -truth.stiffness * truth.spring_reference, tol, "-K q_ref")
    model = result.identified_model()
    assert_rel(model.stiffness, truth.stiffness, tol, "model stiffness")
    assert_rel(model.spring_reference, truth.spring_reference, tol, "model spring_reference")
    assert_rel(rd.rnea(model, q, qd, qdd), log.tau, tol, "torques")
    # the nominal base parameters hold the nominal model's own springs: none here
    rows = [result.base.names.index(n) for n in names]
    assert_rel(result.beta_nominal[rows], np.zeros(3), 0.0)


def test_stiffness_without_offsets_and_floating_bases():
    """Without offset columns the identified springs rest at 0 (the estimate's ``K q``); the
    nominal parameters hold the model's own springs; a floating base's stiffness columns are
    zero and drop out of the base parameters."""
    truth = _sprung_elbow().replace(spring_reference=np.zeros(3))
    traj = ident.feasible_trajectory(truth, period=6.0, harmonics=3, samples=40, seed=4)
    t, q, qd, qdd = traj.sample(12.0, 50.0)
    result = ident.identify(truth, ident.Log(t, q, qd, qdd, rd.rnea(truth, q, qd, qdd)), stiffness=True)
    assert "offset" not in result.extra()
    model = result.identified_model()
    assert_rel(model.stiffness, truth.stiffness, 1e-8)
    assert_rel(model.spring_reference, np.zeros(3), 0.0)
    assert_rel(result.estimate.beta, result.beta_nominal, 1e-8)  # the nominal model is the truth
    sprung = _sprung_elbow()
    base = ident.base_parameters(sprung, stiffness=True, offset=True)
    prior = nominal_parameters(sprung, base)
    assert_rel(prior[-3:], -sprung.stiffness * sprung.spring_reference, 0.0)
    assert_rel(prior[-6:-3], sprung.stiffness, 0.0)
    floating = random_model(3, seed=5, floating_base=True)
    base = ident.base_parameters(floating, stiffness=True)
    free = [f"stiffness[{n}]" for n in floating.dof_names[:6]]
    joints = [f"stiffness[{n}]" for n in floating.dof_names[6:]]
    assert set(free) <= set(base.columns) and not any(n in base.names for n in free)
    assert set(joints) <= set(base.names)


def test_cli_identify_stiffness(tmp_path, capsys):
    """``robodyn identify --stiffness --offset`` identifies the springs (the URDF it writes
    cannot hold them: a warning says so)."""
    truth = _sprung_elbow()
    traj = ident.feasible_trajectory(truth, period=6.0, harmonics=3, samples=40, seed=3)
    t, q, qd, qdd = traj.sample(12.0, 50.0)
    data = ident.write_log(tmp_path / "data.csv", truth, t, q, v=qd, a=qdd, tau=rd.rnea(truth, q, qd, qdd))
    capsys.readouterr()
    assert main(["identify", "elbow_3r", str(data), "--stiffness", "--offset"]) == 0
    out = capsys.readouterr().out
    for k, name in enumerate(truth.dof_names):
        line = next(x for x in out.splitlines() if x.endswith(f"  stiffness[{name}]"))
        assert abs(float(line.split()[1]) - truth.stiffness[k]) < 1e-6 * truth.stiffness[k], line


def test_identify_errors():
    model = rd.models.load("planar_2r")
    log = ident.Log(np.arange(3.0), np.zeros((3, 2)), tau=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="method"):
        ident.identify(model, log, method="magic")
    with pytest.raises(ValueError, match="preprocess"):
        ident.identify(model, log)


# -- command line -----------------------------------------------------------------------------
def test_cli_excite_and_identify(tmp_path, capsys):
    """`robodyn excite` writes a CSV and a plot; torques computed along it feed `robodyn
    identify`, whose URDF loads with the default checks and reproduces the torques."""
    traj = tmp_path / "traj.csv"
    assert main(["excite", "elbow_3r", "--duration", "6", "--out", str(traj), "--harmonics", "2",
                 "--samples", "30", "--maxiter", "3", "--rate", "50"]) == 0
    assert traj.with_suffix(".png").read_bytes()[:4] == b"\x89PNG"
    model = rd.models.load("elbow_3r").replace(damping=np.full(3, 0.2), coulomb=np.full(3, 0.4))
    log = ident.read_log(traj, model, require_tau=False)
    data = ident.write_log(tmp_path / "data.csv", model, log.t, log.q, v=log.v, a=log.a,
                           tau=rd.rnea(model, log.q, log.v, log.a))
    urdf, report = tmp_path / "identified.urdf", tmp_path / "report"
    assert main(["identify", "elbow_3r", str(data), "--method", "physical", "--out", str(urdf),
                 "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "condition number of the base regressor" in out and f"wrote {urdf}" in out
    back = rd.load_urdf(urdf)
    assert_rel(rd.rnea(back, log.q, log.v, log.a), rd.rnea(model, log.q, log.v, log.a), 1e-6)
    assert (report / "report.txt").is_file() and (report / "torques.png").is_file()
    bad = ident.write_log(tmp_path / "bad.csv", model, log.t, log.q)
    assert main(["identify", "elbow_3r", str(bad)]) == 2
    assert "missing columns" in capsys.readouterr().err
