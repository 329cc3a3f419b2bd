"""Closed-form equations of motion ``M(q) a + C(q, v) v + g(q) = tau``.

:func:`equations_of_motion` derives them by the energy route (:mod:`.lagrange`) or the
recursive Newton-Euler route (:mod:`.newton_euler`) in exact trigonometric polynomials
(:mod:`._ring`), and returns :class:`EquationsOfMotion` with the terms as sympy expressions
in ``q = (q1, ...)``, ``v = (qd1, ...)``, ``a = (qdd1, ...)`` (the joint velocities and
accelerations, named as everywhere in robodyn; their symbols print as q-dot, q-double-dot):

    M    (n, n)  mass matrix, with the joints' armature on the diagonal
    C    (n, n)  Christoffel matrix C_ij = sum_k Gamma_ijk v_k,
                 Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2, so Mdot - 2C is
                 skew-symmetric (as robodyn.coriolis_matrix)
    C_v  (n,)    C v, the Coriolis and centrifugal forces
    g    (n,)    gravity forces dU/dq (as robodyn.gravity)
    T, U, L      kinetic energy v^T M v / 2, potential energy -sum m_i g . p_ci, T - U
    tau  (n,)    M a + C v + g (as robodyn.rnea without friction)

Friction is not part of these terms. Expressions of up to ``TRIG_TERMS`` terms are rewritten
with the angle-sum rules (sympy's ``TR10i``: ``c1 c2 - s1 s2 = cos(q1 + q2)``); all stay
otherwise in the canonical expanded form (no ``simplify`` or ``trigsimp`` on big
expressions, which is what makes other tools take hours). Code generation
(:meth:`EquationsOfMotion.to_function`, ``to_numba``, ``to_c``) writes ``M``, ``C_v``,
``g`` and ``tau`` by default as the straight-line code of the recursions (:mod:`.recursive`:
not expanded, fast to compile and to run) and the other terms, or every term with
``form="expanded"``, as the expanded expressions after common-subexpression elimination.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp
from sympy.simplify.fu import TR10i

from .._deprecated import renamed_attribute
from . import codegen, lagrange, newton_euler
from ._ring import TrigRing, readable_numbers
from ._terms import GeneratedCode, check_form, check_term, signature
from .model import SymbolicModel, from_model
from .recursive import RECURSIONS, recursive_program

METHODS = {"lagrange": lagrange.derive, "newton_euler": newton_euler.derive}
# Expressions with at most this many terms are rewritten with the angle-sum rules.
TRIG_TERMS = 16



def christoffel_matrix(rg: TrigRing, M) -> list:
    """``C_ij = sum_k Gamma_ijk qd_k`` with the Christoffel symbols of the first kind of ``M``."""
    n = len(M)
    dM = [[[rg.dq(M[i][j], k) for k in range(n)] for j in range(n)] for i in range(n)]
    return [[sum(((dM[i][j][k] + dM[i][k][j] - dM[j][k][i]) * rg.qd[k] for k in range(n)), rg.zero) / 2
             for j in range(n)] for i in range(n)]


def christoffel_from_quadratic(rg: TrigRing, quad, n: int) -> list:
    """``C`` from the quadratic part ``sum_jk Gamma_ijk qd_j qd_k`` of each ``tau_i``, with
    ``Gamma_ijk`` symmetric in ``j, k`` (a ``qd_j qd_k`` term, ``j != k``, holds ``2 Gamma_ijk``)."""
    C = [[rg.zero.copy() for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for mon, cf in quad[i].items():
            js = [j for j in range(n) if mon[rg.qd_index[j]]]
            if len(js) == 1:  # qd_j^2: Gamma_ijj
                j = js[0]
                m = list(mon)
                m[rg.qd_index[j]] -= 1
                C[i][j] += rg.ring.term_new(tuple(m), cf)
            else:  # qd_j qd_k: Gamma_ijk = Gamma_ikj = cf / 2
                j, k = js
                for a, b in ((j, k), (k, j)):
                    m = list(mon)
                    m[rg.qd_index[a]] -= 1  # C_ia = sum_b Gamma_iab qd_b
                    C[i][a] += rg.ring.term_new(tuple(m), cf / 2)
    return C


class EquationsOfMotion(GeneratedCode):
    """The closed-form terms of one model (module docstring); ``method`` says how they
    were derived. Terms are computed once, on first access."""

    default_c_terms = ("M", "C", "g", "tau")

    def __init__(self, model: SymbolicModel, method: str, rg: TrigRing, result: dict):
        self.model = model
        self.method = method
        self._rg = rg
        n = model.nv
        self.n = n
        self.q, self.v, self.a = model.q, model.v, model.a
        self.parameters = model.parameters()
        self._programs = {}
        tau = result["tau"]
        parts = [rg.split(t) for t in tau]
        self._poly = {
            "tau": tau,
            "M": [[rg.coefficient(tau[i], j) for j in range(n)] for i in range(n)],
            "g": [p.get((0, 0), rg.zero) for p in parts],
            "C_v": [p.get((2, 0), rg.zero) for p in parts],
            "T": result["T"],
            "U": result["U"],
        }
        self._poly["L"] = result["T"] - result["U"]
        if method == "newton_euler":
            self._poly["C"] = christoffel_from_quadratic(rg, self._poly["C_v"], n)
        else:
            self._poly["C"] = christoffel_matrix(rg, self._poly["M"])
        extra = set(parts[0]) if n else set()
        for p in parts:
            extra |= set(p)
        if extra - {(0, 0), (2, 0), (0, 1)}:
            raise AssertionError(f"tau has terms of degrees {sorted(extra)} in (qd, qdd)")

    def __repr__(self) -> str:
        return f"EquationsOfMotion({self.model.name!r}, method={self.method!r}, n={self.n})"

    # -- sympy expressions -------------------------------------------------------------
    def _expr(self, p, trig: str = "functions"):
        e = self._rg.expr(p, trig)
        if trig == "functions" and 1 < len(p) <= TRIG_TERMS:
            e = TR10i(e)  # c1 c2 - s1 s2 -> cos(q1 + q2), ...
        return readable_numbers(e)

    def _shaped(self, name: str, trig: str = "functions"):
        p = self._poly[name]
        if name in ("M", "C"):
            return sp.Matrix(self.n, self.n, [self._expr(x, trig) for row in p for x in row])
        if name in ("g", "C_v", "tau"):
            return sp.Matrix(self.n, 1, [self._expr(x, trig) for x in p])
        return self._expr(p, trig)

    @cached_property
    def M(self) -> sp.Matrix:
        """Mass matrix ``M(q)`` (n x n), armature included."""
        return self._shaped("M")

    @cached_property
    def C(self) -> sp.Matrix:
        """Christoffel matrix ``C(q, v)`` (n x n), ``Mdot - 2C`` skew-symmetric."""
        return self._shaped("C")

    @cached_property
    def C_v(self) -> sp.Matrix:
        """Coriolis and centrifugal forces ``C(q, v) v`` (n x 1)."""
        return self._shaped("C_v")

    qd = renamed_attribute("qd", "v")
    qdd = renamed_attribute("qdd", "a")
    C_qd = renamed_attribute("C_qd", "C_v")

    @cached_property
    def g(self) -> sp.Matrix:
        """Gravity forces ``g(q) = dU/dq`` (n x 1)."""
        return self._shaped("g")

    @cached_property
    def tau(self) -> sp.Matrix:
        """Joint forces ``M a + C v + g`` (n x 1)."""
        return self._shaped("tau")

    @cached_property
    def T(self) -> sp.Expr:
        """Kinetic energy ``v^T M v / 2``."""
        return self._shaped("T")

    @cached_property
    def U(self) -> sp.Expr:
        """Potential energy ``-sum_i m_i g . p_ci``."""
        return self._shaped("U")

    @cached_property
    def L(self) -> sp.Expr:
        """Lagrangian ``T - U``."""
        return self._shaped("L")

    @property
    def ring(self) -> TrigRing:
        """The polynomial ring of the terms (trigonometric names, symbols, revolute flags)."""
        return self._rg

    @property
    def polynomials(self) -> dict:
        """The terms as polynomials of :attr:`ring`: ``"M"``, ``"C"`` (lists of rows), ``"g"``,
        ``"tau"`` (lists), ``"T"``, ``"U"`` (one polynomial each)."""
        return self._poly

    def term(self, name: str):
        """A term by name: ``"M"``, ``"C"``, ``"C_v"``, ``"g"``, ``"tau"``, ``"T"``, ``"U"``, ``"L"``."""
        name = check_term(name)
        return getattr(self, name)

    def equals(self, other: "EquationsOfMotion", name: str) -> bool:
        """Exact equality of a term with the same term of ``other`` (same model), by the
        canonical polynomial form: no simplification heuristics involved."""
        a, b = self._poly[name], other._poly[name]
        flat = lambda x: [e for row in x for e in row] if isinstance(x, list) and x and isinstance(x[0], list) else (x if isinstance(x, list) else [x])  # noqa: E731
        return all(self._rg.expr(u, "symbols") - other._rg.expr(v, "symbols") == 0 for u, v in zip(flat(a), flat(b)))

    # -- output ------------------------------------------------------------------------
    def program(self, name: str, form: str = "auto") -> codegen.Program:
        """The :class:`~.codegen.Program` of a term, as generated code evaluates it.

        ``form="expanded"``: the expanded term (as :attr:`M`, :attr:`C`, ...) after
        common-subexpression elimination; ``form="recursive"``: ``M`` by the
        composite-rigid-body recursion, ``C_v``, ``g``, ``tau`` by the Newton-Euler recursion
        (:mod:`.recursive`: straight-line code, not expanded, much faster for 6 and more
        joints); ``form="auto"`` (default): recursive for these four terms, expanded for
        ``C``, ``T``, ``U``, ``L``. Both forms compute the same functions."""
        check_form(form)
        name = check_term(name)
        if form == "auto":
            form = "recursive" if name in RECURSIONS else "expanded"
        if form == "recursive" and name not in RECURSIONS:
            raise ValueError(f"form='recursive' is available for {list(RECURSIONS)}, not {name!r}")
        if (name, form) not in self._programs:
            self._programs[name, form] = (recursive_program(self.model, name) if form == "recursive"
                                          else self._expanded_program(name))
        return self._programs[name, form]

    def _expanded_program(self, name: str) -> codegen.Program:
        rg, n = self._rg, self.n
        p = self._poly[name]
        flat = [x for row in p for x in row] if name in ("M", "C") else (p if isinstance(p, list) else [p])
        shape = (n, n) if name in ("M", "C") else ((n,) if isinstance(p, list) else ())
        big = sum(len(x) for x in flat) > codegen.CSE_TERMS
        exprs = None if big else [rg.expr(x, "symbols") for x in flat]
        args, doc = signature(self.model, name, f"expanded ({self.method.replace('_', '-')} derivation)")
        trig = [(*rg.trig_names(k), self.q[k]) for k in range(n) if rg.revolute[k]]
        return codegen.program(name, exprs, shape, args, trig, doc, polys=flat, values=rg.generator_values())

    def latex(self, name: str | None = None) -> str:
        """LaTeX of one term (``name``), or with ``name=None`` a complete document with the
        model and every term."""
        from .latex import document, term_latex

        if name is None:
            return document(self)
        return term_latex(self, name)


def equations_of_motion(model, method: str = "lagrange") -> EquationsOfMotion:
    """Closed-form equations of motion of ``model`` (a :class:`robodyn.Model` with revolute
    and prismatic joints on a fixed base, or a :class:`SymbolicModel`).

    ``method="lagrange"``: Euler-Lagrange equations of ``T = qd^T M qd / 2`` and
    ``U = -sum m_i g . p_ci`` (:mod:`.lagrange`); ``method="newton_euler"``: the recursive
    Newton-Euler algorithm on symbols (:mod:`.newton_euler`). Both give identical terms.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)}, got {method!r}")
    sm = from_model(model)
    rg = TrigRing(sm)
    return EquationsOfMotion(sm, method, rg, METHODS[method](rg))
