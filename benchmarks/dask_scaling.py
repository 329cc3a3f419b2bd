"""Throughput of ``rd.rnea`` on Panda states streamed through a Dask ``LocalCluster``
against the in-memory batch on one machine, and its scaling with the number of workers.

    python benchmarks/dask_scaling.py                       # 10^8 states, chunks of 10^7
    python benchmarks/dask_scaling.py --states 2e7 --chunk 5e6 --workers 1 2

Both sides run the same pipeline per chunk of states: draw ``q, v, a`` (NumPy's PCG64),
``tau = rd.rnea(...)``, and reduce ``tau`` to its sum (so that nothing is gathered): in memory,
chunk after chunk in this process (Numba's threads on every core); on the cluster, as Dask
tasks of ``da.random`` and ``rd.rnea`` on Dask arrays, each worker a process with one thread
and one Numba thread (one core). Reported: states per second, the overhead of Dask
(``1 - cluster rate / in-memory rate`` with as many workers as cores), and for each worker
count the speed-up over one worker and the serial fraction of Amdahl's law
``s = (n / S - 1) / (n - 1)`` it implies, with the projected speed-up ``1 / (s + (1 - s) / n)``
for more workers.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def in_memory(model, states: int, chunk: int) -> float:
    import robodyn as rd

    rng = np.random.default_rng(0)
    total, t0 = 0.0, time.perf_counter()
    for start in range(0, states, chunk):
        n = min(chunk, states - start)
        q, v, a = rng.standard_normal((3, n, model.nv))
        total += float(rd.rnea(model, q, v, a).sum())
    return states / (time.perf_counter() - t0)


def on_cluster(model, states: int, chunk: int, workers: int) -> float:
    import dask.array as da
    from distributed import Client, LocalCluster

    import robodyn as rd

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=40, env={"NUMBA_NUM_THREADS": "1"}) as cluster, Client(cluster) as client:
        client.register_plugin(rd.distributed.Warmup(only=["rnea"]))
        rng = da.random.default_rng(0)
        q, v, a = (rng.standard_normal((states, model.nv), chunks=(chunk, -1)) for _ in range(3))
        t0 = time.perf_counter()
        client.compute(rd.rnea(model, q, v, a).sum()).result()
        return states / (time.perf_counter() - t0)


def main() -> None:
    import robodyn as rd

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--states", type=float, default=1e8)
    p.add_argument("--chunk", type=float, default=1e7)
    p.add_argument("--memory-states", type=float, default=1e7, help="states of the in-memory reference")
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = p.parse_args()
    states, chunk = int(args.states), int(args.chunk)
    model = rd.models.load("panda")
    rd.warmup(only=["rnea"])
    ref = in_memory(model, int(args.memory_states), chunk)
    print(f"in memory: {ref:.3e} states/s ({int(args.memory_states):.0e} states, chunks of {chunk:.0e})")
    rates = {}
    for n in args.workers:
        rates[n] = on_cluster(model, states, chunk, n)
        print(f"LocalCluster, {n} worker(s): {rates[n]:.3e} states/s ({states:.0e} states), "
              f"{rates[n] / ref:.2f} x in memory")
    cores = os.cpu_count() or 1
    if cores in rates:
        print(f"Dask overhead ({cores} workers, one per core, against in memory on {cores} cores): "
              f"{1 - rates[cores] / ref:+.1%}")
    one = rates.get(1)
    if one is not None:
        for n, r in rates.items():
            if n > 1:
                S = r / one
                s = min(max((n / S - 1) / (n - 1), 0.0), 1.0)
                proj = ", ".join(f"{m}: {1 / (s + (1 - s) / m):.2f}" for m in (4, 8, 16, 64))
                print(f"{n} workers: speed-up {S:.2f}, serial fraction {s:.3f}; projected speed-up {proj}")


if __name__ == "__main__":
    main()
