"""Straight-line code from the recursions: scalars as named intermediates.

An :class:`Emitter` offers the interface of :class:`._ring.TrigRing` that the recursions of
:mod:`._spatial`, :mod:`.crba` and :mod:`.newton_euler` use (``model``, ``revolute``,
``pos``, ``cos``, ``qd``, ``qdd``, ``zero``, ``const``, ``vec``, ``mat``, ``reduce`` and the
vector products), on small sympy expressions instead of polynomials. ``reduce`` (applied to
every entry a step computes) records the entry as an assignment ``x_k = expression`` and
returns the symbol ``x_k``, so nothing is ever expanded: each step is a few operations on the
names of the previous steps. Numbers fold as the recursion runs (sympy's automatic
evaluation: ``0 * x = 0``, ``1 * x = x``, ``x - x = 0``), so the zeros and ones of the
geometry, the axes and the inertial parameters cost nothing, and an expression met twice is
named once. Coordinate ``k`` enters as ``s_k``, ``c_k`` (revolute) or ``q_k`` (prismatic), as in
:class:`._ring.TrigRing`, and a mimic joint as the assignments of its ``sin``, ``cos`` or
``x`` from its source's (:meth:`._ring.VectorAlgebra.couple_joints`). This is the
"customised" symbolic evaluation of the recursive algorithms of W. Khalil, J.-F. Kleinfinger,
"Minimum operations and minimum parameters of the dynamic models of tree structure robots",
IEEE J. Robotics and Automation 3(6), 1987.
"""

from __future__ import annotations

import sympy as sp

from ._ring import VectorAlgebra, trig_names
from .model import SymbolicModel


class Emitter(VectorAlgebra):
    """Records the assignments of one evaluation of a recursion on ``model``. ``qd`` and
    ``qdd`` are the model's symbols, or zero when ``rates=False`` / ``accelerations=False``
    (their terms then fold away)."""

    def __init__(self, model: SymbolicModel, rates: bool = True, accelerations: bool = True):
        n = model.nv
        self.model = model
        self.revolute = [model.joint_type[b] == "revolute" for b in model.independent]
        self.pos = [trig_names(k)[0] if r else model.q[k] for k, r in enumerate(self.revolute)]
        self.cos = [trig_names(k)[1] if r else None for k, r in enumerate(self.revolute)]
        self.angle = list(model.q)
        self.zero, self.one = sp.S.Zero, sp.S.One
        self.qd = list(model.v) if rates else [self.zero] * n
        self.qdd = list(model.a) if accelerations else [self.zero] * n
        self.assignments = []
        self._names = {}
        self._symbols = sp.numbered_symbols("x", real=True)
        self.couple_joints()

    def reduce(self, e):
        """``e`` itself when it is a number or a (negated) symbol, else the name of an
        assignment ``x_k = e`` (one per distinct expression)."""
        e = sp.sympify(e)
        if e.is_Atom or (-e).is_Atom:
            return e
        if e in self._names:
            return self._names[e]
        if -e in self._names:
            return -self._names[-e]
        x = next(self._symbols)
        self.assignments.append((x, e))
        self._names[e] = x
        return x

    def const(self, e):
        """A model entry (number, symbol or expression in the parameters)."""
        return self.reduce(e)

    def vec(self, v) -> list:
        return [self.const(x) for x in v]

    def mat(self, m) -> list:
        return [[self.const(m[r, c]) for c in range(3)] for r in range(3)]

    def trig(self) -> list:
        """``(s_k, c_k, q_k)`` of each revolute joint."""
        return [(self.pos[k], self.cos[k], self.model.q[k]) for k in range(self.model.nv) if self.revolute[k]]
