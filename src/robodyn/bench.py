"""Timings of robodyn's algorithms, and the same calls in Pinocchio when it is installed.

``robodyn bench [MODEL]`` prints per-call times of single calls (input checks on) and
per-state times of batched calls, for ``rnea``, ``aba``, ``crba`` and ``coriolis_matrix``.
When Pinocchio (``pip install pin``) is importable, the model is converted with
:func:`robodyn.interop.to_pinocchio` and Pinocchio's Python calls are timed on the same states in the same
process, with the ratio robodyn / Pinocchio (below 1 means robodyn is faster).

Pinocchio is never a runtime dependency: it is imported only when asked for.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from .interop.pinocchio import to_pinocchio


@dataclass
class Timing:
    name: str
    robodyn_us: float
    other_us: float | None = None

    @property
    def ratio(self) -> float | None:
        return None if self.other_us is None else self.robodyn_us / self.other_us


def _calibrate(fn, min_time: float) -> tuple[int, float]:
    """Calls of ``fn`` that take at least ``min_time`` s (up to a million), and their time."""
    fn()
    n = 1
    while True:
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        dt = time.perf_counter() - t0
        if dt > min_time or n > 1_000_000:
            return n, dt
        n *= 4


def per_call_us(fn, min_time: float = 0.2, repeat: int = 5) -> float:
    """Best-of-``repeat`` time of one call of ``fn`` in microseconds."""
    n, dt = _calibrate(fn, min_time / repeat)
    best = dt / n
    for _ in range(repeat - 1):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, (time.perf_counter() - t0) / n)
    return best * 1e6


def paired_us(fn, other=None, min_time: float = 0.02, rounds: int = 15) -> tuple[float, float | None]:
    """Best per-call times in microseconds of ``fn`` and ``other``, timed in alternating
    rounds so that both see the same machine load (on a shared machine the speed drifts
    between seconds; comparing minima of interleaved rounds keeps the ratio honest)."""
    fns = [f for f in (fn, other) if f is not None]
    counts = [_calibrate(f, min_time)[0] for f in fns]  # calls per round
    best = [float("inf")] * len(fns)
    for _ in range(rounds):
        for j, (f, n) in enumerate(zip(fns, counts)):
            t0 = time.perf_counter()
            for _ in range(n):
                f()
            best[j] = min(best[j], (time.perf_counter() - t0) / n)
    return best[0] * 1e6, (best[1] * 1e6 if other is not None else None)


def states(model, batch: int, seed: int = 0):
    """Random states: single ``(q, v, a)`` and batched ``(Q, V, A)`` of ``batch`` rows."""
    from .random import random_state

    rng = np.random.default_rng(seed)
    Q, V, A = random_state(model, rng, batch)
    return (Q[0].copy(), V[0].copy(), A[0].copy()), (Q, V, A)


def robodyn_calls(model, q, v, a, suffix: str = "", out: bool = False) -> dict:
    """The four timed calls on the states ``(q, v, a)`` (single or batched), by name; with
    ``out``, each writes into an array allocated once (as Pinocchio's calls write into theirs)."""
    import robodyn as rd

    vec, mat = ((np.empty(v.shape), np.empty(v.shape + (model.nv,))) if out else (None, None))
    return {
        "rnea" + suffix: lambda: rd.rnea(model, q, v, a, out=vec),
        "aba" + suffix: lambda: rd.aba(model, q, v, a, out=vec),
        "crba" + suffix: lambda: rd.crba(model, q, out=mat),
        "coriolis_matrix" + suffix: lambda: rd.coriolis_matrix(model, q, v, out=mat),
    }


def _runnable(pm, calls: dict) -> dict:
    """The Pinocchio ``calls`` that run on ``pm``. On a model with mimic joints Pinocchio's ABA
    is left out without a try (4.1: ``aba`` refuses it, ``abaInParallel`` crashes the
    process), and the others are tried once: those it refuses (``RuntimeError``) are left out
    of the comparison."""
    kept = {}
    mimic = len(pm.mimicking_joints) > 0
    for name, fn in calls.items():
        if mimic and name.startswith("aba"):
            continue
        try:
            fn()
        except RuntimeError:
            continue
        kept[name] = fn
    return kept


def single_call_timings(model, pm=None, seed: int = 0) -> list[Timing]:
    """Per-call times of robodyn (and Pinocchio's Python API if ``pm`` is given)."""
    (q, v, a), _ = states(model, 1, seed)
    calls = robodyn_calls(model, q, v, a)
    pin_calls = {}
    if pm is not None:  # the converted model has the same q layout (one angle per joint)
        import pinocchio as pin

        pd = pm.createData()
        pin_calls = _runnable(pm, {
            "rnea": lambda: pin.rnea(pm, pd, q, v, a),
            "aba": lambda: pin.aba(pm, pd, q, v, a),
            "crba": lambda: pin.crba(pm, pd, q),
            "coriolis_matrix": lambda: pin.computeCoriolisMatrix(pm, pd, q, v),
        })
    return [Timing(name, *paired_us(fn, pin_calls.get(name))) for name, fn in calls.items()]


def batch_timings(model, batch: int, pm=None, seed: int = 0) -> list[Timing]:
    """Per-state times of batched calls; Pinocchio's ``rneaInParallel``/``abaInParallel``
    with the same number of threads, and Python loops over ``crba``/``computeCoriolisMatrix``.
    Both libraries write into arrays allocated before the timing (robodyn's ``out=``)."""
    _, (Q, V, A) = states(model, batch, seed)
    threads = numba.get_num_threads()
    calls = robodyn_calls(model, Q, V, A, " (batch)", out=True)
    others = {}
    if pm is not None:
        import pinocchio as pin

        pool = pin.ModelPool(pm, threads)
        Qt, Vt, At = (np.asfortranarray(X.T) for X in (Q, V, A))
        tau = np.zeros((model.nv, batch), order="F")
        pd = pm.createData()
        n_loop = min(batch, 2000)
        others = _runnable(pm, {
            "rnea (batch)": lambda: pin.rneaInParallel(threads, pool, Qt, Vt, At, tau),
            "aba (batch)": lambda: pin.abaInParallel(threads, pool, Qt, Vt, At, tau),
            "crba (batch)": lambda: [pin.crba(pm, pd, Q[s]) for s in range(n_loop)],
            "coriolis_matrix (batch)": lambda: [pin.computeCoriolisMatrix(pm, pd, Q[s], V[s]) for s in range(n_loop)],
        })
    out = []
    for name, fn in calls.items():
        ours, theirs = paired_us(fn, others.get(name), rounds=9)
        loop = name in ("crba (batch)", "coriolis_matrix (batch)")  # Pinocchio: a Python loop of n_loop calls
        out.append(Timing(name, ours / batch, None if theirs is None else theirs / (n_loop if loop else batch)))
    return out


def rel_error(actual, expected) -> float:
    """``max |actual - expected| / max(1, max |expected|)``, the relative error of the tests
    against Pinocchio (0 for empty arrays)."""
    if np.size(expected) == 0:
        return 0.0
    return float(np.max(np.abs(actual - expected)) / max(1.0, np.max(np.abs(expected))))


def agreement(model, pm, batch: int, seed: int = 0) -> dict:
    """Largest relative error (see :func:`rel_error`, state by state) between robodyn and
    Pinocchio on the states :func:`batch_timings` times: every state for ``rnea`` and ``aba``
    (Pinocchio's parallel calls), the looped states for ``crba`` and ``coriolis_matrix``.
    Joint friction, which Pinocchio's dynamics leave out, is switched off here."""
    import pinocchio as pin

    import robodyn as rd

    _, (Q, V, A) = states(model, batch, seed)
    threads = numba.get_num_threads()
    pool = pin.ModelPool(pm, threads)
    Qt, Vt, At = (np.asfortranarray(X.T) for X in (Q, V, A))
    out = np.zeros((model.nv, batch), order="F")
    pd = pm.createData()
    n_loop = min(batch, 2000)
    errors = {}
    pin.rneaInParallel(threads, pool, Qt, Vt, At, out)
    errors["rnea"] = max(map(rel_error, rd.rnea(model, Q, V, A, friction=False), out.T))
    pin.abaInParallel(threads, pool, Qt, Vt, At, out)
    errors["aba"] = max(map(rel_error, rd.aba(model, Q, V, A, friction=False), out.T))
    M, C = rd.crba(model, Q[:n_loop]), rd.coriolis_matrix(model, Q[:n_loop], V[:n_loop])
    errors["crba"] = errors["coriolis_matrix"] = 0.0
    for s in range(n_loop):
        Mp = pin.crba(pm, pd, Q[s])  # upper triangle
        errors["crba"] = max(errors["crba"], rel_error(M[s], np.triu(Mp) + np.triu(Mp, 1).T))
        errors["coriolis_matrix"] = max(errors["coriolis_matrix"],
                                        rel_error(C[s], pin.computeCoriolisMatrix(pm, pd, Q[s], V[s])))
    return errors


def format_table(rows: list[Timing], other: str = "pinocchio") -> str:
    lines = [f"  {'call':<26} {'robodyn us':>11} {other + ' us':>14} {'ratio':>7}"]
    for t in rows:
        o = "" if t.other_us is None else f"{t.other_us:14.3f}"
        r = "" if t.ratio is None else f"{t.ratio:7.3g}"
        lines.append(f"  {t.name:<26} {t.robodyn_us:11.3f} {o:>14} {r:>7}")
    return "\n".join(lines)


def run_bench(model, label: str, batch: int = 10000, compare: bool = True) -> int:
    """Print robodyn's timings for ``model`` (and Pinocchio's, if installed and ``compare``)."""
    pm = None
    if compare:
        try:
            pm = to_pinocchio(model)
        except ImportError:
            print("(Pinocchio is not installed: robodyn timings only; `pip install pin` to compare)")
        except ValueError as e:  # a tree Pinocchio cannot represent in robodyn's body order
            print(f"(robodyn timings only: {e})")
    print(f"robodyn bench on {label!r}: nq={model.nq}, nv={model.nv}, {model.nbodies} bodies, "
          f"{numba.get_num_threads()} threads")
    print("Single calls from Python (input checks on), microseconds per call:")
    print(format_table(single_call_timings(model, pm)))
    print(f"Batches of {batch} states, microseconds per state:")
    print(format_table(batch_timings(model, batch, pm)))
    if pm is not None:
        print("ratio = robodyn / pinocchio: below 1 means robodyn is faster"
              + ("; no Pinocchio time: Pinocchio does not run that algorithm on mimic joints"
                 if len(pm.mimicking_joints) else ""))
    return 0
