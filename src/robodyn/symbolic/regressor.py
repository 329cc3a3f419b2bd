"""The symbolic regressor ``Y(q, v, a)`` with ``tau = Y theta``.

The joint forces of the rigid bodies are linear in the inertial parameters
``theta = [m1, mx1, my1, mz1, Ixx1, Ixy1, Iyy1, Ixz1, Iyz1, Izz1, m2, ...]`` (about each
body origin, robodyn's order; :func:`.model.with_inertia_symbols`). The model's parameters
are made symbols, ``tau`` is derived exactly (:mod:`.newton_euler` or :mod:`.lagrange`), and
``Y_ij = d tau_i / d theta_j``. Armature, friction and joint springs are not inertial parameters and
are not in ``Y``: ``rnea(model, q, v, a, friction=False, armature=False) = Y theta`` (the
numeric :func:`robodyn.regressor` has columns for them). With mimic joints (a
:class:`robodyn.CoupledModel`, :mod:`.mimic`) ``Y = G^T Y_full(P q + offset, G v, G a)``, n rows
for the independent coordinates and the 10 columns of every body of the full tree, as
``robodyn.regressor(coupled, q, v, a)`` without its extra columns.
Reference: W. Khalil, E. Dombre, *Modeling, Identification and Control of Robots*, Hermes
2002, chapter 12.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from .._deprecated import renamed_attribute
from . import codegen
from .equations import METHODS
from ._ring import TrigRing
from .model import from_model, with_inertia_symbols


class Regressor:
    """``Y`` (n x 10 nbodies) and ``theta`` (10 nbodies) of ``tau = Y theta``."""

    def __init__(self, model, method: str, rg: TrigRing, Y: list):
        self.model = model
        self.method = method
        self.theta = model.inertial_parameters()
        self.q, self.v, self.a = model.q, model.v, model.a
        self.parameters = [s for s in model.parameters() if s not in set(self.theta)]
        self._rg = rg
        self._Y = Y

    qd = renamed_attribute("qd", "v")
    qdd = renamed_attribute("qdd", "a")

    @cached_property
    def Y(self) -> sp.Matrix:
        """The regressor matrix (n x 10 nbodies), sympy expressions in q, v, a."""
        rows = [[self._rg.expr(p) for p in row] for row in self._Y]
        return sp.Matrix(rows)

    def program(self) -> codegen.Program:
        rg, n = self._rg, self.model.nv
        flat = [p for row in self._Y for p in row]
        exprs = None if sum(len(p) for p in flat) > codegen.CSE_TERMS else [rg.expr(p, "symbols") for p in flat]
        args = [("q", list(self.q)), ("v", list(self.v)), ("a", list(self.a))]
        if self.parameters:
            args.append(("params", list(self.parameters)))
        trig = [(*rg.trig_names(k), self.q[k]) for k in range(n) if rg.revolute[k]]
        doc = f"{self.model.name}: regressor Y(q, v, a), ({n}, {len(self.theta)}), tau = Y theta"
        return codegen.program("Y", exprs, (n, len(self.theta)), args, trig, doc, polys=flat,
                               values=rg.generator_values())

    def to_function(self):
        """NumPy function ``Y(q, v, a)``, batched: ``(..., n, 10 nbodies)``."""
        return codegen.numpy_function(self.program())

    def to_numba(self):
        """Numba-compiled ``Y(q, v, a)``."""
        return codegen.numba_function(self.program())


def regressor(model, method: str = "newton_euler") -> Regressor:
    """The regressor of ``model`` (numeric, coupled or symbolic; its inertial parameters are
    replaced by the symbols ``m1, mx1, ...``, its armature, friction and springs left out)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)}, got {method!r}")
    sm = with_inertia_symbols(from_model(model)).rigid()
    rg = TrigRing(sm)
    tau = METHODS[method](rg)["tau"]
    theta = [rg.const(t) for t in sm.inertial_parameters()]
    Y = [[t.diff(th) for th in theta] for t in tau]
    return Regressor(sm, method, rg, Y)
