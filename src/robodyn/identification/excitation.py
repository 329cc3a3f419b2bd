"""Excitation trajectories: periodic finite Fourier series, optimised for identification.

Each joint ``j`` follows (Swevers, Ganseman, Tukel, De Schutter and Van Brussel, "Optimal
robot excitation and identification", IEEE Trans. Robotics and Automation 13(5), 1997)

    q_j(t) = q0_j + sum_{l=1}^{L} a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t)

with the fundamental pulsation ``w = 2 pi / period``; velocities and accelerations follow
analytically, and the motion is periodic (the data of several periods can be averaged). The
coefficients ``(q0, a, b)`` minimise the condition number of the base regressor stacked
over one period, subject to the joint position limits (with a margin), velocity limits and
acceleration limits, at every sample, with SciPy's SLSQP.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..files import atomic_path
from ..joints import FREE, SPHERICAL
from ._blas import one_blas_thread


@dataclass(frozen=True)
class FourierTrajectory:
    """``q0`` (nv,), ``a``, ``b`` (nv, L) and the ``period`` (s) of a Fourier-series
    trajectory (module docstring)."""

    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    period: float

    @property
    def harmonics(self) -> int:
        return int(self.a.shape[1])

    def __call__(self, t):
        """``(q, v, a)``, each (len(t), nv), at times ``t`` (s)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        w = 2.0 * np.pi / self.period
        l = np.arange(1, self.harmonics + 1)
        wl = w * l                                   # (L,)
        s, c = np.sin(np.outer(t, wl)), np.cos(np.outer(t, wl))  # (T, L)
        q = self.q0 + s @ (self.a / wl).T - c @ (self.b / wl).T
        qd = c @ self.a.T + s @ self.b.T
        qdd = -s @ (self.a * wl).T + c @ (self.b * wl).T
        return q, qd, qdd

    def sample(self, duration: float, rate: float):
        """``(t, q, v, a)`` sampled at ``rate`` Hz over ``[0, duration)``."""
        if not (duration > 0 and rate > 0):
            raise ValueError(f"duration and rate must be positive, got {duration}, {rate}")
        t = np.arange(int(round(duration * rate))) / rate
        return (t, *self(t))

    def to_csv(self, path, model, duration: float, rate: float) -> Path:
        """Write ``t, q:<joint>..., v:<joint>..., a:<joint>...`` sampled at ``rate`` (robodyn's
        tabular format, :mod:`robodyn.io.log`)."""
        from ..io.log import write_log

        t, q, v, a = self.sample(duration, rate)
        return write_log(path, model, t, q, v=v, a=a)

    def plot(self, path, model, rate: float = 200.0) -> Path:
        """PNG of positions, velocities and accelerations over one period."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        t, q, qd, qdd = self.sample(self.period, rate)
        fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
        for ax, x, label in zip(axes, (q, qd, qdd), ("q [rad or m]", "v [/s]", "a [/s^2]")):
            for j in range(x.shape[1]):
                ax.plot(t, x[:, j], label=model.joint_names[j])
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        axes[0].legend(ncol=4, fontsize="small")
        axes[-1].set_xlabel("t [s]")
        axes[0].set_title(f"Excitation trajectory ({self.harmonics} harmonics, period {self.period:g} s)")
        fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=100)
        plt.close(fig)
        return Path(path)


@dataclass(frozen=True)
class Limits:
    """Per-joint bounds used by the optimisation: position ``lower``/``upper`` (already shrunk
    by the margin), ``velocity`` and ``acceleration`` (positive)."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def limits_of(model, acceleration=10.0, velocity=None, margin: float = 0.05, span: float = np.pi) -> Limits:
    """The model's limits for the optimisation: positions within ``[lower, upper]`` shrunk by
    ``margin`` of the range (joints without limits get ``+- span / 2``), velocities from
    ``model.velocity_limit`` (or ``velocity``, default 2 rad/s where the model has none), the
    given ``acceleration`` bound (scalar or (nv,), rad/s^2; models carry no acceleration
    limits)."""
    if np.any(model.joint_type == FREE):
        raise ValueError("excitation: a floating-base model has no joint limits to excite against; "
                         "use a fixed-base model")
    if np.any(model.joint_type == SPHERICAL):
        raise ValueError("excitation: Fourier trajectories drive joints of one dof; this model has a spherical joint")
    nv = model.nv
    lo, hi = model.lower.copy(), model.upper.copy()
    bounded = np.isfinite(lo) & np.isfinite(hi)
    lo, hi = np.where(bounded, lo, -span / 2), np.where(bounded, hi, span / 2)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo) * (1.0 - 2.0 * margin)
    vel = np.broadcast_to(np.asarray(velocity if velocity is not None else model.velocity_limit, float), (nv,)).copy()
    vel[~np.isfinite(vel)] = 2.0
    acc = np.broadcast_to(np.asarray(acceleration, dtype=float), (nv,)).copy()
    if np.any(~(vel > 0)) or np.any(~(acc > 0)) or np.any(~np.isfinite(acc)):
        raise ValueError(f"velocity and acceleration limits must be positive and finite, got {vel}, {acc}")
    return Limits(mid - half, mid + half, vel, acc)


def feasible_trajectory(model, *, period: float = 10.0, harmonics: int = 5, samples: int = 100,
                        limits: Limits | None = None, seed: int = 0) -> FourierTrajectory:
    """A random Fourier trajectory (standard normal coefficients, centred in the position
    range) scaled into the limits at ``samples`` points per period: the optimisation's
    starting point, or a validation motion."""
    lim = limits if limits is not None else limits_of(model)
    nv, L = model.nv, int(harmonics)
    t = np.arange(samples) * (period / samples)
    rng = np.random.default_rng(seed)
    x = np.concatenate([0.5 * (lim.lower + lim.upper), rng.standard_normal(2 * nv * L)])
    return _unpack(_into_limits(x, nv, L, period, t, lim), nv, L, period)


def _pack(traj: FourierTrajectory) -> np.ndarray:
    return np.concatenate([traj.q0, traj.a.ravel(), traj.b.ravel()])


def _unpack(x, nv, L, period):
    q0 = x[:nv]
    ab = x[nv:].reshape(2, nv, L)
    return FourierTrajectory(q0.copy(), ab[0].copy(), ab[1].copy(), period)


def _constraints(traj, t, lim: Limits):
    """Non-negative when every sample is within the limits (normalised per joint)."""
    q, qd, qdd = traj(t)
    return np.concatenate([
        (lim.upper - q.max(axis=0)) / (lim.upper - lim.lower),
        (q.min(axis=0) - lim.lower) / (lim.upper - lim.lower),
        1.0 - np.abs(qd).max(axis=0) / lim.velocity,
        1.0 - np.abs(qdd).max(axis=0) / lim.acceleration,
    ])


def condition_number(model, base, traj, t) -> float:
    """Condition number (2-norm) of the base regressor ``W`` stacked over the samples ``t``,
    from the eigenvalues of ``W^T W`` (r x r: cheap, and exact enough for condition numbers
    below about 1e7, the range that matters for a usable excitation)."""
    q, qd, qdd = traj(t)
    W = base.regressor(model, q, qd, qdd).reshape(-1, base.count)
    lam = np.linalg.eigvalsh(W.T @ W)
    return float(np.sqrt(lam[-1] / lam[0])) if lam[0] > 0 else float("inf")


@dataclass(frozen=True)
class ExcitationResult:
    trajectory: FourierTrajectory
    condition_number: float
    initial_condition_number: float
    iterations: int
    message: str


def optimize_excitation(model, base, *, period: float = 10.0, harmonics: int = 5, samples: int = 100,
                        limits: Limits | None = None, maxiter: int = 100, seed: int = 0) -> ExcitationResult:
    """A Fourier trajectory that minimises the condition number of ``base.regressor``.

    Args:
        base: :class:`~robodyn.identification.base.BaseParameters` (with the friction columns
            to be identified).
        period: period of the trajectory (s); harmonics: ``L``; samples: points per period
            where the regressor and the limits are evaluated.
        limits: :func:`limits_of` (default: the model's, acceleration 10 rad/s^2).
        maxiter: SLSQP iterations; seed: random initial coefficients.

    The initial guess is random coefficients scaled into the limits; the result is feasible
    at the samples (SLSQP keeps the best feasible iterate; if it ends infeasible the
    coefficients are scaled back into the limits).
    """
    from scipy.optimize import minimize

    lim = limits if limits is not None else limits_of(model)
    nv, L = model.nv, int(harmonics)
    if L < 1 or samples < 2 or period <= 0:
        raise ValueError(f"harmonics >= 1, samples >= 2 and period > 0 required, got {L}, {samples}, {period}")
    t = np.arange(samples) * (period / samples)
    x0 = _pack(feasible_trajectory(model, period=period, harmonics=L, samples=samples, limits=lim, seed=seed))
    init = condition_number(model, base, _unpack(x0, nv, L, period), t)

    def objective(x):
        c = condition_number(model, base, _unpack(x, nv, L, period), t)
        return np.log(c) if np.isfinite(c) else 1e3

    with one_blas_thread():
        res = minimize(objective, x0, method="SLSQP",
                       constraints=[{"type": "ineq", "fun": lambda x: _constraints(_unpack(x, nv, L, period), t, lim)}],
                       options={"maxiter": maxiter, "ftol": 1e-6})
    x = res.x if np.all(_constraints(_unpack(res.x, nv, L, period), t, lim) >= -1e-9) else \
        _into_limits(res.x, nv, L, period, t, lim)
    traj = _unpack(x, nv, L, period)
    cond = condition_number(model, base, traj, t)
    if not cond <= init:  # never return something worse than the feasible start
        traj, cond = _unpack(x0, nv, L, period), init
    return ExcitationResult(traj, cond, init, int(res.nit), str(res.message))


def _into_limits(x, nv, L, period, t, lim: Limits):
    """Scale the oscillating part of ``x`` (and clip the offsets) until every sample is
    inside the limits."""
    x = x.copy()
    x[:nv] = np.clip(x[:nv], lim.lower, lim.upper)
    for _ in range(200):
        traj = _unpack(x, nv, L, period)
        q, qd, qdd = traj(t)
        room = np.minimum(lim.upper - traj.q0, traj.q0 - lim.lower)
        swing = np.abs(q - traj.q0).max(axis=0)
        ratio = np.max([swing / np.maximum(room, 1e-12), np.abs(qd).max(axis=0) / lim.velocity,
                        np.abs(qdd).max(axis=0) / lim.acceleration], axis=0)
        if np.all(ratio <= 1.0):
            return x
        ab = x[nv:].reshape(2, nv, L)
        ab *= (0.99 / np.maximum(ratio, 1.0))[None, :, None]
        x[nv:] = ab.ravel()
    raise ValueError("excitation: could not bring the trajectory inside the limits")


def write_excitation(path, model, result: ExcitationResult, duration: float, rate: float = 100.0,
                     plot: bool = True) -> list[Path]:
    """CSV of the trajectory sampled at ``rate`` over ``duration`` (repeating the period), and
    a PNG plot next to it (same stem). Returns the paths written."""
    path = Path(path)
    out = [result.trajectory.to_csv(path, model, duration, rate)]
    if plot:
        out.append(result.trajectory.plot(path.with_suffix(".png"), model))
    return out

