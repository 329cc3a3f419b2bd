"""Analytical derivatives of the dynamics against Pinocchio and against finite differences.

    python benchmarks/derivatives.py [--batch 10000]

Robots from example-robot-data: Panda (fixed base), Solo12 and Talos reduced (floating base).
For ``rnea_derivatives`` and ``aba_derivatives``: single calls from Python against Pinocchio's
``computeRNEADerivatives`` / ``computeABADerivatives``, the per-state time of a batch against
a Python loop over Pinocchio (which has no batched derivatives), each pair timed in alternating
rounds, and ``aba_derivatives`` against central finite differences of ``aba`` (one
batched ``aba`` call on the ``4 nv`` perturbed states, step 1e-6): time and accuracy. Every
result is checked against Pinocchio (relative error printed). Ratio: robodyn / other, below 1
robodyn is faster. ``rnea_second_derivatives`` against central differences of
``rnea_derivatives`` (one batched call on the ``4 nv`` perturbed states, step 1e-6; Pinocchio's
Python bindings do not expose its second-order derivatives): time and agreement.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numba
import numpy as np

import robodyn as rd
from robodyn.bench import Timing, format_table, paired_us, rel_error

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare import load_pair  # noqa: E402

ROBOTS = [("Panda", "panda_description/urdf/panda.urdf", False),
          ("Solo12", "solo_description/robots/solo12.urdf", True),
          ("Talos reduced", "talos_data/robots/talos_reduced.urdf", True)]
STEP = 1e-6


def aba_by_differences(model, q, v, tau):
    """``(dqdd_dq, dqdd_dv)`` by central differences: one batched ``aba`` of the 4 nv states."""
    n = model.nv
    E = np.vstack([np.eye(n), -np.eye(n)]) * STEP
    Q = np.vstack([rd.integrate(model, q, E), np.broadcast_to(q, (2 * n, q.size))])
    V = np.vstack([np.broadcast_to(v, (2 * n, n)), v + E])
    out = rd.aba(model, Q, V, np.broadcast_to(tau, (4 * n, n)), friction=False)
    d = (out[:n] - out[n:2 * n]) / (2 * STEP), (out[2 * n:3 * n] - out[3 * n:]) / (2 * STEP)
    return d[0].T, d[1].T


def rnea_second_by_differences(model, q, v, a):
    """``(d2tau_dq2, d2tau_dqdv, d2tau_dv2, d2tau_dadq)`` by central differences of
    ``rnea_derivatives``: one batched call on the 4 nv perturbed states, ``[i, j, k]`` =
    ``d/dx_k`` of ``dtau_i/dy_j``."""
    n = model.nv
    E = np.vstack([np.eye(n), -np.eye(n)]) * STEP
    Q = np.vstack([rd.integrate(model, q, E), np.broadcast_to(q, (2 * n, q.size))])
    V = np.vstack([np.broadcast_to(v, (2 * n, n)), v + E])
    dq, dv, M = rd.rnea_derivatives(model, Q, V, np.broadcast_to(a, (4 * n, n)), friction=False)

    def along(x, lo):  # stack the k-th difference last: (nv, nv, nv)
        return np.moveaxis((x[lo:lo + n] - x[lo + n:lo + 2 * n]) / (2 * STEP), 0, -1)
    return along(dq, 0), along(dq, 2 * n), along(dv, 2 * n), along(M, 0)


def per_state(ours, n_ours: int, theirs, n_theirs: int) -> tuple[float, float]:
    """Microseconds per state of two batched calls, timed in alternating rounds (best of 15:
    a batch takes tens of milliseconds, and the host's speed drifts between seconds)."""
    a, b = paired_us(ours, theirs, rounds=15)
    return a / n_ours, b / n_theirs


def section(name: str, relpath: str, floating: bool, batch: int) -> str:
    import pinocchio as pin

    model, pm = load_pair(name, relpath, floating)
    data = pm.createData()
    rng = np.random.default_rng(0)
    q, v, a = rd.random.random_state(model, rng)
    Q, V, A = rd.random.random_state(model, rng, batch)
    tau = rd.rnea(model, q, v, a, friction=False)
    T = rd.rnea(model, Q, V, A, friction=False)
    kw = dict(friction=False)

    errors = {}
    mine, theirs = rd.rnea_derivatives(model, q, v, a, **kw), pin.computeRNEADerivatives(pm, data, q, v, a)
    errors["rnea_derivatives"] = max(rel_error(mine[0], theirs[0]), rel_error(mine[1], theirs[1]),
                                     rel_error(mine[2], np.triu(theirs[2]) + np.triu(theirs[2], 1).T))
    mine, theirs = rd.aba_derivatives(model, q, v, tau, **kw), pin.computeABADerivatives(pm, data, q, v, tau)
    errors["aba_derivatives"] = max(rel_error(x, y) for x, y in zip(mine, theirs))
    fd = aba_by_differences(model, q, v, tau)
    errors["aba finite differences"] = max(rel_error(fd[0], mine[0]), rel_error(fd[1], mine[1]))
    second = rd.rnea_second_derivatives(model, q, v, a, **kw)
    errors["rnea second derivatives / differences"] = max(
        rel_error(x, y) for x, y in zip(second, rnea_second_by_differences(model, q, v, a)))
    Bn = batch // 10  # the Python loops are slow: time them on a tenth of the batch
    rows = [
        Timing("rnea_derivatives", *paired_us(lambda: rd.rnea_derivatives(model, q, v, a, **kw),
                                              lambda: pin.computeRNEADerivatives(pm, data, q, v, a))),
        Timing("aba_derivatives", *paired_us(lambda: rd.aba_derivatives(model, q, v, tau, **kw),
                                             lambda: pin.computeABADerivatives(pm, data, q, v, tau))),
        Timing("rnea_derivatives (batch) / loop", *per_state(
            lambda: rd.rnea_derivatives(model, Q, V, A, **kw), batch,
            lambda: [pin.computeRNEADerivatives(pm, data, *x) for x in zip(Q[:Bn], V[:Bn], A[:Bn])], Bn)),
        Timing("aba_derivatives (batch) / loop", *per_state(
            lambda: rd.aba_derivatives(model, Q, V, T, **kw), batch,
            lambda: [pin.computeABADerivatives(pm, data, *x) for x in zip(Q[:Bn], V[:Bn], T[:Bn])], Bn)),
        Timing("aba_derivatives / aba differences", *paired_us(lambda: rd.aba_derivatives(model, q, v, tau, **kw),
                                                               lambda: aba_by_differences(model, q, v, tau))),
        Timing("rnea_second_derivatives / differences", *paired_us(
            lambda: rd.rnea_second_derivatives(model, q, v, a, **kw),
            lambda: rnea_second_by_differences(model, q, v, a))),
    ]
    head = (f"### {name} ({'floating' if floating else 'fixed'} base, nv = {model.nv}), Pinocchio {pin.__version__}, "
            f"{numba.get_num_threads()} threads, batch {batch}\n")
    agree = ", ".join(f"{k} {e:.1e}" for k, e in errors.items())
    return (head + "\n```\n" + format_table(rows, "other") + "\n```\n\n"
            + f"Relative errors: against Pinocchio ({agree}; the last two are the finite differences' "
                     "errors).\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--batch", type=int, default=10000)
    args = parser.parse_args()
    for name, path, floating in ROBOTS:
        print(section(name, path, floating, args.batch), flush=True)


if __name__ == "__main__":
    main()
