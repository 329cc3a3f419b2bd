"""NumPy or sympy: the few 3-vector and 3 x 3 matrix operations that robodyn's helpers run on
numbers and on symbols alike (:mod:`robodyn.inertia`, :func:`robodyn.from_poe`). Matrix
products use ``@``, which both libraries define."""

from __future__ import annotations

import numpy as np


def is_symbolic(*arrays) -> bool:
    """Whether any entry of the arguments (numbers, sequences, arrays, matrices) is a sympy object."""
    return any(type(x).__module__.split(".")[0] == "sympy"
               for a in arrays for x in np.asarray(a, dtype=object).ravel())


class Algebra:
    """Vectors (3,) and matrices in NumPy (floats, checked finite) or in sympy (exact)."""

    def __init__(self, symbolic: bool):
        self.symbolic = symbolic
        if symbolic:
            import sympy as sp

            self.sp = sp

    def vector(self, x, what: str):
        """``x`` as a 3-vector (a (3,) array or a 3 x 1 sympy matrix); ``ValueError`` naming ``what``."""
        if self.symbolic:
            items = list(x)
            v = self.sp.Matrix(3, 1, items) if len(items) == 3 else None
        else:
            v = np.asarray(x, dtype=float)
            v = v if v.shape == (3,) and np.all(np.isfinite(v)) else None
        if v is None:
            raise ValueError(f"{what}: expected 3 finite numbers, got {x!r}")
        return v

    def matrix(self, x, what: str, shape=(3, 3)):
        """``x`` as a matrix of ``shape``; ``ValueError`` naming ``what``."""
        if self.symbolic:
            m = self.sp.Matrix(x)
            ok = tuple(m.shape) == shape
        else:
            m = np.asarray(x, dtype=float)
            ok = m.shape == shape and bool(np.all(np.isfinite(m)))
        if not ok:
            raise ValueError(f"{what}: expected a finite {shape[0]} x {shape[1]} matrix, got {x!r}")
        return m

    def eye(self):
        return self.sp.eye(3) if self.symbolic else np.eye(3)

    def outer(self, u):
        return u @ u.T if self.symbolic else np.outer(u, u)

    def dot(self, a, b):
        return (a.T @ b)[0] if self.symbolic else float(a @ b)

    def cross(self, a, b):
        return a.cross(b) if self.symbolic else np.cross(a, b)

    def is_zero(self, a, tol: float) -> bool:
        """Every entry zero (sympy: exactly, after simplification; NumPy: norm within ``tol``)."""
        if self.symbolic:
            return all(self.sp.simplify(x) == 0 for x in a)
        return bool(np.linalg.norm(a) <= tol)

    def simplify(self, x):
        return x.applyfunc(self.sp.simplify) if self.symbolic else x
