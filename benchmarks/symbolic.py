"""Closed-form models: derivation time and the speed of the generated mass matrix.

    python benchmarks/symbolic.py [--robots puma560,panda] [--write]

For each robot (numeric parameters): the time to derive M, C, g (``equations_of_motion``,
Lagrange and Newton-Euler routes) and to turn them into sympy expressions (``eom.M``,
``eom.C``, ``eom.g``). Then the generated Numba mass matrix in its two forms: the
straight-line code of the composite-rigid-body recursion (``recursive_dynamics(model)
.to_numba("M")``, the default of ``eom.to_numba("M")``) and the expanded closed form
(``eom.to_numba("M", form="expanded")``): the time to generate and compile each, and their
single-call times from Python against ``rd.crba`` on the same state, in the same process. The
machine is shared: the three calls are timed in turns, ``ROUNDS`` rounds of ``timeit`` and the
best of each kept. ``--write`` puts the tables into the closed-form section of
``benchmarks/RESULTS.md`` (replacing an earlier one).
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

ROUNDS, NUMBER = 9, 20000
SECTION = "## Closed-form models (robodyn.symbolic)"


def best_of_rounds(calls: dict) -> dict:
    """Microseconds per call of each ``calls[name]``: best of ``ROUNDS`` rounds, the calls
    taking turns within a round."""
    best = {k: np.inf for k in calls}
    for _ in range(ROUNDS):
        for k, f in calls.items():
            best[k] = min(best[k], timeit.timeit(f, number=NUMBER) / NUMBER * 1e6)
    return best


def compiled(make, q):
    """``make()`` and its first call on ``q`` (the compilation), and the seconds they took."""
    t0 = time.perf_counter()
    f = make()
    f(q)
    return f, time.perf_counter() - t0


def measure(name: str) -> tuple[list[str], str]:
    model = rd.models.load(name)
    rows = []
    for method in ("lagrange", "newton_euler"):
        t0 = time.perf_counter()
        eom = S.equations_of_motion(model, method)
        t1 = time.perf_counter()
        eom.M, eom.C, eom.g  # the sympy expressions, computed on first access
        t2 = time.perf_counter()
        sizes = [sum(len(x) for row in eom._poly[k] for x in (row if isinstance(row, list) else [row])) for k in "MCg"]
        rows.append(f"| {name} | {method} | {t1 - t0:.2f} | {t2 - t0:.2f} | {sizes[0]} / {sizes[1]} / {sizes[2]} |")
        print(rows[-1], flush=True)
    q = np.random.default_rng(0).uniform(-2, 2, model.nq)
    rec = S.recursive_dynamics(model)
    fast, t_fast = compiled(lambda: rec.to_numba("M"), q)
    full, t_full = compiled(lambda: eom.to_numba("M", form="expanded"), q)
    expected = rd.crba(model, q)
    err = max(np.abs(fast(q) - expected).max(), np.abs(full(q) - expected).max()) / np.abs(expected).max()
    us = best_of_rounds({"recursive": lambda: fast(q), "expanded": lambda: full(q), "crba": lambda: rd.crba(model, q)})
    ops = len(rec.program("M").assignments)
    speed = (f"| {name} | {t_fast:.1f} / {t_full:.1f} | {ops} | {us['recursive']:.2f} | {us['expanded']:.2f} | "
             f"{us['crba']:.2f} | {us['recursive'] / us['crba']:.2f} | {us['expanded'] / us['crba']:.2f} | {err:.1e} |")
    print(speed, flush=True)
    return rows, speed


def write(text: str) -> None:
    """Replace the closed-form section of RESULTS.md by ``text`` (or append it)."""
    path = Path(__file__).parent / "RESULTS.md"
    old = path.read_text()
    start = old.find(SECTION)
    if start < 0:
        path.write_text(old.rstrip("\n") + "\n" + text)
        return
    end = old.find("\n## ", start + 1)
    rest = "\n" + old[end + 1:] if end >= 0 else ""
    path.write_text(old[:start] + text.strip("\n") + "\n" + rest)


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
        f"{SECTION}, {time.strftime('%Y-%m-%d')}, {platform.machine()}, "
        f"Python {platform.python_version()}, sympy {sympy.__version__}",
        "",
        f"Command: `python benchmarks/symbolic.py --robots {args.robots} --write` (numeric parameters; one process, "
        "so the first derivation also pays for importing sympy)",
        "",
        "| robot | method | derive (s) | derive + M, C, g as sympy expressions (s) | monomials in M / C / g |",
        "|---|---|---|---|---|",
        *derive,
        "",
        "Generated mass matrix (Numba, single call from Python with input checks) against `rd.crba` on the same "
        "state: recursive = straight-line code of the composite-rigid-body recursion "
        "(`rd.symbolic.recursive_dynamics(model).to_numba(\"M\")`, also the default of `eom.to_numba(\"M\")`), "
        "expanded = the expanded closed form (`eom.to_numba(\"M\", form=\"expanded\")`). Times: best of "
        f"{ROUNDS} rounds of {NUMBER} calls, the three calls taking turns; ratio = generated / rd.crba.",
        "",
        "| robot | generate + compile (s), recursive / expanded | assignments in recursive M | recursive M (us) "
        "| expanded M (us) | rd.crba (us) | ratio recursive | ratio expanded | max relative difference |",
        "|---|---|---|---|---|---|---|---|---|",
        *speed,
        "",
    ])
    print(text)
    if args.write:
        write(text)


if __name__ == "__main__":
    main()
