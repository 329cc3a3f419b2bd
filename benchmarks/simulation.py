"""Simulation speed: seconds of wall time per run, after compilation.

    python benchmarks/simulation.py

Target: 10 s of Panda at 1 kHz with RK4 (40,000 forward-dynamics calls) in under 1 s. The
uncontrolled robot and the built-in PDGravity and ComputedTorque run entirely in compiled
code; other controllers (and the built-in ones wrapped in a lambda, shown for comparison)
are called at every RK4 stage from a Python loop. Each figure is the best of ``--repeat``
runs (energies and Lyapunov function included). Gains: natural frequency 10 rad/s,
critically damped, PD gains scaled by the diagonal of the mass matrix.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import robodyn as rd
from robodyn import control
from robodyn.random import random_model, random_state

PANDA_Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7])


def best(fn, repeat: int) -> float:
    fn()  # compilation / caches
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    panda = rd.models.load("panda")
    v0 = np.zeros(7)
    target = PANDA_Q0 + 0.3
    fb = random_model(12, seed=1, floating_base=True, branching=0.5)
    q_fb, v_fb, _ = random_state(fb, np.random.default_rng(0))
    ref = control.quintic(PANDA_Q0, target, 0.5)
    m = np.diag(rd.crba(panda, PANDA_Q0))
    pd = control.PDGravity(panda, target, 100.0 * m, 20.0 * m)
    ct = control.ComputedTorque(panda, ref, 100.0, 20.0)
    sl = control.SlotineLi(panda, ref, 10.0, 20.0 * m)
    cases = [
        ("panda, no controller, rk4", 10.0, lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3)),
        ("panda, no controller, semi_implicit_euler", 10.0,
         lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, integrator="semi_implicit_euler")),
        ("floating tree (12 bodies, nv = 17), no controller, rk4", 10.0, lambda d: rd.simulate(fb, q_fb, v_fb, d, 1e-3)),
        ("panda, PDGravity (compiled), rk4", 10.0, lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, pd)),
        ("panda, ComputedTorque (compiled), rk4", 10.0, lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, ct)),
        ("panda, PDGravity (Python loop), rk4", 1.0,
         lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, lambda t, q, v: pd(t, q, v))),
        ("panda, ComputedTorque (Python loop), rk4", 1.0,
         lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, lambda t, q, v: ct(t, q, v))),
        ("panda, SlotineLi (Python loop), rk4", 1.0, lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, sl)),
        ("panda, no controller, DOP853 (rtol 1e-8)", 1.0,
         lambda d: rd.simulate(panda, PANDA_Q0, v0, d, 1e-3, integrator="DOP853")),
    ]
    print(f"{'run (1 kHz samples)':<58} {'simulated s':>11} {'wall s':>8} {'us/step':>8}")
    for name, duration, fn in cases:
        wall = best(lambda: fn(duration), args.repeat)
        print(f"{name:<58} {duration:>11.1f} {wall:>8.3f} {wall / (duration * 1000) * 1e6:>8.1f}")


if __name__ == "__main__":
    main()
