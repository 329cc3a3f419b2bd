"""Fleet identification on a Dask ``LocalCluster``: time, and peak memory per worker against
the memory of one log's regressor.

    python benchmarks/dask_fleet.py                      # 100 logs of 10^5 samples, Panda
    python benchmarks/dask_fleet.py --logs 20 --samples 20000

The logs are simulated measurements: a random Fourier excitation per robot of the fleet
(``identification.feasible_trajectory``, seed = log number), sampled at 1 kHz, the torques
``rd.rnea`` of the nominal model with friction plus 1 % Gaussian noise, written as Parquet
files in robodyn's log format. ``identify(model, paths, client=client)`` then reduces each log
on a worker and combines the factors; the same call without ``client`` (a loop here) is the
single-machine reference. Reported: wall time of both, the largest relative difference of the
estimates, and the growth of each worker's peak resident memory during the job
(``tracemalloc``'s peak, NumPy's buffers included, and ``ru_maxrss`` before and after), next to the size of one log's regressor ``N nv x r``
doubles, which a worker must never need.
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from pathlib import Path

import numpy as np


def peak_rss_mb() -> float:
    """This process's peak resident memory (MB; Linux reports ru_maxrss in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def start_tracing() -> None:
    import tracemalloc

    tracemalloc.start()


def peak_traced_mb() -> float:
    """The peak of the memory allocated since :func:`start_tracing` (Python objects and NumPy
    arrays, which report their buffers to ``tracemalloc``), MB."""
    import tracemalloc

    return tracemalloc.get_traced_memory()[1] / 1e6


def write_logs(model, directory: Path, logs: int, samples: int) -> list[Path]:
    import robodyn as rd
    from robodyn.identification import feasible_trajectory
    from robodyn.io.log import write_log

    paths = []
    for k in range(logs):
        traj = feasible_trajectory(model, seed=k)
        t, q, v, a = traj.sample(samples / 1000.0, 1000.0)
        tau = rd.rnea(model, q, v, a)
        tau = tau + 0.01 * np.abs(tau).max(axis=0) * np.random.default_rng(k).standard_normal(tau.shape)
        paths.append(write_log(directory / f"log-{k:03d}.parquet", model, t, q, v=v, a=a, tau=tau))
    return paths


def main() -> None:
    from distributed import Client, LocalCluster

    import robodyn as rd
    from robodyn.identification import base_parameters, identify

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--logs", type=int, default=100)
    p.add_argument("--samples", type=int, default=100_000)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--method", default="wls")
    args = p.parse_args()
    base_model = rd.models.load("panda")
    model = base_model.replace(damping=np.full(7, 0.5), coulomb=np.full(7, 1.0))
    base = base_parameters(model, damping=True, coulomb=True)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        paths = write_logs(model, Path(tmp), args.logs, args.samples)
        print(f"{args.logs} logs of {args.samples} samples written in {time.perf_counter() - t0:.1f} s "
              f"({sum(p.stat().st_size for p in paths) / 1e6:.0f} MB of Parquet)")
        t0 = time.perf_counter()
        here = identify(model, paths, method=args.method, base=base)
        t_here = time.perf_counter() - t0
        print(f"one machine, a loop: {t_here:.1f} s")
        with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                          silence_logs=40) as cluster, Client(cluster) as client:
            client.register_plugin(rd.distributed.Warmup(only=["regressor"]))
            before = client.run(peak_rss_mb)
            client.run(start_tracing)
            t0 = time.perf_counter()
            there = identify(model, [str(p) for p in paths], method=args.method, base=base, client=client)
            t_there = time.perf_counter() - t0
            after = client.run(peak_rss_mb)
            traced = client.run(peak_traced_mb)
        diff = np.abs(there.estimate.beta - here.estimate.beta).max() / np.abs(here.estimate.beta).max()
        regressor_mb = args.samples * model.nv * base.count * 8 / 1e6
        print(f"LocalCluster, {args.workers} workers: {t_there:.1f} s ({t_here / t_there:.2f} x the loop); "
              f"largest relative difference of beta {diff:.1e}")
        for w in sorted(before):
            print(f"  worker {w}: peak allocated during the job {traced[w]:.0f} MB, peak resident "
                  f"{before[w]:.0f} -> {after[w]:.0f} MB; one log's regressor: {regressor_mb:.0f} MB")


if __name__ == "__main__":
    main()
