"""Reduced statistics of identification data: one triangular factor per joint.

With ``W_j`` (N, r) the rows of the base regressor for joint ``j`` (one per sample) and
``y_j`` (N,) that joint's measured torques,

    [W_j  y_j] = Q_j R_j,        R_j (r + 1, r + 1) upper triangular,

so ``R_j^T R_j = [W_j y_j]^T [W_j y_j]``: the factor keeps exactly ``W_j^T W_j``, ``W_j^T y_j``
and ``y_j^T y_j``, without forming them (which would square the condition number). Every
quantity of the estimators (:mod:`.estimation`) follows from the ``R_j``:

* ``|W_j b - y_j|^2 = |R_j [b; -1]|^2`` for every ``b``: the residual of each joint, exactly;
* the triangular factor of ``[R_1 s_1; ...; R_nv s_nv]`` (``s_j`` a weight per joint) is that
  of the weighted stacked ``[W y]``: its leading r x r block ``R_w`` has the singular values
  of ``W`` (the condition number), ``R_w^T R_w = W^T S W`` (the covariances), and
  ``R_w beta = z`` (its last column) the least-squares normal equations, solved stably.

Samples are absorbed a block at a time by the QR of ``[R_j; W_j' y_j']`` (memory: one
block's regressor, whatever the length of the log), and two reduced objects combine by the QR
of their stacked factors, in any order or tree: the tall-skinny QR (TSQR) of Demmel, Grigori,
Hoemmen and Langou, "Communication-optimal parallel and sequential QR and LU
factorizations", SIAM J. Sci. Comput. 34(1), 2012. Each factor is made unique by rows
scaled to a nonnegative diagonal (the Cholesky factor of ``[W_j y_j]^T [W_j y_j]`` when that
is definite). The rows of the stacked ``W`` are ordered sample by sample (``k nv + j`` for
sample ``k``, joint ``j``), as :func:`stack` builds them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import BaseParameters
from .data import Log

BLOCK = 4096  # samples whose regressor is held at once by Reduced.from_log


def stack(model, base: BaseParameters, log: Log):
    """``(W, y)``: the base regressor (N nv, r) and the torques (N nv,) of a log whose
    ``v``, ``a`` and ``tau`` are known (see ``data.preprocess``)."""
    if log.v is None or log.a is None or log.tau is None:
        raise ValueError("the log needs velocities, accelerations and torques; run preprocess() first")
    W = base.regressor(model, log.q, log.v, log.a)
    return W.reshape(-1, base.count), log.tau.reshape(-1)


def check_block(block) -> int:
    """``block`` as a positive ``int`` (samples per block), else ``ValueError``."""
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 1:
        raise ValueError(f"block: expected a positive integer, got {block!r}")
    return int(block)


def triangular(M) -> np.ndarray:
    """The R of the QR of each ``M[j]`` ((..., m, n), ``m >= n``) with a nonnegative diagonal:
    (..., n, n)."""
    R = np.linalg.qr(M, mode="r")
    sign = np.sign(np.diagonal(R, axis1=-2, axis2=-1))
    return R * np.where(sign == 0, 1.0, sign)[..., :, None]


@dataclass(frozen=True, eq=False)
class Reduced:
    """Reduced statistics (module docstring): ``R`` (nv, r + 1, r + 1), the upper triangular
    factor of ``[W_j y_j]`` per joint ``j``, and the number of ``samples`` (N: the rows of
    each joint). Combine two with :meth:`combine` or ``+``."""

    R: np.ndarray
    samples: int

    def __post_init__(self):
        R = np.asarray(self.R, dtype=float)
        if R.ndim != 3 or R.shape[1] != R.shape[2] or R.shape[1] < 2:
            raise ValueError(f"Reduced: R must have shape (nv, r + 1, r + 1) with r >= 1, got {R.shape}")
        if int(self.samples) != self.samples or self.samples < 0:
            raise ValueError(f"Reduced: samples must be a nonnegative integer, got {self.samples}")
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "samples", int(self.samples))

    @property
    def nv(self) -> int:
        return int(self.R.shape[0])

    @property
    def count(self) -> int:
        """The number ``r`` of regressor columns (base parameters)."""
        return int(self.R.shape[1] - 1)

    @property
    def rows(self) -> int:
        """Equations ``N nv`` of the stacked regressor."""
        return self.samples * self.nv

    @classmethod
    def empty(cls, nv: int, count: int) -> "Reduced":
        """No samples: zero factors (the neutral element of :meth:`combine`)."""
        return cls(np.zeros((nv, count + 1, count + 1)), 0)

    @classmethod
    def from_rows(cls, W, y, nv: int) -> "Reduced":
        """Of a stacked regressor ``W`` (N nv, r) and torques ``y`` (N nv,), rows ordered
        sample by sample (:func:`stack`)."""
        W = np.asarray(W, dtype=float)
        if W.ndim != 2:
            raise ValueError(f"W: expected a matrix (N nv, r), got shape {W.shape}")
        return cls.empty(nv, W.shape[1]).absorb(W, y)

    @classmethod
    def from_log(cls, model, base: BaseParameters, log: Log, *, block: int = BLOCK) -> "Reduced":
        """Of a log with ``v``, ``a`` and ``tau`` (``data.preprocess``), its regressor computed
        ``block`` samples at a time (memory: one block's regressor)."""
        block = check_block(block)
        out = cls.empty(model.nv, base.count)
        for k in range(0, max(len(log), 1), block):  # an empty log too: stack checks its columns
            out = out.absorb(*stack(model, base, log.rows(slice(k, k + block))))
        return out

    def absorb(self, W, y) -> "Reduced":
        """With the samples of ``W`` (B nv, r) and ``y`` (B nv,) added (rows ordered sample by
        sample): the QR of ``[R_j; W_j y_j]`` per joint."""
        W, y = np.asarray(W, dtype=float), np.asarray(y, dtype=float)
        nv, r = self.nv, self.count
        if W.ndim != 2 or W.shape[1] != r or W.shape[0] % nv or y.shape != (W.shape[0],):
            raise ValueError(f"expected W (B nv, r) = (B {nv}, {r}) and y (B nv,), got {W.shape} and {y.shape}")
        n = W.shape[0] // nv
        rows = np.concatenate([W.reshape(n, nv, r), y.reshape(n, nv, 1)], axis=2).transpose(1, 0, 2)
        return Reduced(triangular(np.concatenate([self.R, rows], axis=1)), self.samples + n)

    def combine(self, other: "Reduced") -> "Reduced":
        """The reduced statistics of both sets of samples: QR of the stacked factors."""
        if not isinstance(other, Reduced):
            raise TypeError(f"combine: expected Reduced, got {type(other).__name__}")
        if other.R.shape != self.R.shape:
            raise ValueError(f"combine: reduced statistics of different sizes (nv, r) = ({self.nv}, {self.count}) "
                             f"and ({other.nv}, {other.count})")
        return Reduced(triangular(np.concatenate([self.R, other.R], axis=1)), self.samples + other.samples)

    def __add__(self, other):
        return self.combine(other) if isinstance(other, Reduced) else NotImplemented

    def stacked(self, scale=None) -> np.ndarray:
        """(r + 1, r + 1): the triangular factor of all joints' rows, joint ``j``'s multiplied
        by ``scale[j]`` (default 1): the QR of ``[R_1 s_1; ...; R_nv s_nv]``."""
        R = self.R if scale is None else self.R * np.asarray(scale, dtype=float).reshape(self.nv, 1, 1)
        return triangular(R.reshape(-1, self.count + 1))

    def residuals(self, beta) -> np.ndarray:
        """(nv,): ``|W_j beta - y_j|^2 = |R_j [beta; -1]|^2`` per joint."""
        e = self.R @ np.append(np.asarray(beta, dtype=float), -1.0)
        return np.einsum("ji,ji->j", e, e)

    def torque_rms(self) -> np.ndarray:
        """(nv,): root-mean-square torque ``|y_j| / sqrt(N)`` of each joint (0 without samples)."""
        return np.linalg.norm(self.R[:, :, -1], axis=1) / np.sqrt(max(self.samples, 1))


def combine(a: Reduced, b: Reduced) -> Reduced:
    """``a + b`` as a module-level function (a task of a distributed tree reduction)."""
    return a.combine(b)


__all__ = ["Reduced", "combine", "stack", "triangular", "check_block", "BLOCK"]
