"""Base parameters: the identifiable combinations of the inertial (and friction) parameters.

Only some combinations of the ``10 nb`` inertial parameters change the joint torques: a
parameter with no effect drops out, and columns of the regressor that are linear
combinations of others merge into them. With ``W`` the regressor stacked over many generic
states (``W theta = tau``), the base parameters are

    theta_base = K theta,      W = W_base K,       W_base = W[:, independent]

(Gautier, "Numerical calculation of the base inertial parameters of robots", J. Robotic
Systems 8(4), 1991; Khalil and Dombre, *Modeling, Identification and Control of Robots*,
2002, section 12.4.) The number of base parameters depends only on the kinematics (the
joint axes and placements and the direction of gravity), not on the parameter values.

Computation: the columns of ``W`` are scaled to unit norm (which changes no linear
dependency), the singular values of the scaled matrix give the rank ``r`` with the relative
tolerance ``rtol`` and the gap ``sigma_r / sigma_{r+1}``; the independent columns are then
chosen in the order of the parameters (body 1 first, ``[m, mx, my, mz, Ixx, Ixy, Iyy, Ixz,
Iyz, Izz]`` within a body), each kept when its distance to the span of the columns kept so far
exceeds ``rtol`` (Gram-Schmidt, twice orthogonalised, i.e. a QR factorisation in that
order). The parameters of a body are thereby grouped into those of the bodies nearer the
base, as in Khalil's symbolic regrouping (``Izz1 + 0.64 m2``). The coefficients of ``K`` come
from ``W[:, dependent] = W_base beta`` by least squares.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._deprecated import renamed_keywords
from ..algorithms.regressor import EXTRA_COLUMNS, extra_columns, regressor
from ..coupling import independent_q, joint_tree
from ..joints import NQ
from ..random import random_configuration
from ._blas import one_blas_thread

PARAMETER_NAMES = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")


def parameter_names(model, **extra) -> list[str]:
    """Names of the regressor columns: ``m1, mx1, ..., Izz1, m2, ...`` (body numbers from 1;
    ``mx = m cx``; inertias about the body origin), then the extra columns of
    :func:`robodyn.regressor` switched on in ``extra`` (``damping[joint]``, ...)."""
    names = [f"{p}{i + 1}" for i in range(model.nbodies) for p in PARAMETER_NAMES]
    return names + extra_columns(model, **extra)


def random_states(model, n: int, rng: np.random.Generator):
    """``n`` generic states: joint positions uniform within the limits (or in [-pi, pi]),
    velocities and accelerations standard normal (a model with mimic joints: its independent
    coordinates of the tree's)."""
    tree = joint_tree(model)
    q = random_configuration(tree, rng, n)
    for i in range(tree.nbodies):
        if NQ[tree.joint_type[i]] > 1:  # free, spherical and planar joints stay as drawn
            continue
        k, kv = tree.idx_q[i], tree.idx_v[i]
        lo, hi = tree.lower[kv], tree.upper[kv]
        if np.isfinite(lo) and np.isfinite(hi) and hi > lo:
            q[:, k] = rng.uniform(lo, hi, n)
    return independent_q(model, q), rng.standard_normal((n, model.nv)), rng.standard_normal((n, model.nv))


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a model (see the module docstring).

    ``columns`` (p,): names of the regressor columns (standard parameters); ``independent``
    (r,) and ``dependent`` (p - r,) column indices (zero columns are dependent, with all-zero
    coefficients); ``K`` (r, p) with ``theta_base = K theta``; ``names`` (r,): readable
    combinations; ``singular_values`` of the column-scaled stacked regressor; ``gap``:
    ``sigma_r / sigma_{r+1}`` (inf when the regressor has full column rank);
    ``extra``: the switches of the extra (friction, stiffness, armature, offset) columns.
    """

    columns: tuple
    independent: np.ndarray
    dependent: np.ndarray
    K: np.ndarray
    names: tuple
    singular_values: np.ndarray
    gap: float
    rtol: float
    extra: dict = field(default_factory=dict)

    @property
    def count(self) -> int:
        return int(self.independent.shape[0])

    def project(self, theta) -> np.ndarray:
        """``theta_base = K theta`` for (..., p) standard parameters."""
        return np.asarray(theta, dtype=float) @ self.K.T

    def regressor(self, model, q, v, a, **kw) -> np.ndarray:
        """The base regressor ``Y[..., independent]`` (..., nv, r) of the states."""
        return regressor(model, q, v, a, **self.extra, **kw)[..., self.independent]

    def completion(self, theta_base, theta_prior) -> np.ndarray:
        """Standard parameters closest to ``theta_prior`` (Euclidean) with ``K theta =
        theta_base``: ``theta_prior + K^+ (theta_base - K theta_prior)``. The dynamics (the
        torques of every motion) are those of ``theta_base``."""
        prior = np.asarray(theta_prior, dtype=float)
        return prior + np.linalg.pinv(self.K) @ (np.asarray(theta_base, dtype=float) - self.K @ prior)

    def summary(self) -> str:
        s = self.singular_values
        r = self.count
        lines = [f"{r} base parameters of {len(self.columns)} (relative tolerance {self.rtol:g}; "
                 f"singular values of the scaled regressor: sigma_{r} = {s[r - 1]:.3g}"
                 + (f", sigma_{r + 1} = {s[r]:.3g}, gap {self.gap:.3g})" if r < s.shape[0] else ", full rank)")]
        lines += [f"  {k + 1:>3}  {n}" for k, n in enumerate(self.names)]
        return "\n".join(lines)


def _combination_name(head: str, coeffs: np.ndarray, columns) -> str:
    parts = [head]
    for j in np.flatnonzero(coeffs):
        c = coeffs[j]
        sign = "-" if c < 0 else "+"
        mag = abs(c)
        parts.append(f"{sign} {columns[j]}" if abs(mag - 1.0) < 1e-9 else f"{sign} {mag:.6g}*{columns[j]}")
    return " ".join(parts)


def _independent_in_order(Ws, candidates, rtol: float) -> list:
    """Columns of ``Ws`` (unit norm) kept in order when farther than ``rtol`` from the span of
    those kept before (Gram-Schmidt, orthogonalised twice)."""
    basis = np.zeros((Ws.shape[0], 0))
    kept = []
    for j in candidates:
        w = Ws[:, j]
        for _ in range(2):
            w = w - basis @ (basis.T @ w)
        d = np.linalg.norm(w)
        if d > rtol:
            kept.append(int(j))
            basis = np.column_stack([basis, w / d])
    return kept


@renamed_keywords(viscous="damping")
def base_parameters(model, *, damping: bool = False, coulomb: bool = False, stiffness: bool = False,
                    armature: bool = False, offset: bool = False, n_states: int | None = None, rtol: float = 1e-8,
                    seed: int = 0) -> BaseParameters:
    """Base parameters of ``model`` from the regressor of ``n_states`` random states.

    Args:
        damping, coulomb, stiffness, armature, offset: include these extra columns (see
            :func:`robodyn.regressor`); they are identifiable with the inertial parameters.
            The springs' reference positions enter through the offsets (``-K q_ref``): identify
            them with ``stiffness=True, offset=True``. The stiffness columns of the dofs of free,
            spherical and planar joints are zero (no springs there) and drop out.
        n_states: number of random states (default: enough for 4 rows per column).
        rtol: relative tolerance on the singular values and on the distance of a column to
            the span of the ones kept.
        seed: seed of the random states.

    Raises:
        ValueError: when the rank from the singular values and the number of columns kept
            disagree (``rtol`` sits inside a cluster of singular values: no clear gap).
    """
    extra = dict(damping=bool(damping), coulomb=bool(coulomb), stiffness=bool(stiffness), armature=bool(armature),
                 offset=bool(offset))
    columns = tuple(parameter_names(model, **extra))
    p = len(columns)
    if model.nv == 0:
        raise ValueError("base_parameters: the model has no joints")
    if not 0 < rtol < 1:
        raise ValueError(f"rtol: expected a value in (0, 1), got {rtol}")
    n = n_states if n_states is not None else max(20, int(np.ceil(4 * p / model.nv)))
    q, v, a = random_states(model, n, np.random.default_rng(seed))
    W = regressor(model, q, v, a, **extra).reshape(-1, p)
    norms = np.linalg.norm(W, axis=0)
    scale = norms.max() if norms.size and norms.max() > 0 else 1.0
    nonzero = norms > rtol * scale
    Ws = np.zeros_like(W)
    Ws[:, nonzero] = W[:, nonzero] / norms[nonzero]
    with one_blas_thread():
        sv = np.linalg.svd(Ws, compute_uv=False)
    rank = int(np.sum(sv > rtol * sv[0])) if sv.size else 0
    with one_blas_thread():
        kept = _independent_in_order(Ws, np.flatnonzero(nonzero), rtol)
    if len(kept) != rank:
        raise ValueError(
            f"base_parameters: {rank} singular values above rtol={rtol:g} but {len(kept)} independent columns "
            f"found in order; singular values near the tolerance: {sv[max(rank - 2, 0):rank + 2].tolist()}; "
            "choose rtol inside the gap")
    ind = np.array(kept, dtype=np.int64)
    dep = np.array([j for j in range(p) if j not in set(kept)], dtype=np.int64)
    K = np.zeros((len(kept), p))
    K[np.arange(len(kept)), ind] = 1.0
    if dep.size:
        with one_blas_thread():
            beta = np.linalg.lstsq(W[:, ind], W[:, dep], rcond=None)[0]
        beta[np.abs(beta) < 1e-10 * max(1.0, np.abs(beta).max())] = 0.0
        K[:, dep] = beta
    names = tuple(_combination_name(columns[j], np.where(np.isin(np.arange(p), dep), K[r], 0.0), columns)
                  for r, j in enumerate(ind))
    gap = float(sv[rank - 1] / sv[rank]) if rank < sv.shape[0] and sv[rank] > 0 else float("inf")
    return BaseParameters(columns=columns, independent=ind, dependent=dep, K=K, names=names, singular_values=sv,
                          gap=gap, rtol=rtol, extra=extra)


__all__ = ["BaseParameters", "base_parameters", "parameter_names", "EXTRA_COLUMNS"]
