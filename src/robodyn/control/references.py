"""Joint-space reference trajectories ``t -> (q_d, qd_d, qdd_d)``.

* :class:`PointToPoint`: rest-to-rest motion ``q_d(t) = q0 + s(tau) (q1 - q0)``,
  ``tau = (t - t0) / T``, with the cubic time scaling ``s = 3 tau^2 - 2 tau^3`` (zero end
  velocities) or the quintic ``s = 10 tau^3 - 15 tau^4 + 6 tau^5`` (zero end velocities and
  accelerations); Lynch and Park, *Modern Robotics* (2017), section 9.2.2.
* :class:`Sampled`: samples ``(t_k, q_k)`` (e.g. a CSV file) interpolated by a cubic spline
  (not-a-knot end conditions; scipy's ``CubicSpline``).

References take a time or an array of times (then each output is (N, n)).
Before the start and after the end a reference holds its first / last position at rest
(a point-to-point reference gives its polynomial's values on the closed interval, so the
cubic's acceleration jumps at both ends: fixed-step integrators are most accurate with the
quintic).
"""

from __future__ import annotations

import numpy as np

from .._deprecated import warn_renamed

# Coefficients of s(tau), lowest power first.
_POLYNOMIALS = {"cubic": (0.0, 0.0, 3.0, -2.0), "quintic": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0)}
_SCALINGS = {
    # s(tau), s'(tau), s''(tau)
    "cubic": (lambda x: 3 * x ** 2 - 2 * x ** 3, lambda x: 6 * x - 6 * x ** 2, lambda x: 6 - 12 * x),
    "quintic": (lambda x: 10 * x ** 3 - 15 * x ** 4 + 6 * x ** 5, lambda x: 30 * x ** 2 - 60 * x ** 3 + 30 * x ** 4,
                lambda x: 60 * x - 180 * x ** 2 + 120 * x ** 3),
}


def _points(name: str, x, n: int | None = None) -> np.ndarray:
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(x).__name__}") from None
    if a.ndim != 1 or (n is not None and a.shape != (n,)):
        raise ValueError(f"{name}: expected shape ({n if n is not None else 'n'},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or Inf")
    return a


class PointToPoint:
    """Rest-to-rest joint motion from ``q0`` to ``q1`` in ``duration`` seconds from ``t0``.

    ``profile``: ``"cubic"`` or ``"quintic"`` (module docstring). Call it with a time ``t``
    to get ``(q_d, qd_d, qdd_d)``, each (n,).
    """

    def __init__(self, q0, q1, duration: float, profile: str = "quintic", t0: float = 0.0):
        if profile not in _SCALINGS:
            raise ValueError(f"profile: expected 'cubic' or 'quintic', got {profile!r}")
        self.q0 = _points("q0", q0)
        self.q1 = _points("q1", q1, self.q0.shape[0])
        if not (np.isfinite(duration) and duration > 0):
            raise ValueError(f"duration: must be finite and > 0, got {duration}")
        if not np.isfinite(t0):
            raise ValueError(f"t0: must be finite, got {t0}")
        self.duration, self.t0, self.profile = float(duration), float(t0), profile

    def __call__(self, t):
        """``(q_d, qd_d, qdd_d)`` at ``t``: each (n,) for a scalar ``t``, (N, n) for ``t`` (N,)."""
        s, ds, dds = _SCALINGS[self.profile]
        d = self.q1 - self.q0
        if np.ndim(t) == 0:
            x = (t - self.t0) / self.duration
            if x < 0.0 or x > 1.0:  # at rest outside the motion
                return (self.q0 if x < 0.0 else self.q1).copy(), np.zeros_like(d), np.zeros_like(d)
            return self.q0 + s(x) * d, ds(x) / self.duration * d, dds(x) / self.duration ** 2 * d
        x = (np.asarray(t, dtype=float)[:, None] - self.t0) / self.duration
        inside = (x >= 0.0) & (x <= 1.0)
        x = np.clip(x, 0.0, 1.0)
        return (self.q0 + s(x) * d, np.where(inside, ds(x) / self.duration * d, 0.0),
                np.where(inside, dds(x) / self.duration ** 2 * d, 0.0))

    def piecewise_polynomial(self):
        """``(breaks (2,), coefs (k, 1, n))`` in scipy's ``PPoly`` layout (highest power of
        ``t - t0`` first), for the compiled controllers."""
        a = np.array(_POLYNOMIALS[self.profile]) / self.duration ** np.arange(len(_POLYNOMIALS[self.profile]))
        coefs = a[:, None] * (self.q1 - self.q0)[None, :]
        coefs[0] += self.q0
        return np.array([self.t0, self.t0 + self.duration]), np.ascontiguousarray(coefs[::-1, None, :])


def cubic(q0, q1, duration: float, t0: float = 0.0) -> PointToPoint:
    """Cubic rest-to-rest reference (zero velocity at both ends)."""
    return PointToPoint(q0, q1, duration, "cubic", t0)


def quintic(q0, q1, duration: float, t0: float = 0.0) -> PointToPoint:
    """Quintic rest-to-rest reference (zero velocity and acceleration at both ends)."""
    return PointToPoint(q0, q1, duration, "quintic", t0)


class Sampled:
    """A reference through samples ``q`` (N, n) at strictly increasing times ``t`` (N,),
    interpolated by a cubic spline (N >= 2; two samples give a straight line)."""

    def __init__(self, t, q):
        from scipy.interpolate import CubicSpline

        self.t = _points("t", t)
        q = np.array(q, dtype=float)
        if q.ndim != 2 or q.shape[0] != self.t.shape[0]:
            raise ValueError(f"q: expected shape ({self.t.shape[0]}, n), got {q.shape}")
        if self.t.shape[0] < 2 or np.any(np.diff(self.t) <= 0):
            raise ValueError("t: need at least 2 strictly increasing times")
        if not np.all(np.isfinite(q)):
            raise ValueError("q: contains NaN or Inf")
        self.q = q
        self.spline = CubicSpline(self.t, q, axis=0)

    def __call__(self, t):
        """``(q_d, qd_d, qdd_d)`` at ``t``: each (n,) for a scalar ``t``, (N, n) for ``t`` (N,)."""
        if np.ndim(t) == 0:
            if t < self.t[0] or t > self.t[-1]:
                z = np.zeros(self.q.shape[1])
                return (self.q[0] if t < self.t[0] else self.q[-1]).copy(), z, z.copy()
            return self.spline(t), self.spline(t, 1), self.spline(t, 2)
        t = np.asarray(t, dtype=float)
        tc = np.clip(t, self.t[0], self.t[-1])
        inside = ((t >= self.t[0]) & (t <= self.t[-1]))[:, None]
        return self.spline(tc), np.where(inside, self.spline(tc, 1), 0.0), np.where(inside, self.spline(tc, 2), 0.0)

    def piecewise_polynomial(self):
        """``(breaks (N,), coefs (4, N - 1, n))`` of the spline (scipy's ``PPoly`` layout)."""
        return np.ascontiguousarray(self.spline.x), np.ascontiguousarray(self.spline.c)

    @classmethod
    def from_csv(cls, path, model) -> "Sampled":
        """The ``q`` columns of a trajectory or log file (format of :mod:`robodyn.io.log`);
        ``(path, model)`` as every reader of robodyn (the old order ``(model, path)`` warns)."""
        from ..io.log import read_log
        from ..model import Model

        if isinstance(path, Model):
            warn_renamed("Sampled.from_csv(model, path)", "Sampled.from_csv(path, model)", "robodyn")
            path, model = model, path
        log = read_log(path, model)
        return cls(log.t, log.q)
