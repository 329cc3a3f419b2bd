"""Dense Cholesky factorisation and triangular solves of small symmetric positive definite
matrices, in place, for the compiled kernels (the reduced mass matrix of a coupled model, the
Delassus matrix of the contact solver): ``M = L L^T``, then ``M^-1 b = L^-T (L^-1 b)``.
Reference: Golub and Van Loan, Matrix Computations (4th ed., 2013), Algorithm 4.2.1.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline


@inline
def cholesky(M):
    """``M = L L^T`` in place (the lower triangle becomes ``L``); False unless positive definite."""
    n = M.shape[0]
    for j in range(n):
        d = M[j, j]
        for k in range(j):
            d -= M[j, k] * M[j, k]
        if not d > 0.0:
            return False
        d = np.sqrt(d)
        M[j, j] = d
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= M[i, k] * M[j, k]
            M[i, j] = s / d
    return True


@inline
def forward(L, x):
    """``x <- L^-1 x`` (``L`` lower triangular)."""
    for i in range(x.shape[0]):
        s = x[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]


@inline
def backward(L, x):
    """``x <- L^-T x`` (``L`` lower triangular)."""
    for i in range(x.shape[0] - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, x.shape[0]):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
