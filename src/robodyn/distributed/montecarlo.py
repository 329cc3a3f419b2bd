"""Monte Carlo simulation: many runs of :func:`robodyn.simulate`, on the threads of this
machine or as tasks of a Dask cluster.

Run ``i`` simulates ``model`` (perturbed, when asked, with the random numbers of
``numpy.random.default_rng([seed, i])``, so a run is the same wherever and however often it
runs) from ``(q0[i], v0[i])`` under ``controller``, which keeps its own (nominal) model: the
robustness study of a controller against a plant that differs from its model.

Perturbations (``perturb``, relative half-widths of uniform distributions):

* ``"mass"``: each body's inertial parameters ``[m, m c, I]`` scaled by ``1 + u``,
  ``u ~ U(-x, x)`` per body: the mass changes, the centre of mass stays, the body stays
  physically consistent;
* ``"damping"``, ``"coulomb"``, ``"armature"``: each joint's coefficient scaled by ``1 + u``,
  one ``u`` per joint (``"friction"`` is both damping and Coulomb).

Without ``client`` the runs use a pool of threads (the compiled simulation kernels release the
GIL); with a ``dask.distributed.Client`` they are tasks of ``chunk`` runs each, the model and
the controller sent to each worker once. A run that raises does not stop the others: its
message is kept in :attr:`MonteCarlo.errors` and one warning counts the failed runs. With
``out``, run ``i``'s trajectory is written to ``out/run-<i>.parquet`` (or ``.csv``) by an
atomic rename, so a task that is retried rewrites the same file and never duplicates a run.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PERTURBATIONS = ("mass", "damping", "coulomb", "armature", "friction")


@dataclass(frozen=True)
class MonteCarlo:
    """Summary of ``N`` runs. ``q_final`` (N, nq), ``v_final`` (N, nv): the last sample;
    ``max_torque`` (N, nv): the largest ``|tau|`` of each joint over the run; ``max_error``
    (N,): the largest tracking error ``|q_desired - q|`` (NaN without a reference);
    ``mass_scale`` (N, nbodies) and ``joint_scale`` (N, 3, nv) (damping, Coulomb, armature):
    the perturbations drawn; ``errors``: None for a run that finished, else the message of
    what stopped it (its summary rows are NaN); ``paths``: the trajectory files (or None)."""

    q_final: np.ndarray
    v_final: np.ndarray
    max_torque: np.ndarray
    max_error: np.ndarray
    mass_scale: np.ndarray
    joint_scale: np.ndarray
    errors: tuple
    paths: tuple | None = None

    @property
    def failed(self) -> np.ndarray:
        """Indices of the runs that did not finish."""
        return np.array([i for i, e in enumerate(self.errors) if e is not None], dtype=np.int64)


def _perturbation(perturb) -> dict:
    perturb = dict(perturb or {})
    for key, x in perturb.items():
        if key not in PERTURBATIONS:
            raise ValueError(f"perturb: unknown key {key!r}; expected some of {PERTURBATIONS}")
        if not (isinstance(x, (int, float)) and 0 <= x < 1):
            raise ValueError(f"perturb[{key!r}]: expected a relative half-width in [0, 1), got {x!r}")
    if "friction" in perturb:
        x = perturb.pop("friction")
        perturb.setdefault("damping", x)
        perturb.setdefault("coulomb", x)
    return perturb


def perturbed_model(model, perturb, seed: int, i: int):
    """``(model_i, mass_scale (nbodies,), joint_scale (3, nv))`` of run ``i`` (module
    docstring): the random numbers of ``numpy.random.default_rng([seed, i])``."""
    perturb = _perturbation(perturb)
    rng = np.random.default_rng([seed, i])
    u = rng.uniform(-1.0, 1.0, size=(4, max(model.nbodies, model.nv)))  # rows: mass, damping, Coulomb, armature
    mass = 1.0 + perturb.get("mass", 0.0) * u[0, :model.nbodies]
    joint = np.stack([1.0 + perturb.get(k, 0.0) * u[1 + j, :model.nv]
                      for j, k in enumerate(("damping", "coulomb", "armature"))])
    if not perturb:
        return model, mass, joint
    m = model.with_inertial_parameters((model.theta * mass[:, None]).ravel()) if "mass" in perturb else model
    changes = {k: getattr(model, k) * joint[j] for j, k in enumerate(("damping", "coulomb", "armature"))
               if k in perturb}
    return (m.replace(**changes) if changes else m), mass, joint


def _one(model, q0, v0, duration, dt, controller, perturb, seed, i, path, options):
    """Run ``i``: its summary row, or the message of the error that stopped it."""
    from ..simulation import simulate

    plant, mass, joint = perturbed_model(model, perturb, seed, i)
    try:
        traj = simulate(plant, q0, v0, duration, dt, controller, **options)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as e:
        return None, mass, joint, f"run {i}: {type(e).__name__}: {e}"
    if path is not None:
        traj.to_csv(path)
    err = traj.tracking_error
    row = (traj.q[-1], traj.v[-1], np.abs(traj.tau).max(axis=0),
           float(np.abs(err).max()) if err is not None else np.nan)
    return row, mass, joint, None


def run_chunk(model, q0, v0, duration, dt, controller, perturb, seed, indices, out, suffix, options):
    """The runs ``indices`` (q0, v0 rows aligned with them), in this thread or task: a list of
    ``_one`` results. Module level and pure, for Dask."""
    return [_one(model, q0[k], v0[k], duration, dt, controller, perturb, seed, int(i),
                 None if out is None else Path(out) / f"run-{int(i):06d}{suffix}", options)
            for k, i in enumerate(indices)]


def _initial(name, x, n, N):
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[None]
    if x.ndim != 2 or x.shape[1] != n or x.shape[0] not in (1, N):
        raise ValueError(f"{name}: expected shape ({n},) or ({N}, {n}), got {np.shape(x)}")
    return np.broadcast_to(x, (N, n))


def simulate_many(model, q0, v0, duration: float, dt: float, controller=None, *, runs: int | None = None,
                  perturb=None, seed: int = 0, out=None, format: str = "parquet", client=None,
                  chunk: int | None = None, progress: bool = False, **options) -> MonteCarlo:
    """Many simulations (module docstring): run ``i`` is ``robodyn.simulate(model_i, q0[i],
    v0[i], duration, dt, controller, **options)``.

    Args:
        q0: (N, nq) or (nq,) initial configurations; v0: (N, nv) or (nv,).
        runs: N when both initial states are single (then every run starts there and only
            the perturbations differ).
        perturb: e.g. ``{"mass": 0.1, "friction": 0.2}`` (module docstring), or None.
        seed: the random numbers of run ``i`` are ``default_rng([seed, i])``.
        out: a directory for the trajectories (``run-000042.parquet``), or None.
        format: ``"parquet"`` or ``"csv"``.
        client: a ``dask.distributed.Client`` (tasks on its workers), or None (threads here).
        chunk: runs per task (default: about four tasks per worker or thread).
        progress: show Dask's progress bar (with ``client``).
        options: further keywords of :func:`robodyn.simulate` (``integrator``, ``contacts``,
            ``f_ext``, ...).
    """
    from ..simulation.simulate import positive_integer, positive_number

    q = np.asarray(q0, dtype=float)
    w = np.asarray(v0, dtype=float)
    N = max(q.shape[0] if q.ndim == 2 else 1, w.shape[0] if w.ndim == 2 else 1)
    if runs is not None:
        if q.ndim == 2 or w.ndim == 2:
            raise ValueError("runs: give it only with single initial states q0 (nq,) and v0 (nv,)")
        N = positive_integer("runs", runs)
    Q0, V0 = _initial("q0", q, model.nq, N), _initial("v0", w, model.nv, N)
    duration, dt = positive_number("duration", duration), positive_number("dt", dt)
    _perturbation(perturb)
    if format not in ("parquet", "csv"):
        raise ValueError(f"format: expected 'parquet' or 'csv', got {format!r}")
    suffix = "." + format
    if out is not None:
        Path(out).mkdir(parents=True, exist_ok=True)
    workers = len(client.scheduler_info()["workers"]) if client is not None else (os.cpu_count() or 1)
    chunk = max(1, -(-N // (4 * max(workers, 1)))) if chunk is None else positive_integer("chunk", chunk)
    parts = [np.arange(s, min(s + chunk, N)) for s in range(0, N, chunk)]
    fixed = (duration, dt)
    if client is None:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=workers) as pool:
            done = list(pool.map(lambda idx: run_chunk(model, Q0[idx], V0[idx], *fixed, controller, perturb, seed, idx,
                                                       out, suffix, options), parts))
    else:
        shared = client.scatter([model, controller], broadcast=True, hash=True)
        futures = [client.submit(run_chunk, shared[0], Q0[idx], V0[idx], *fixed, shared[1], perturb, seed, idx,
                                 None if out is None else str(out), suffix, options, pure=True)
                   for idx in parts]
        if progress:
            from distributed import progress as show

            show(futures)
        done = client.gather(futures)
    return _summary(model, [r for part in done for r in part], N, out, suffix)


def _summary(model, results, N, out, suffix) -> MonteCarlo:
    nan = np.nan
    qf, vf = np.full((N, model.nq), nan), np.full((N, model.nv), nan)
    tmax, emax = np.full((N, model.nv), nan), np.full(N, nan)
    mass, joint = np.empty((N, model.nbodies)), np.empty((N, 3, model.nv))
    errors = []
    for i, (row, m, j, err) in enumerate(results):
        mass[i], joint[i] = m, j
        errors.append(err)
        if row is not None:
            qf[i], vf[i], tmax[i], emax[i] = row
    failed = [e for e in errors if e is not None]
    if failed:
        warnings.warn(f"simulate_many: {len(failed)} of {N} runs did not finish (MonteCarlo.errors); "
                      f"the first: {failed[0]}", RuntimeWarning, stacklevel=3)
    paths = None if out is None else tuple(
        None if errors[i] is not None else Path(out) / f"run-{i:06d}{suffix}" for i in range(N))
    return MonteCarlo(qf, vf, tmax, emax, mass, joint, tuple(errors), paths)
