"""Energy drift of the fixed-step integrators over long runs (no forcing).

    python benchmarks/energy_drift.py [--steps 100000] [--dt 0.005]

The double pendulum from rest at (1.0, -0.5) rad: the largest |E - E0| over the run and over
its last tenth, and the wall time, for "symplectic" (Stormer-Verlet in momentum form),
"semi_implicit_euler" and "rk4". A symplectic method keeps the error bounded (last tenth no
larger than the whole run's typical oscillation); the others drift.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import robodyn as rd


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--dt", type=float, default=0.005)
    args = parser.parse_args()
    model = rd.models.load("double_pendulum")
    q0, v0 = np.array([1.0, -0.5]), np.zeros(2)
    duration = args.steps * args.dt
    print(f"double pendulum, {args.steps} steps of {args.dt} s ({duration:g} s)")
    print(f"  {'integrator':<22} {'max|E-E0| (J)':>14} {'last tenth':>12} {'first tenth':>12} {'time (s)':>9}")
    for integrator in ("symplectic", "semi_implicit_euler", "rk4"):
        start = time.perf_counter()
        run = rd.simulate(model, q0, v0, duration, args.dt, integrator=integrator)
        wall = time.perf_counter() - start
        error = np.abs(run.energy - run.energy[0])
        tenth = len(error) // 10
        print(f"  {integrator:<22} {error.max():14.3e} {error[-tenth:].max():12.3e} {error[:tenth].max():12.3e} "
              f"{wall:9.2f}")


if __name__ == "__main__":
    main()
