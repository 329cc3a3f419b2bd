"""Measurement logs: CSV reading and writing, zero-phase filtering, differentiation, decimation.

CSV layout (one header row, comma separated, one row per sample, SI units, radians)::

    time, q_<joint>..., [qd_<joint>...], [qdd_<joint>...], [tau_<joint>...]

with ``<joint>`` each name of ``model.joint_names`` (the 1-dof joints, order free; extra
columns are ignored). ``time`` must increase strictly and, for filtering and
differentiation, uniformly. Velocities ``qd_*`` and accelerations ``qdd_*`` are optional
(all joints or none); when absent they are obtained by differentiating the filtered
positions. Torques ``tau_*`` are required for identification. Empty fields and ``nan`` are
missing values: such rows are reported by their line numbers in the file and never used.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..files import atomic_path
from ..joints import FREE, SPHERICAL

KINDS = ("q", "qd", "qdd", "tau")


@dataclass(frozen=True)
class Log:
    """Samples ``t`` (N,), ``q`` (N, nv) and, when known, ``qd``, ``qdd``, ``tau`` (N, nv)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    tau: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def rows(self, sl) -> "Log":
        """The samples ``sl`` (a slice or index array) of every array."""
        return Log(*(None if x is None else x[sl] for x in (self.t, self.q, self.qd, self.qdd, self.tau)))


def _fixed_base(model, what: str) -> None:
    if np.any(model.joint_type == FREE):
        raise ValueError(f"{what}: logs hold the 1-dof joints of a fixed-base model; this model has a free joint")
    if np.any(model.joint_type == SPHERICAL):
        raise ValueError(f"{what}: logs hold the 1-dof joints of a fixed-base model; this model has a spherical joint")


def column_names(model, kind: str) -> list[str]:
    """CSV columns of one kind (``q``, ``qd``, ``qdd`` or ``tau``): ``<kind>_<joint>``."""
    return [f"{kind}_{j}" for j in model.joint_names]


def write_log(path, model, t, q, *, qd=None, qdd=None, tau=None) -> Path:
    """Write a log in the CSV layout of this module (full float precision)."""
    _fixed_base(model, "write_log")
    path = Path(path)
    header, cols = ["time"], [np.asarray(t, dtype=float)[:, None]]
    for kind, x in zip(KINDS, (q, qd, qdd, tau)):
        if x is not None:
            x = np.asarray(x, dtype=float)
            if x.shape != (cols[0].shape[0], model.nv):
                raise ValueError(f"{kind}: expected shape ({cols[0].shape[0]}, {model.nv}), got {x.shape}")
            header += column_names(model, kind)
            cols.append(x)
    data = np.hstack(cols)
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows([[repr(float(v)) for v in row] for row in data])
    return path


def read_log(path, model, *, require_tau: bool = True) -> Log:
    """Read a CSV log (module docstring) for ``model``.

    Raises ``ValueError`` naming the file for: missing columns (listed), a kind given for
    only some joints, non-numeric fields (line and column), missing values (lines listed),
    time not strictly increasing (first offending line), fewer than 2 rows.
    """
    _fixed_base(model, "read_log")
    path = Path(path)
    try:
        with open(path, newline="") as f:
            reader = csv.reader(f)
            try:
                header = [h.strip() for h in next(reader)]
            except StopIteration:
                raise ValueError(f"{path}: empty file, expected a header row") from None
            rows = [(reader.line_num, row) for row in reader if any(cell.strip() for cell in row)]
    except (UnicodeDecodeError, csv.Error) as e:
        raise ValueError(f"{path}: not a CSV text file ({e})") from None
    index = {name: k for k, name in enumerate(header)}
    need = ["time"] + column_names(model, "q") + (column_names(model, "tau") if require_tau else [])
    missing = [n for n in need if n not in index]
    if missing:
        raise ValueError(f"{path}: missing columns {missing}; expected time, q_<joint>"
                         f"{', tau_<joint>' if require_tau else ''} for joints {list(model.joint_names)}")
    kinds = {"time": ["time"]}
    for kind in KINDS:
        names = column_names(model, kind)
        present = [n for n in names if n in index]
        if present and len(present) != len(names):
            raise ValueError(f"{path}: {kind} given for some joints only; missing columns "
                             f"{[n for n in names if n not in index]}")
        if present:
            kinds[kind] = names
    if len(rows) < 2:
        raise ValueError(f"{path}: {len(rows)} data rows, need at least 2")
    wanted = [n for names in kinds.values() for n in names]
    data = np.empty((len(rows), len(wanted)))
    lines = np.array([ln for ln, _ in rows])
    for r, (line, row) in enumerate(rows):
        for c, name in enumerate(wanted):
            k = index[name]
            cell = row[k].strip() if k < len(row) else ""
            try:
                data[r, c] = float(cell) if cell else np.nan
            except ValueError:
                raise ValueError(f"{path}: line {line}, column {name!r}: not a number: {cell!r}") from None
    bad = ~np.isfinite(data).all(axis=1)
    if bad.any():
        shown = lines[bad][:20].tolist()
        raise ValueError(f"{path}: {int(bad.sum())} rows with missing or non-finite values at lines {shown}"
                         f"{' ...' if bad.sum() > 20 else ''}; remove or repair them")
    t = data[:, 0]
    step = np.diff(t)
    if np.any(step <= 0):
        k = int(np.flatnonzero(step <= 0)[0])
        raise ValueError(f"{path}: time not strictly increasing at line {lines[k + 1]} "
                         f"(t = {t[k + 1]!r} after {t[k]!r} on line {lines[k]})")
    out, c = {}, 1
    for kind in KINDS:
        if kind in kinds:
            out[kind] = data[:, c:c + model.nv].copy()
            c += model.nv
    return Log(t=t.copy(), **out)


def sample_rate(t: np.ndarray, rtol: float = 1e-3) -> float:
    """The sampling rate (Hz) of uniformly spaced times; ``ValueError`` if they are not."""
    step = np.diff(t)
    dt = float(np.median(step))
    worst = float(np.abs(step - dt).max())
    if worst > rtol * dt:
        k = int(np.argmax(np.abs(step - dt)))
        raise ValueError(f"time is not uniformly sampled: step {step[k]:.6g} s at sample {k + 1}, "
                         f"median {dt:.6g} s; resample the log first")
    return 1.0 / dt


def preprocess(log: Log, *, cutoff: float | None = None, order: int = 4, decimate: int = 1,
               trim: int | None = None) -> Log:
    """Filter, differentiate and decimate a log.

    1. Zero-phase Butterworth low-pass of ``order`` at ``cutoff`` Hz on positions, given
       velocities and accelerations, and torques (``scipy.signal.filtfilt``, forward and
       backward: no phase lag, so torques and states stay aligned; odd extension of
       ``3 rate / cutoff`` samples at the ends).
    2. Missing velocities and accelerations: central differences of the filtered positions
       (``numpy.gradient``, second order), then of the velocities.
    3. ``trim`` samples dropped at each end (filter and difference edge effects; default
       ``ceil(rate / cutoff)``, or 2 without filter).
    4. Every ``decimate``-th sample kept; the low-pass is the anti-aliasing filter, so
       ``cutoff`` must be below the new Nyquist frequency.
    """
    from scipy.signal import butter, filtfilt

    fs = sample_rate(log.t)
    if decimate < 1 or int(decimate) != decimate:
        raise ValueError(f"decimate: expected a positive integer, got {decimate}")
    if cutoff is not None:
        if not 0 < cutoff < fs / 2:
            raise ValueError(f"cutoff: expected 0 < cutoff < {fs / 2:g} Hz (Nyquist), got {cutoff}")
        if decimate > 1 and cutoff >= fs / (2 * decimate):
            raise ValueError(f"cutoff {cutoff:g} Hz is not below the Nyquist frequency {fs / (2 * decimate):g} Hz "
                             f"after decimating by {decimate}: the samples would alias")
    elif decimate > 1:
        raise ValueError("decimate > 1 needs a low-pass cutoff (anti-aliasing)")
    if cutoff is not None:
        b, a = butter(order, cutoff / (fs / 2))
        # odd extension over three periods of the cutoff: the edge transients die out in it
        padlen = max(3 * max(len(a), len(b)), 3 * int(np.ceil(fs / cutoff)))
        if len(log) <= padlen:
            raise ValueError(f"log of {len(log)} samples is too short for the filter at {cutoff:g} Hz "
                             f"(needs more than {padlen})")
        filt = lambda x: None if x is None else filtfilt(b, a, x, axis=0, padlen=padlen)  # noqa: E731
    else:
        filt = lambda x: x  # noqa: E731
    q = filt(log.q)
    qd = filt(log.qd) if log.qd is not None else np.gradient(q, log.t, axis=0, edge_order=2)
    qdd = filt(log.qdd) if log.qdd is not None else np.gradient(qd, log.t, axis=0, edge_order=2)
    out = Log(t=log.t, q=q, qd=qd, qdd=qdd, tau=filt(log.tau))
    k = trim if trim is not None else (int(np.ceil(fs / cutoff)) if cutoff else 2)
    if 2 * k >= len(out):
        raise ValueError(f"trim: {k} samples at each end leave nothing of {len(out)} samples")
    return out.rows(slice(k, len(out) - k, int(decimate)))


__all__ = ["Log", "read_log", "write_log", "preprocess", "column_names", "sample_rate"]
