"""Identification from reduced statistics and from many logs (robodyn.identification.reduced,
.fleet): the per-joint triangular factors against the textbook least-squares formulas on the
stacked regressor (written here with NumPy), logs split and combined against the whole, a list
of logs (objects, CSV and Parquet files) against their samples concatenated, the same on a
two-process Dask cluster and from a Dask DataFrame, and errors that name the bad log.

The simulated robot is the SCARA with viscous and Coulomb friction, torques with a different
noise level per joint (so that WLS reweights), along random Fourier trajectories."""

from __future__ import annotations

import builtins
import functools
import re

import numpy as np
import pytest

import robodyn as rd
from robodyn import identification as ident
from robodyn.identification.estimation import ols, physical, wls
from robodyn.identification.identify import METHODS, nominal_parameters
from robodyn.identification.reduced import Reduced, stack
from helpers import rng_for

RATE = 100.0
NOISE = np.array([0.02, 0.05, 0.1, 0.2])  # torque noise per joint (N m, N)


@functools.lru_cache(maxsize=None)
def robot():
    """``(nominal model, truth with friction, base parameters with friction columns)``."""
    model = rd.models.load("scara")
    truth = model.replace(damping=np.linspace(0.2, 0.5, model.nv), coulomb=np.linspace(0.3, 0.6, model.nv))
    return model, truth, ident.base_parameters(model, damping=True, coulomb=True)


@functools.lru_cache(maxsize=None)
def simulated(seed: int, duration: float) -> ident.Log:
    """Exact ``q, v, a`` of a random trajectory within the limits, ``tau`` of the truth plus noise."""
    _, truth, _ = robot()
    traj = ident.feasible_trajectory(truth, period=4.0, harmonics=3, samples=40, seed=seed)
    t, q, v, a = traj.sample(duration, RATE)
    tau = rd.rnea(truth, q, v, a) + NOISE * rng_for("fleet", seed).standard_normal((t.size, truth.nv))
    return ident.Log(t, q, v, a, tau)


def concatenated(logs) -> ident.Log:
    """One log of the samples of all ``logs`` (time is not used by the estimators)."""
    return ident.Log(*(np.concatenate([getattr(log, k) for log in logs]) for k in ("t", "q", "v", "a", "tau")))


def assert_close(actual, expected, tol: float = 1e-10, what: str = "") -> None:
    """``max |actual - expected| <= tol max |expected|``: relative to the largest entry."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    err = np.max(np.abs(actual - expected)) / np.max(np.abs(expected))
    assert err <= tol, f"{what}: relative error {err:.3g} > {tol:g}\nactual={actual}\nexpected={expected}"


def assert_same_estimate(a, b, tol: float = 1e-10, what: str = "") -> None:
    for field in ("beta", "std", "sigma"):
        assert_close(getattr(a, field), getattr(b, field), tol, f"{what} {field}")


# -- textbook least squares on the stacked regressor ---------------------------------------
def textbook_ols(W, y, nv):
    """``beta = W^+ y``, ``s^2 = |y - W beta|^2 / (n - r)``, ``std = sqrt(diag((W^T W)^+) s^2)``,
    ``sigma_j = sqrt(|y_j - W_j beta|^2 / (N - r / nv))`` (rows sample by sample)."""
    n, r = W.shape
    beta = np.linalg.lstsq(W, y, rcond=None)[0]
    res = y - W @ beta
    s2 = res @ res / (n - r)
    std = np.sqrt(np.diag(np.linalg.pinv(W.T @ W)) * s2)
    sigma = np.sqrt((res.reshape(-1, nv) ** 2).sum(axis=0) / (n // nv - r / nv))
    return beta, std, sigma


def textbook_wls(W, y, nv, iterations=10):
    """Gautier's WLS (Khalil and Dombre 2002, 12.5): rows of joint j weighted by 1 / sigma_j,
    ``std = sqrt(diag((W^T S^-1 W)^+))``, the sigma_j re-estimated from the weighted fit's
    residuals until they change by less than 1 % (floor: 1e-12 of the largest RMS torque)."""
    n, r = W.shape
    sigma = textbook_ols(W, y, nv)[2]
    floor = 1e-12 * np.sqrt((y.reshape(-1, nv) ** 2).mean(axis=0)).max()
    for _ in range(iterations):
        s = np.maximum(sigma, floor)
        w = np.tile(1.0 / s, n // nv)
        beta = np.linalg.lstsq(W * w[:, None], y * w, rcond=None)[0]
        std = np.sqrt(np.diag(np.linalg.pinv(W.T @ (W * w[:, None] ** 2))))
        res = y - W @ beta
        sigma = np.sqrt((res.reshape(-1, nv) ** 2).sum(axis=0) / (n // nv - r / nv))
        if np.all(np.abs(sigma - s) <= 0.01 * s):
            break
    return beta, std, sigma


def test_reduced_statistics_give_the_textbook_estimates():
    """One log reduced in blocks of 37 samples: OLS and WLS equal the formulas on ``W`` and
    ``y`` to 1e-10; the factor's singular values are those of ``W``; a stacked ``W`` given to
    ols/wls directly is reduced the same way."""
    model, _, base = robot()
    log = simulated(1, 4.0)
    W, y = stack(model, base, log)
    stats = Reduced.from_log(model, base, log, block=37)
    assert (stats.samples, stats.nv, stats.count, stats.rows) == (len(log), model.nv, base.count, W.shape[0])
    for estimator, textbook in ((ols, textbook_ols), (wls, textbook_wls)):
        expected = textbook(W, y, model.nv)
        for est in (estimator(stats), estimator(W, y, model.nv)):
            for got, want, field in zip((est.beta, est.std, est.sigma), expected, ("beta", "std", "sigma")):
                assert_close(got, want, 1e-10, f"{estimator.__name__} {field}")
    # WLS really reweights: the noise levels differ by a factor 10 and sigma follows them
    assert_close(wls(stats).sigma, NOISE, 0.15, "wls sigma against the noise levels")
    r = base.count
    assert_close(np.linalg.svd(stats.stacked()[:r, :r], compute_uv=False), np.linalg.svd(W, compute_uv=False), 1e-12)
    assert_close(stats.residuals(np.zeros(r)), (y.reshape(-1, model.nv) ** 2).sum(axis=0), 1e-12)


def test_split_logs_combine_to_the_whole():
    """A log split in 3 parts reduced with uneven blocks (13, 1 and 4096 samples) and combined,
    in two orders: the same information ``R_j^T R_j = [W_j y_j]^T [W_j y_j]`` per joint (a
    joint's own rows are rank deficient, so its factor is not unique), the same factor of all
    rows stacked (of full rank: unique with its nonnegative diagonal), and the same OLS, WLS
    and physically consistent estimates as the whole log, to 1e-10."""
    model, _, base = robot()
    log = simulated(2, 4.0)
    whole = Reduced.from_log(model, base, log)
    parts = [Reduced.from_log(model, base, log.rows(slice(0, 97)), block=13),
             Reduced.from_log(model, base, log.rows(slice(97, 260)), block=1),
             Reduced.from_log(model, base, log.rows(slice(260, None)), block=4096)]
    for combined in (parts[0] + parts[1] + parts[2], parts[2].combine(parts[1].combine(parts[0]))):
        assert combined.samples == len(log)
        gram = lambda x: x.R.transpose(0, 2, 1) @ x.R  # noqa: E731
        assert_close(gram(combined), gram(whole), 1e-12, "R_j^T R_j")
        assert_close(combined.stacked(), whole.stacked(), 1e-12, "stacked factor")
        assert_same_estimate(ols(combined), ols(whole), what="ols")
        assert_same_estimate(wls(combined), wls(whole), what="wls")
    prior = nominal_parameters(model, base)
    a, b = physical(model, base, combined, prior), physical(model, base, whole, prior)
    assert_same_estimate(a, b, what="physical")
    assert_close(a.theta, b.theta, 1e-10, "physical theta")
    # identify takes reduced statistics as they are
    result = ident.identify(model, combined, method="wls", base=base)
    assert result.samples == len(log)
    assert_same_estimate(result.estimate, wls(whole), what="identify of Reduced")
    with pytest.raises(ValueError, match=r"reduced statistics of \(nv, r\) = \(4, 15\); the model and its base "
                                         r"parameters have \(4, 16\)"):
        ident.identify(model, Reduced.empty(4, 15), base=base)
    # the empty statistics are neutral; statistics of other sizes do not combine
    assert_close((whole + Reduced.empty(model.nv, base.count)).stacked(), whole.stacked(), 1e-15)
    with pytest.raises(ValueError, match=r"different sizes \(nv, r\) = \(4, 16\) and \(4, 15\)"):
        whole + Reduced.empty(4, 15)
    with pytest.raises(ValueError, match="block: expected a positive integer, got 0"):
        Reduced.from_log(model, base, log, block=0)
    with pytest.raises(TypeError, match="expected Reduced statistics"):
        physical(model, base, stack(model, base, log)[0], prior)


@pytest.mark.parametrize("method", METHODS)
def test_identify_many_logs_equals_their_samples_concatenated(method, tmp_path):
    """Four logs of different lengths, two as objects and two as files (CSV, Parquet): the same
    estimate, condition number and sample count as one log of all their samples."""
    model, _, base = robot()
    logs = [simulated(seed, duration) for seed, duration in ((3, 3.0), (4, 4.0), (5, 5.0), (6, 2.5))]
    files = [ident.write_log(tmp_path / name, model, log.t, log.q, v=log.v, a=log.a, tau=log.tau)
             for name, log in (("b.csv", logs[1]), ("d.parquet", logs[3]))]
    many = ident.identify(model, [logs[0], files[0], logs[2], str(files[1])], method=method, base=base)
    one = ident.identify(model, concatenated(logs), method=method, base=base)
    assert many.samples == one.samples == sum(len(log) for log in logs)
    assert_same_estimate(many.estimate, one.estimate, what=method)
    assert_close(many.condition_number, one.condition_number, 1e-10)
    assert_close(many.singular_values, one.singular_values, 1e-10)


def test_identify_preprocesses_every_log(tmp_path):
    """Logs of positions and torques only (files and an object), ``preprocess={"cutoff": 10}``:
    each filtered and differentiated on its own (``data.preprocess``), then combined; a single
    log the same; without ``preprocess`` such a log is refused."""
    model, _, base = robot()
    raw = [ident.Log(log.t, log.q, tau=log.tau) for log in (simulated(7, 3.0), simulated(8, 4.0), simulated(9, 3.5))]
    paths = [ident.write_log(tmp_path / f"{k}.csv", model, log.t, log.q, tau=log.tau) for k, log in enumerate(raw[:2])]
    expected = concatenated([ident.preprocess(log, cutoff=10.0) for log in raw])
    many = ident.identify(model, [*paths, raw[2]], method="wls", base=base, preprocess={"cutoff": 10.0})
    assert_same_estimate(many.estimate, ident.identify(model, expected, method="wls", base=base).estimate)
    single = ident.identify(model, raw[0], base=base, preprocess={"cutoff": 10.0, "decimate": 2})
    reference = ident.identify(model, ident.preprocess(raw[0], cutoff=10.0, decimate=2), base=base)
    assert_same_estimate(single.estimate, reference.estimate)
    assert single.samples == len(ident.preprocess(raw[0], cutoff=10.0, decimate=2))
    with pytest.raises(ValueError, match=r"logs\[1\]: the log has no velocities and accelerations: preprocess it"):
        ident.identify(model, [simulated(7, 3.0), raw[1]], base=base)
    with pytest.raises(TypeError, match="preprocess: got an unexpected keyword argument 'cutof'"):
        ident.identify(model, raw, base=base, preprocess={"cutof": 10.0})


def test_a_bad_log_is_named(tmp_path):
    """A missing file, a log without torques, a file with a hole: the error names the log (its
    index and path) and says what is wrong."""
    model, _, base = robot()
    good = simulated(3, 3.0)
    missing = tmp_path / "missing.csv"
    with pytest.raises(ValueError, match=re.escape(f"logs[1] ({missing}): FileNotFoundError")):
        ident.identify(model, [good, missing], base=base)
    no_tau = ident.write_log(tmp_path / "no_tau.csv", model, good.t, good.q, v=good.v, a=good.a)
    with pytest.raises(ValueError, match=re.escape(f"logs[2] ({no_tau}): {no_tau}: missing columns")):
        ident.identify(model, [good, good, no_tau], base=base)
    with pytest.raises(ValueError, match=r"logs\[1\]: the log has no torques"):
        ident.identify(model, [good, ident.Log(good.t, good.q, good.v, good.a)], base=base)
    with pytest.raises(ValueError, match="logs: the list is empty"):
        ident.identify(model, [], base=base)
    with pytest.raises(TypeError, match="logs: expected a Log, a path, a list or tuple"):
        ident.identify(model, {"a": good}, base=base)


def test_local_identification_does_not_import_dask(monkeypatch, tmp_path):
    """Without a client, many logs are identified with Dask unimportable."""
    model, _, base = robot()
    real = builtins.__import__

    def no_dask(name, *args, **kw):
        if name.split(".")[0] in ("dask", "distributed"):
            raise ImportError(f"{name} imported by the local path")
        return real(name, *args, **kw)

    log = simulated(3, 3.0)
    path = ident.write_log(tmp_path / "a.csv", model, log.t, log.q, v=log.v, a=log.a, tau=log.tau)
    monkeypatch.setattr(builtins, "__import__", no_dask)
    result = ident.identify(model, [log, path], base=base)
    assert result.samples == 2 * len(log)


def test_dask_dataframe_partitions_are_logs(tmp_path):
    """A Dask DataFrame of three CSV files (one partition each), on Dask's default scheduler:
    the estimate of the three logs; a hole in the second file is reported with its partition
    and its line in that file."""
    import dask.dataframe as dd

    model, _, base = robot()
    logs = [simulated(seed, 3.0) for seed in (3, 4, 5)]
    paths = [ident.write_log(tmp_path / f"{k}.csv", model, log.t, log.q, v=log.v, a=log.a, tau=log.tau)
             for k, log in enumerate(logs)]
    frame = dd.read_csv([str(p) for p in paths], blocksize=None)
    assert frame.npartitions == 3
    result = ident.identify(model, frame, method="wls", base=base)
    assert_same_estimate(result.estimate, ident.identify(model, logs, method="wls", base=base).estimate)
    lines = paths[1].read_text().splitlines()
    lines[4] = ",".join(lines[4].split(",")[:-1] + [""])  # line 5 of the file: its last torque missing
    paths[1].write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"partition 1: .*1 rows with missing or non-finite values at lines \[5\]"):
        ident.identify(model, dd.read_csv([str(p) for p in paths], blocksize=None), base=base)


# -- on a Dask cluster of two worker processes -----------------------------------------------
@pytest.fixture(scope="module")
def client():
    """A LocalCluster of 2 single-threaded worker processes and its Client, started once for
    the module. The kernels are compiled here first (cached on disk, where the workers load
    them from) by a local identification."""
    from distributed import Client, LocalCluster

    model, _, base = robot()
    ident.identify(model, [simulated(3, 3.0)], base=base)
    cluster = LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None)
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()


@pytest.fixture(scope="module")
def fleet_files(tmp_path_factory):
    """Five CSV logs of different motions and lengths."""
    model, _, _ = robot()
    folder = tmp_path_factory.mktemp("fleet")
    return [ident.write_log(folder / f"robot{k}.csv", model, log.t, log.q, v=log.v, a=log.a, tau=log.tau)
            for k, log in enumerate(simulated(seed, 2.0 + 0.5 * seed) for seed in range(10, 15))]


@pytest.mark.parametrize("method", ["wls", "physical"])
def test_cluster_identification_equals_the_local_one(client, fleet_files, method):
    """Paths reduced on the workers and combined in a tree there: the local loop's estimate to
    1e-10; a Dask DataFrame of the same files (one partition each), computed on the cluster,
    too; a missing file among them is named in the error raised here."""
    import dask.dataframe as dd
    from distributed import get_task_stream

    model, _, base = robot()
    local = ident.identify(model, fleet_files, method=method, base=base)
    with get_task_stream(client) as stream:
        remote = ident.identify(model, fleet_files, method=method, base=base, client=client)
    names = [str(task["key"]).split("-")[0] for task in stream.data]
    assert (names.count("_reduce_labelled"), names.count("combine")) == (5, 4)  # a log per task, a binary tree
    assert remote.samples == local.samples
    assert_same_estimate(remote.estimate, local.estimate, what=f"{method} on the cluster")
    frame = dd.read_csv([str(p) for p in fleet_files], blocksize=None)
    from_frame = ident.identify(model, frame, method=method, base=base, client=client)
    assert from_frame.samples == local.samples
    assert_same_estimate(from_frame.estimate, local.estimate, what=f"{method} from a Dask DataFrame")
    missing = fleet_files[0].parent / "missing.csv"
    with pytest.raises(ValueError, match=re.escape(f"logs[2] ({missing}): FileNotFoundError")):
        ident.identify(model, [*fleet_files[:2], missing, *fleet_files[2:]], base=base, client=client)
