"""Closed-form equations of motion ``M(q) a + C(q, v) v + g(q) + tau_p(q, v) = tau``.

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
    g    (n,)    gravity forces (as robodyn.gravity), the derivative of the gravity part of U
    tau_p (n,)   passive joint forces b v + Fc sgn(v) + K (q - q_ref): the joints' viscous
                 damping b, Coulomb friction Fc (sgn = sympy's sign, or tanh(v / eps) when
                 the model's coulomb_smoothing eps > 0, as robodyn.rnea) and springs of
                 stiffness K about spring_reference q_ref
    T, U, L      kinetic energy v^T M v / 2, potential energy -sum m_i g . p_ci
                 + sum K (q - q_ref)^2 / 2 (gravity and the springs, as a simulated
                 trajectory's potential), T - U
    tau  (n,)    M a + C v + g + tau_p (as robodyn.rnea)

A model with mimic joints (a :class:`robodyn.CoupledModel`, or a :class:`SymbolicModel` with
``mimic``; :mod:`.mimic`) has the terms of its independent coordinates q1..qn, as the numeric
algorithms': ``M = G^T M_full G``, ``tau = G^T tau_full(P q + offset, G v, G a)``, the mimic
joints' armature, friction and springs through ``G^T``, and ``C`` the Christoffel matrix of
this ``M``.

``friction=False`` (as ``robodyn.rnea(..., friction=False)``) leaves the passive elements out:
``tau_p`` is zero, ``U`` has no spring energy and ``tau = M a + C v + g`` (the armature stays
in ``M``, as ``rnea``'s ``armature=True``). ``dU/dq = g + K (q - q_ref)``: the springs' force is
a part of ``tau_p``, not of ``g``. ``tau_p`` and the spring energy are written in ``q_k``
itself and ``sign(v_k)``, not in the ring's ``sin q_k``, ``cos q_k``; they are kept apart from
the ring polynomials (:attr:`EquationsOfMotion.polynomials`) and added to them.

Expressions of up to ``TRIG_TERMS`` terms are rewritten with the angle-sum rules (sympy's
``TR10i``: ``c1 c2 - s1 s2 = cos(q1 + q2)``); all stay otherwise in the canonical expanded
form (no ``simplify`` or ``trigsimp`` on big expressions, which is what makes other tools
take hours). Code generation (:meth:`EquationsOfMotion.to_function`, ``to_numba``,
``to_c``) writes ``M``, ``C_v``, ``g``, ``tau`` and ``tau_p`` by default as the straight-line
code of the recursions (:mod:`.recursive`: not expanded, fast to compile and to run) and the
other terms, or every term with ``form="expanded"``, as the expanded expressions after
common-subexpression elimination.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp
from sympy.simplify.fu import TR10i

from .._deprecated import renamed_attribute
from . import codegen, lagrange, newton_euler
from ._ring import TrigRing, readable_numbers
from ._terms import GeneratedCode, check_form, check_term, signature
from .model import SymbolicModel, from_model, passive_forces, spring_energy
from .recursive import RECURSIONS, recursive_program, tau_description

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
    were derived, ``friction`` whether the passive forces ``tau_p`` (and the springs' energy)
    are in. Terms are computed once, on first access."""

    default_c_terms = ("M", "C", "g", "tau")

    def __init__(self, model: SymbolicModel, method: str, rg: TrigRing, result: dict, friction: bool = True):
        self.model = model
        self.method = method
        self.friction = bool(friction)
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
        self._poly["tau_p"] = [rg.zero] * n
        # the terms outside the ring: passive forces and spring energy (symbols q_k, v_k)
        tau_p = passive_forces(model) if friction else [sp.Integer(0)] * n
        U_spring = spring_energy(model) if friction else sp.Integer(0)
        self._extra = {"tau_p": tau_p, "tau": tau_p, "U": [U_spring], "L": [-U_spring]}
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
        return (f"EquationsOfMotion({self.model.name!r}, method={self.method!r}, n={self.n}"
                f"{'' if self.friction else ', friction=False'})")

    # -- sympy expressions -------------------------------------------------------------
    def _expr(self, p, trig: str = "functions", extra=0):
        e = self._rg.expr(p, trig)
        if trig == "functions" and 1 < len(p) <= TRIG_TERMS:
            e = TR10i(e)  # c1 c2 - s1 s2 -> cos(q1 + q2), ...
        return readable_numbers(e + extra)

    def flat_terms(self, name: str) -> tuple[list, list]:
        """``(polynomials, extra)`` of a term, flat and row-major: the ring part of each entry
        (:attr:`polynomials`) and the sympy expression added to it (the passive forces and
        the springs' energy: zero for the other terms)."""
        p = self._poly[name]
        flat = [x for row in p for x in row] if name in ("M", "C") else (p if isinstance(p, list) else [p])
        return flat, self._extra.get(name, [sp.Integer(0)] * len(flat))

    def _entry_expressions(self, name: str, trig: str = "functions") -> list:
        """The entries of a term as sympy expressions, flat and row-major."""
        flat, extra = self.flat_terms(name)
        return [self._expr(x, trig, e) for x, e in zip(flat, extra)]

    def _shaped(self, name: str, trig: str = "functions"):
        entries = self._entry_expressions(name, trig)
        if name in ("M", "C"):
            return sp.Matrix(self.n, self.n, entries)
        if name in ("g", "C_v", "tau", "tau_p"):
            return sp.Matrix(self.n, 1, entries)
        return entries[0]

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
    def tau_p(self) -> sp.Matrix:
        """Passive joint forces ``b v + Fc sgn(v) + K (q - q_ref)`` (n x 1): damping, Coulomb
        friction and springs (zero with ``friction=False``)."""
        return self._shaped("tau_p")

    @cached_property
    def tau(self) -> sp.Matrix:
        """Joint forces ``M a + C v + g + tau_p`` (n x 1), as ``robodyn.rnea``."""
        return self._shaped("tau")

    @cached_property
    def T(self) -> sp.Expr:
        """Kinetic energy ``v^T M v / 2``."""
        return self._shaped("T")

    @cached_property
    def U(self) -> sp.Expr:
        """Potential energy ``-sum_i m_i g . p_ci + sum_k K_k (q_k - q_ref_k)^2 / 2`` (gravity
        and the joint springs)."""
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
        """The rigid-body parts of the terms as polynomials of :attr:`ring`: ``"M"``, ``"C"``
        (lists of rows), ``"g"``, ``"C_v"``, ``"tau"``, ``"tau_p"`` (lists), ``"T"``, ``"U"``,
        ``"L"`` (one polynomial each). The passive forces and the springs' energy are not
        ring polynomials (they hold ``q_k`` and ``sign``): :meth:`flat_terms` has them."""
        return self._poly

    def term(self, name: str):
        """A term by name: ``"M"``, ``"C"``, ``"C_v"``, ``"g"``, ``"tau_p"``, ``"tau"``, ``"T"``,
        ``"U"``, ``"L"``."""
        name = check_term(name)
        return getattr(self, name)

    def equals(self, other: "EquationsOfMotion", name: str) -> bool:
        """Exact equality of a term with the same term of ``other`` (same model), by the
        canonical polynomial form (and the passive terms, which are built alike): no
        simplification heuristics involved."""
        (a, x), (b, y) = self.flat_terms(name), other.flat_terms(name)
        return all(self._rg.expr(u, "symbols") - other._rg.expr(v, "symbols") == 0 and sp.expand(e - f) == 0
                   for u, v, e, f in zip(a, b, x, y))

    # -- output ------------------------------------------------------------------------
    def program(self, name: str, form: str = "auto") -> codegen.Program:
        """The :class:`~.codegen.Program` of a term, as generated code evaluates it.

        ``form="expanded"``: the expanded term (as :attr:`M`, :attr:`C`, ...) after
        common-subexpression elimination; ``form="recursive"``: ``M`` by the
        composite-rigid-body recursion, ``C_v``, ``g``, ``tau`` by the Newton-Euler recursion
        (:mod:`.recursive`: straight-line code, not expanded, much faster for 6 and more
        joints), ``tau_p`` written out joint by joint; ``form="auto"`` (default): recursive
        for these five terms, expanded for ``C``, ``T``, ``U``, ``L``. Both forms compute the
        same functions; ``tau`` includes ``tau_p`` unless ``friction=False``."""
        check_form(form)
        name = check_term(name)
        if form == "auto":
            form = "recursive" if name in RECURSIONS else "expanded"
        if form == "recursive" and name not in RECURSIONS:
            raise ValueError(f"form='recursive' is available for {list(RECURSIONS)}, not {name!r}")
        if (name, form) not in self._programs:
            self._programs[name, form] = (recursive_program(self.model, name, self.friction) if form == "recursive"
                                          else self._expanded_program(name))
        return self._programs[name, form]

    def _expanded_program(self, name: str) -> codegen.Program:
        rg, n = self._rg, self.n
        p = self._poly[name]
        flat, extra = self.flat_terms(name)
        shape = (n, n) if name in ("M", "C") else ((n,) if isinstance(p, list) else ())
        big = sum(len(x) for x in flat) > codegen.CSE_TERMS
        exprs = None if big else [rg.expr(x, "symbols") for x in flat]
        how = f"expanded ({self.method.replace('_', '-')} derivation)"
        args, doc = signature(self.model, name, tau_description(name, how, self.friction))
        trig = [(*rg.trig_names(k), self.q[k]) for k in range(n) if rg.revolute[k]]
        return codegen.program(name, exprs, shape, args, trig, doc, polys=flat, values=rg.generator_values(),
                               extra=extra)

    def latex(self, name: str | None = None) -> str:
        """LaTeX of one term (``name``), or with ``name=None`` a complete document with the
        model and every term."""
        from .latex import document, term_latex

        if name is None:
            return document(self)
        return term_latex(self, name)


def equations_of_motion(model, method: str = "lagrange", *, friction: bool = True) -> EquationsOfMotion:
    """Closed-form equations of motion of ``model`` (a :class:`robodyn.Model` with revolute
    and prismatic joints on a fixed base, a :class:`robodyn.CoupledModel` of one (mimic joints:
    the equations of its independent coordinates, module docstring), or a :class:`SymbolicModel`).

    ``method="lagrange"``: Euler-Lagrange equations of ``T = qd^T M qd / 2`` and the gravity
    potential ``-sum m_i g . p_ci`` (:mod:`.lagrange`); ``method="newton_euler"``: the
    recursive Newton-Euler algorithm on symbols (:mod:`.newton_euler`). Both give identical
    terms. ``friction``: add the joints' passive forces ``tau_p`` (damping, Coulomb friction,
    springs) to ``tau`` and the springs' energy to ``U``, as ``robodyn.rnea``'s switch of the
    same name (module docstring).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)}, got {method!r}")
    sm = from_model(model)
    rg = TrigRing(sm)
    return EquationsOfMotion(sm, method, rg, METHODS[method](rg), friction)
