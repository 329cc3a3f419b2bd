"""Time per state against the number of bodies, for random chains and branching trees.

    python benchmarks/scaling.py [--out benchmarks/scaling.png]

Runs each algorithm on a batch of states with one thread (so the per-state time is the
algorithm's cost, without Python call overhead), for random models of 5 to 200 bodies, and
fits the exponent of ``time ~ n^p``: RNEA and ABA should be linear (p ~ 1), CRBA and the
Coriolis matrix at most quadratic (p <= 2; O(n d) with d the depth). Writes a log-log plot.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numba
import numpy as np

import robodyn as rd
from robodyn.bench import per_call_us
from robodyn.random import random_model, random_state

SIZES = (5, 10, 20, 50, 100, 200)
ALGORITHMS = {
    "rnea": lambda m, Q, V, A: rd.rnea(m, Q, V, A),
    "aba": lambda m, Q, V, A: rd.aba(m, Q, V, A),
    "crba": lambda m, Q, V, A: rd.crba(m, Q),
    "coriolis_matrix": lambda m, Q, V, A: rd.coriolis_matrix(m, Q, V),
}


def measure(branching: float, batch: int) -> dict[str, list[float]]:
    times = {name: [] for name in ALGORITHMS}
    for n in SIZES:
        model = random_model(n, seed=n, branching=branching)
        Q, V, A = random_state(model, np.random.default_rng(0), batch)
        for name, fn in ALGORITHMS.items():
            times[name].append(per_call_us(lambda: fn(model, Q, V, A), min_time=0.3, repeat=3) / batch)
    return times


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default=str(Path(__file__).with_name("scaling.png")))
    p.add_argument("--batch", type=int, default=200)
    args = p.parse_args()
    numba.set_num_threads(1)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    lines = ["| model | " + " | ".join(f"{a} exponent" for a in ALGORITHMS) + " |",
             "|---|" + "---|" * len(ALGORITHMS)]
    for ax, (label, branching) in zip(axes, (("chains", 0.0), ("trees (branching 0.3)", 0.3))):
        times = measure(branching, args.batch)
        exps = []
        for name, t in times.items():
            slope = np.polyfit(np.log(SIZES), np.log(t), 1)[0]
            exps.append(f"{slope:.2f}")
            ax.loglog(SIZES, t, "o-", label=f"{name} (n^{slope:.2f})")
            print(f"{label:<22} {name:<16} " + " ".join(f"{x:9.3f}" for x in t) + f"   exponent {slope:.2f}")
        lines.append(f"| random {label} | " + " | ".join(exps) + " |")
        ax.set_title(f"random {label}, 1 thread")
        ax.set_xlabel("number of bodies")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    axes[0].set_ylabel("time per state (us)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print("\n".join(lines))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
