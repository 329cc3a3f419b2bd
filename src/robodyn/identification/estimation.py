"""Estimation of the base parameters from measured torques.

With the base regressor stacked over the samples, ``W beta = y + noise`` (``y`` the measured
joint torques, ``beta = K theta`` the base parameters, friction columns included; ``n = N nv``
equations for ``r`` parameters):

* ``ols``: ordinary least squares ``beta = W^+ y``, with ``cov = s^2 (W^T W)^+`` and
  ``s^2 = |y - W beta|^2 / (n - r)``; per joint ``sigma_j^2 = |y_j - W_j beta|^2 / (N - r / nv)``;
* ``wls``: weighted least squares with one standard deviation per joint estimated from the
  residuals of that joint (OLS first, then reweighted) (Gautier, "Dynamic identification of robots with power model",
  ICRA 1997; Khalil and Dombre 2002, section 12.5), ``cov = (W^T S^-1 W)^+``;
* ``physical``: the standard parameters ``theta(x)`` of physically consistent bodies, with
  each body's 4 x 4 pseudo-inertia ``J = [[Sigma, h], [h^T, m]]`` (``Sigma = tr(I)/2 1 - I``)
  written as ``J = U U^T``, ``U`` upper triangular with exponentiated diagonal (the
  log-Cholesky parameterisation of Rucker and Wensing, "Smooth parameterization of rigid-body
  inertia", IEEE RA-L 7(2), 2022), so that ``m > 0`` and ``J`` is positive definite for every
  ``x``; friction, stiffness and armature coefficients are bounded below by 0.
  ``scipy.optimize.least_squares`` solves ``min |W K theta(x) - y|^2 + w |P (theta(x) -
  theta_prior)|^2``, through the triangular factor of ``[W y]`` (``r`` rows whatever the
  number of samples); ``P = 1 - K^+ K`` projects on the unobservable directions, so the
  prior (the nominal model) only fixes what the torques cannot tell and does not bias the
  base parameters.

All three work on the reduced statistics of the samples (:class:`.reduced.Reduced`: the
triangular factor ``R_j`` of ``[W_j y_j]`` per joint, of any number of logs combined), never on
``W`` itself: with ``[R_w z; 0 rho]`` the triangular factor of the stacked (and, for WLS,
weighted) ``[R_1; ...; R_nv]``, ``beta`` solves ``R_w beta = z`` (``numpy.linalg.lstsq``:
the minimum-norm solution, as for ``W``, when the columns are dependent), ``W^T S W = R_w^T
R_w`` and the residual of joint ``j`` is ``|R_j [beta; -1]|^2`` (exact, not an approximation).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._blas import one_blas_thread
from .base import BaseParameters
from .reduced import Reduced


@dataclass(frozen=True)
class Estimate:
    """``beta`` (r,) base parameters and their standard deviations ``std`` (r,); ``theta``:
    full standard parameters ``[inertial (10 nb), extra columns]`` (only for ``physical``,
    else None); ``sigma`` (nv,) residual standard deviation per joint; ``method``."""

    method: str
    beta: np.ndarray
    std: np.ndarray
    sigma: np.ndarray
    theta: np.ndarray | None = None

    @property
    def relative_std(self) -> np.ndarray:
        """``std / |beta|`` in percent (inf where beta is 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return 100.0 * self.std / np.abs(self.beta)


def _as_reduced(stats, y, nv) -> Reduced:
    """``stats`` itself, or the reduced statistics of a stacked regressor ``stats`` with ``y``, ``nv``."""
    if isinstance(stats, Reduced):
        if y is not None or nv is not None:
            raise TypeError("y and nv go with a stacked regressor W, not with reduced statistics")
        return stats
    if y is None or nv is None:
        raise TypeError(f"expected Reduced statistics, or a stacked regressor W with y and nv; got "
                        f"{type(stats).__name__}{'' if y is None else ' and y'}{'' if nv is None else ' and nv'}")
    return Reduced.from_rows(stats, y, nv)


def _fit(stats: Reduced, scale=None):
    """``(beta, F)``: the least-squares ``beta`` of the rows of joint ``j`` weighted by ``scale[j]``
    (minimum norm when rank deficient) and ``F`` (r + 1, r + 1), the triangular factor of the
    weighted stacked ``[W y]`` (``beta`` solves ``F[:r, :r] beta = F[:r, r]``)."""
    F = stats.stacked(scale)
    r = stats.count
    return np.linalg.lstsq(F[:r, :r], F[:r, r], rcond=None)[0], F


def _cov_std(Rw, s2=1.0):
    """``sqrt(diag((R_w^T R_w)^+) s2)``: standard deviations of ``cov = s2 (W^T S W)^+``."""
    return np.sqrt(np.maximum(np.diag(np.linalg.pinv(Rw.T @ Rw)) * s2, 0.0))


def _sigma(stats: Reduced, res) -> np.ndarray:
    """Residual standard deviation per joint, ``sqrt(res_j / max(N - r / nv, 1))``."""
    return np.sqrt(res / max(stats.samples - stats.count / stats.nv, 1))


def ols(stats, y=None, nv: int | None = None) -> Estimate:
    """Ordinary least squares (module docstring) of reduced statistics ``stats``
    (:class:`.reduced.Reduced`), or of a stacked regressor ``W`` (N nv, r) with torques ``y``
    (N nv,) and ``nv`` (reduced first)."""
    stats = _as_reduced(stats, y, nv)
    n, r = stats.rows, stats.count
    if n <= r:
        raise ValueError(f"ols: {n} equations for {r} base parameters; record a longer log")
    beta, F = _fit(stats)
    res = stats.residuals(beta)
    return Estimate("ols", beta, _cov_std(F[:r, :r], float(res.sum()) / (n - r)), _sigma(stats, res))


def wls(stats, y=None, nv: int | None = None, iterations: int = 10) -> Estimate:
    """Weighted least squares, one weight ``1 / sigma_j`` per joint (the rows ``R_j / sigma_j``),
    the ``sigma_j`` estimated from the residuals: first of OLS, then of the weighted estimate
    again until they change by less than 1 % (iteratively reweighted, ``iterations`` at most).
    ``sigma_j`` is kept above ``1e-12`` times the largest RMS joint torque (exact data).
    Arguments as :func:`ols`."""
    stats = _as_reduced(stats, y, nv)
    est = ols(stats)
    floor = 1e-12 * max(float(stats.torque_rms().max()), 1e-300)
    r = stats.count
    for _ in range(iterations):
        sigma = np.maximum(est.sigma, floor)
        beta, F = _fit(stats, 1.0 / sigma)
        new = _sigma(stats, stats.residuals(beta))
        est = Estimate("wls", beta, _cov_std(F[:r, :r]), new)
        if np.all(np.abs(new - sigma) <= 0.01 * sigma):
            break
    return est


# -- physically consistent estimation ------------------------------------------------------
def pseudo_inertia(theta) -> np.ndarray:
    """4 x 4 pseudo-inertia ``[[tr(I)/2 1 - I, h], [h^T, m]]`` of 10 parameters."""
    m, h = theta[0], theta[1:4]
    I = np.array([[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]])
    J = np.empty((4, 4))
    J[:3, :3] = 0.5 * np.trace(I) * np.eye(3) - I
    J[:3, 3] = J[3, :3] = h
    J[3, 3] = m
    return J


def parameters_of_pseudo_inertia(J) -> np.ndarray:
    """10 parameters of a pseudo-inertia: ``I = tr(Sigma) 1 - Sigma``."""
    S = J[:3, :3]
    I = np.trace(S) * np.eye(3) - S
    return np.array([J[3, 3], J[0, 3], J[1, 3], J[2, 3], I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]])


def log_cholesky(theta, eps: float = 1e-9) -> np.ndarray:
    """``[alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3]`` with ``J = U U^T``,
    ``U = e^alpha [[e^d1, s12, s13, t1], [0, e^d2, s23, t2], [0, 0, e^d3, t3], [0, 0, 0, 1]]``.
    A semi-definite ``J`` (point mass, zero mass) is regularised by ``eps`` times its scale."""
    J = pseudo_inertia(theta)
    J = J + eps * max(np.abs(J).max(), 1e-6) * np.eye(4)
    P = np.eye(4)[::-1]
    U = P @ np.linalg.cholesky(P @ J @ P) @ P  # upper triangular, U U^T = J
    e = U[3, 3]
    V = U / e
    return np.array([np.log(e), np.log(V[0, 0]), np.log(V[1, 1]), np.log(V[2, 2]), V[0, 1], V[1, 2], V[0, 2],
                     V[0, 3], V[1, 3], V[2, 3]])


def _upper_factor(x) -> np.ndarray:
    alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3 = x
    return np.exp(alpha) * np.array([[np.exp(d1), s12, s13, t1], [0.0, np.exp(d2), s23, t2],
                                     [0.0, 0.0, np.exp(d3), t3], [0.0, 0.0, 0.0, 1.0]])


# entry of U that each coordinate after alpha scales (d1, d2, d3 exponentiated, the rest linear)
_ENTRIES = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))


def theta_of_log_cholesky(x) -> np.ndarray:
    """10 inertial parameters of the log-Cholesky coordinates (see :func:`log_cholesky`)."""
    U = _upper_factor(x)
    return parameters_of_pseudo_inertia(U @ U.T)


def theta_jacobian(x) -> np.ndarray:
    """``d theta / d x`` (10, 10) of :func:`theta_of_log_cholesky`: ``dJ = dU U^T + U dU^T``."""
    U = _upper_factor(x)
    out = np.empty((10, 10))
    dU = U.copy()  # d U / d alpha = U
    for k in range(10):
        if k > 0:
            dU = np.zeros((4, 4))
            r, c = _ENTRIES[k - 1]
            dU[r, c] = U[r, c] if k <= 3 else np.exp(x[0])
        dJ = dU @ U.T
        out[:, k] = parameters_of_pseudo_inertia(dJ + dJ.T)
    return out


# log-Cholesky coordinates kept within +-LOG_BOUND: masses and inertias within e^(+-2 LOG_BOUND)
LOG_BOUND = 25.0


def nearest_consistent(theta, eps: float = 1e-6) -> np.ndarray:
    """A physically consistent body near ``theta``: the pseudo-inertia's eigenvalues raised to at
    least ``eps`` times the largest (and a positive mass)."""
    lam, V = np.linalg.eigh(pseudo_inertia(theta))
    floor = eps * max(lam[-1], 1e-9)
    return parameters_of_pseudo_inertia((V * np.maximum(lam, floor)) @ V.T)


def physical(model, base: BaseParameters, stats: Reduced, prior, *, prior_weight: float = 1e-8, start=None,
             max_nfev: int = 200) -> Estimate:
    """Physically consistent least squares (module docstring) of reduced statistics ``stats``
    (:class:`.reduced.Reduced`; ``Reduced.from_rows(W, y, nv)`` of a stacked regressor).

    ``prior`` (p,): standard parameters ``[theta, extra]`` the unobservable directions are
    drawn to (usually the nominal model); ``start``: initial standard parameters (default: the
    least-squares estimate completed towards the prior, each body moved to the nearest
    consistent one). Friction columns (damping, Coulomb), stiffness and armature are bounded
    below by 0.
    The Jacobian is analytic (block diagonal ``d theta / d x``, :func:`theta_jacobian`);
    ``scipy.optimize.least_squares`` (trust region reflective, for the bounds) evaluates the
    residual at most ``max_nfev`` times.
    """
    from scipy.optimize import least_squares

    if not isinstance(stats, Reduced):
        raise TypeError(f"physical: expected Reduced statistics (Reduced.from_rows(W, y, nv) of a stacked "
                        f"regressor), got {type(stats).__name__}")
    r = base.count
    if stats.count != r or stats.nv != model.nv:
        raise ValueError(f"physical: reduced statistics of (nv, r) = ({stats.nv}, {stats.count}), the model and its "
                         f"base parameters have ({model.nv}, {r})")
    nb, p = model.nbodies, base.K.shape[1]
    prior = np.asarray(prior, dtype=float)
    if prior.shape != (p,):
        raise ValueError(f"prior: expected shape ({p},), got {prior.shape}")
    beta_ls, F = _fit(stats)
    if start is None:
        start = base.completion(beta_ls, prior)
        start[:10 * nb] = np.concatenate([nearest_consistent(start[10 * i:10 * i + 10]) for i in range(nb)])
    start = np.asarray(start, dtype=float)
    if start.shape != (p,):
        raise ValueError(f"start: expected shape ({p},), got {start.shape}")
    # |W beta - y|^2 = |R beta - z|^2 + const with [W y] = Q [[R, z], [0, rho]]: r rows, not N nv
    A, z = F[:r, :r] @ base.K, F[:r, r]
    reg = np.sqrt(prior_weight) * max(float(np.linalg.norm(A, axis=0).mean()), 1e-12)
    N = np.eye(p) - np.linalg.pinv(base.K) @ base.K  # projector on the unobservable directions
    x0 = np.concatenate([np.concatenate([log_cholesky(start[10 * i:10 * i + 10]) for i in range(nb)]),
                         start[10 * nb:]])
    lower, upper = np.full(p, -np.inf), np.full(p, np.inf)
    logs = [10 * i + k for i in range(nb) for k in range(4)]
    lower[logs], upper[logs] = -LOG_BOUND, LOG_BOUND
    nonneg = [10 * nb + k for k, name in enumerate(base.columns[10 * nb:])
              if name.split("[")[0] in ("damping", "coulomb", "stiffness", "armature")]
    lower[nonneg] = 0.0
    x0 = np.clip(x0, lower + 1e-9, upper - 1e-9)

    def theta_of(x):
        return np.concatenate([np.concatenate([theta_of_log_cholesky(x[10 * i:10 * i + 10]) for i in range(nb)]),
                               x[10 * nb:]])

    def jac_theta(x):
        D = np.eye(p)
        for i in range(nb):
            D[10 * i:10 * i + 10, 10 * i:10 * i + 10] = theta_jacobian(x[10 * i:10 * i + 10])
        return D

    def residual(x):
        th = theta_of(x)
        return np.concatenate([A @ th - z, reg * (N @ (th - prior))])

    def jacobian(x):
        D = jac_theta(x)
        return np.vstack([A @ D, reg * (N @ D)])

    with one_blas_thread():
        x = least_squares(residual, x0, jac=jacobian, bounds=(lower, upper), method="trf", max_nfev=max_nfev,
                          xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    theta = theta_of(x)
    beta = base.K @ theta
    res = stats.residuals(beta)
    s2 = float(res.sum()) / max(stats.rows - r, 1)
    std = _cov_std(F[:r, :r], s2)  # linearised: the least-squares covariance at the solution
    return Estimate("physical", beta, std, _sigma(stats, res), theta)
