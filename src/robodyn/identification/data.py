"""Measurement logs: zero-phase filtering, differentiation, decimation.

Logs are read and written in robodyn's one tabular format (:mod:`robodyn.io.log`:
``t, q:<joint>..., v:<joint>..., a:<joint>..., tau:<joint>...``) by :func:`read_log` and
:func:`write_log`, re-exported here. ``t`` must be uniformly sampled for filtering and
differentiation; velocities and accelerations, when absent, are obtained by differentiating
the filtered positions.
"""

from __future__ import annotations

import numpy as np

from ..io.log import Log, columns, read_log, write_log


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
        num, den = butter(order, cutoff / (fs / 2))
        # odd extension over three periods of the cutoff: the edge transients die out in it
        padlen = max(3 * max(len(num), len(den)), 3 * int(np.ceil(fs / cutoff)))
        if len(log) <= padlen:
            raise ValueError(f"log of {len(log)} samples is too short for the filter at {cutoff:g} Hz "
                             f"(needs more than {padlen})")
        filt = lambda x: None if x is None else filtfilt(num, den, x, axis=0, padlen=padlen)  # noqa: E731
    else:
        filt = lambda x: x  # noqa: E731
    widths = {x.shape[1] for x in (log.v, log.a, log.tau) if x is not None}
    if (log.v is None or log.a is None) and widths and log.q.shape[1] not in widths:
        raise ValueError("preprocess: a log of a floating-base or ball-jointed model needs its v and a columns "
                         "(positions with quaternions are not differentiated)")
    q = filt(log.q)
    v = filt(log.v) if log.v is not None else np.gradient(q, log.t, axis=0, edge_order=2)
    a = filt(log.a) if log.a is not None else np.gradient(v, log.t, axis=0, edge_order=2)
    out = Log(t=log.t, q=q, v=v, a=a, tau=filt(log.tau), extra={k: filt(x) for k, x in log.extra.items()})
    k = trim if trim is not None else (int(np.ceil(fs / cutoff)) if cutoff else 2)
    if 2 * k >= len(out):
        raise ValueError(f"trim: {k} samples at each end leave nothing of {len(out)} samples")
    return out.rows(slice(k, len(out) - k, int(decimate)))


__all__ = ["Log", "read_log", "write_log", "preprocess", "columns", "sample_rate"]
