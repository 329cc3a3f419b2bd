"""Closed-form models: derivation time and the speed of the generated mass matrix.

    python benchmarks/symbolic.py [--robots puma560,panda] [--write]

For each robot (numeric parameters): the time to derive M, C, g (``equations_of_motion``,
Lagrange and Newton-Euler routes) and to turn them into sympy expressions (``eom.M``,
``eom.C``, ``eom.g``); the time to generate and compile the Numba function of M; then the
single-call time of that function and of ``rd.crba`` on the same state (best of 5 repeats).
``--write`` appends the table to ``benchmarks/RESULTS.md``.
"""

from __future__ import annotations

import argparse
import platform
import time
import timeit
from pathlib import Path

import numpy as np
import sympy

import robodyn as rd
from robodyn import symbolic as S


def best_us(f, number=20000, repeat=5) -> float:
    return min(timeit.repeat(f, number=number, repeat=repeat)) / number * 1e6


def measure(name: str) -> list[str]:
    model = rd.models.load(name)
    rows = []
    for method in ("lagrange", "newton_euler"):
        t0 = time.perf_counter()
        eom = S.equations_of_motion(model, method)
        t1 = time.perf_counter()
        M, C, g = eom.M, eom.C, eom.g
        t2 = time.perf_counter()
        sizes = [sum(len(x) for row in eom._poly[k] for x in (row if isinstance(row, list) else [row])) for k in "MCg"]
        rows.append(f"| {name} | {method} | {t1 - t0:.2f} | {t2 - t0:.2f} | {sizes[0]} / {sizes[1]} / {sizes[2]} |")
        print(rows[-1], flush=True)
    t0 = time.perf_counter()
    fM = eom.to_numba("M")
    q = np.random.default_rng(0).uniform(-2, 2, model.nq)
    err = np.abs(fM(q) - rd.crba(model, q)).max()
    t1 = time.perf_counter()
    rd.crba(model, q)
    ours, crba = best_us(lambda: fM(q)), best_us(lambda: rd.crba(model, q))
    speed = (f"| {name} | {t1 - t0:.1f} | {ours:.2f} | {crba:.2f} | {ours / crba:.2f} | {err:.1e} |")
    print(speed, flush=True)
    return rows, speed


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robots", default="puma560,panda")
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    derive, speed = [], []
    for name in args.robots.split(","):
        r, s = measure(name)
        derive += r
        speed.append(s)
    text = "\n".join([
        "",
        f"## Closed-form models (robodyn.symbolic), {time.strftime('%Y-%m-%d')}, {platform.machine()}, "
        f"Python {platform.python_version()}, sympy {sympy.__version__}",
        "",
        f"Command: `python benchmarks/symbolic.py --robots {args.robots} --write` (numeric parameters; one process, "
        "so the first derivation also pays for importing sympy)",
        "",
        "| robot | method | derive (s) | derive + M, C, g as sympy expressions (s) | monomials in M / C / g |",
        "|---|---|---|---|---|",
        *derive,
        "",
        "Generated mass matrix (`eom.to_numba(\"M\")`, single call from Python with input checks) against `rd.crba`:",
        "",
        "| robot | generate + compile (s) | generated M (us) | rd.crba (us) | ratio | max abs difference |",
        "|---|---|---|---|---|---|",
        *speed,
        "",
    ])
    print(text)
    if args.write:
        with open(Path(__file__).parent / "RESULTS.md", "a") as f:
            f.write(text)


if __name__ == "__main__":
    main()
