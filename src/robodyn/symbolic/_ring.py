"""Exact trigonometric polynomials for the derivations (sympy's sparse polynomial rings).

Every quantity of a derivation (placements, velocities, forces, M, C, g, energies) is a
polynomial over the rationals in these generators:

* ``s_k, c_k`` (``sin q_k``, ``cos q_k``) for a revolute coordinate ``k``, ``x_k`` (``q_k``)
  for a prismatic one, and ``q_k`` itself for a revolute coordinate that a prismatic mimic
  joint follows (:mod:`.mimic`; a mimic joint is no coordinate: its ``sin``, ``cos`` or ``x``
  are polynomials in its source's);
* ``qd_k`` and ``qdd_k``;
* the model's parameters: its free symbols, and every non-polynomial piece of its entries
  (``cos(alpha1)``, ``sqrt(2)``, ``pi``, a mimic joint's ``cos o``, ``sin o``) as an opaque
  generator.

Products are reduced with ``c_k^2 = 1 - s_k^2`` (so each ``c_k`` has degree 0 or 1), and
``cos^2 o = 1 - sin^2 o`` for the offsets of the mimic joints. The
monomials ``s^a`` and ``s^a c`` are a basis of the polynomials in ``sin q, cos q``, so this
form is canonical: two expressions are equal as functions of ``q`` exactly when their
reduced polynomials are equal, and no ``simplify`` is ever needed (for the joint angles;
opaque parameter generators such as ``cos(alpha1)`` and ``sin(alpha1)`` are independent). sympy's ring arithmetic
(sparse dictionaries of exponent tuples) is much faster than arithmetic on expression trees,
which is what makes 6- and 7-dof derivations take seconds instead of hours.
"""

from __future__ import annotations

from fractions import Fraction
from math import comb

import sympy as sp
from sympy import QQ
from sympy.polys.rings import PolyRing

from .model import SymbolicModel


def _nonpolynomial_atoms(e: sp.Expr) -> set:
    """Maximal sub-expressions of ``e`` that are not polynomial in its symbols: functions,
    constants such as ``pi``, and powers with non-natural exponents (``sqrt(2)``, ``1/m``)."""
    out = set()
    walk = sp.preorder_traversal(e)
    for a in walk:
        if isinstance(a, (sp.Function, sp.NumberSymbol)) or (
                isinstance(a, sp.Pow) and not (a.exp.is_Integer and a.exp > 0)):
            out.add(a)
            walk.skip()
    return out


def trig_names(k: int) -> tuple[sp.Symbol, sp.Symbol]:
    """Plain symbols ``s{k+1}``, ``c{k+1}`` (``sin q_{k+1}``, ``cos q_{k+1}``) for generated code."""
    return sp.Symbol(f"s{k + 1}", real=True), sp.Symbol(f"c{k + 1}", real=True)


class VectorAlgebra:
    """3-vector and 3 x 3 matrix products on scalars of a derivation, each entry passed
    through ``self.reduce`` (trigonometric reduction in :class:`TrigRing`, a named
    intermediate in :class:`~._emit.Emitter`); the joints' values from the coordinates' and
    the map of joint forces to the coordinates (mimic joints, :mod:`.mimic`).

    The coordinates' scalars are ``pos[k]`` (``sin q_k`` of a revolute coordinate, ``q_k``
    of a prismatic one), ``cos[k]``, ``angle[k]`` (``q_k`` itself where a prismatic joint
    follows a revolute coordinate, else None), ``qd[k]``, ``qdd[k]``; :meth:`couple_joints`
    sets the joints' (one per body), which the recursions read: ``joint_revolute[i]``,
    ``joint_pos[i]``, ``joint_cos[i]``, ``joint_qd[i]``, ``joint_qdd[i]``."""

    def couple_joints(self) -> None:
        """The joints' values (class docstring) from the coordinates': those of coordinate
        ``k`` for its own joint; for a joint ``r q_k + o`` following it, ``sin``, ``cos`` of
        the sum of angles (:meth:`mimic_angle`), ``r x_k + o`` (prismatic), ``r qd_k``, ``r qdd_k``."""
        m = self.model
        self.joint_revolute = [t == "revolute" for t in m.joint_type]
        self.joint_pos, self.joint_cos, self.joint_qd, self.joint_qdd = [], [], [], []
        for i, (k, r, o) in enumerate(m.coupling):
            same = r == 1 and o == 0 and self.joint_revolute[i] == (self.cos[k] is not None)
            if same:
                s, c = self.pos[k], self.cos[k]
            elif self.joint_revolute[i]:
                s, c = self.mimic_angle(k, r, o)
            else:
                s, c = self.reduce(self.const(r) * self.angle[k] + self.const(o)), None
            self.joint_pos.append(s)
            self.joint_cos.append(c)
            self.joint_qd.append(self.qd[k] if r == 1 else self.const(r) * self.qd[k])
            self.joint_qdd.append(self.qdd[k] if r == 1 else self.const(r) * self.qdd[k])

    def mimic_angle(self, k: int, r, o) -> tuple:
        """``(sin(r q_k + o), cos(r q_k + o))`` for an integer ``r``: ``sin(j q)``, ``cos(j q)``
        by ``(j + 1) q = j q + q`` up to ``|r|``, the sign, then the sum with the constant ``o``."""
        s, c = self.pos[k], self.cos[k]
        sr, cr = self.zero, self.one
        for _ in range(abs(int(r))):
            sr, cr = self.reduce(sr * c + cr * s), self.reduce(cr * c - sr * s)
        if r < 0:
            sr = -sr
        if o != 0:
            co, so = self.const(sp.cos(o)), self.const(sp.sin(o))
            sr, cr = self.reduce(sr * co + cr * so), self.reduce(cr * co - sr * so)
        return sr, cr

    def coordinate_forces(self, f) -> list:
        """``G^T f`` (nv,): the joint forces ``f`` (one per body) on the coordinates, each
        times its joint's multiplier (``f`` itself without mimic joints)."""
        m = self.model
        if not m.mimic:
            return list(f)
        out = [self.zero] * m.nv
        for i, (k, r, _) in enumerate(m.coupling):
            out[k] = out[k] + (f[i] if r == 1 else self.const(r) * f[i])
        return [self.reduce(x) for x in out]

    def coordinate_matrix(self, A) -> list:
        """``G^T A G`` (nv x nv) of a matrix ``A`` over the joints (nb x nb; ``A`` itself
        without mimic joints)."""
        m = self.model
        if not m.mimic:
            return A
        out = [[self.zero] * m.nv for _ in range(m.nv)]
        for i, (k, r, _) in enumerate(m.coupling):
            for j, (l, t, _) in enumerate(m.coupling):
                w = r * t
                out[k][l] = out[k][l] + (A[i][j] if w == 1 else self.const(w) * A[i][j])
        return [[self.reduce(x) for x in row] for row in out]

    def matvec(self, R, v):
        return [self.reduce(R[r][0] * v[0] + R[r][1] * v[1] + R[r][2] * v[2]) for r in range(3)]

    def matTvec(self, R, v):
        return [self.reduce(R[0][r] * v[0] + R[1][r] * v[1] + R[2][r] * v[2]) for r in range(3)]

    def matmul(self, A, B):
        return [[self.reduce(sum((A[r][k] * B[k][c] for k in range(3)), self.zero)) for c in range(3)]
                for r in range(3)]

    @staticmethod
    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def dot(self, a, b):
        return self.reduce(sum((x * y for x, y in zip(a, b)), self.zero))


class TrigRing(VectorAlgebra):
    """The polynomial ring of a model's derivation, with trigonometric reduction,
    differentiation along ``q`` and conversion to and from sympy expressions."""

    def __init__(self, model: SymbolicModel):
        n = model.nv
        self.model = model
        self.revolute = [model.joint_type[b] == "revolute" for b in model.independent]
        pos = [sp.Dummy(f"s{k + 1}") if r else model.q[k] for k, r in enumerate(self.revolute)]
        cos = [sp.Dummy(f"c{k + 1}") for k, r in enumerate(self.revolute) if r]
        # the angle itself of a revolute coordinate that a prismatic joint follows (x = r q + o)
        angles = sorted({k for (k, _, _), t in zip(model.coupling, model.joint_type)
                         if t == "prismatic" and self.revolute[k]})
        exprs = list(model.gravity) + [*model.armature]
        for i in range(model.nbodies):
            exprs += [*model.joint_axis[i], *model.X_tree_R[i], *model.X_tree_p[i], *model.theta[i]]
        for joint, _, r, o in model.mimic:
            exprs += [r, o] + ([sp.cos(o), sp.sin(o)] if model.joint_type[model.joint_names.index(joint)] == "revolute"
                               else [])
        atoms = set()
        for e in exprs:
            atoms |= _nonpolynomial_atoms(e)
        self.atom_dummies = {a: sp.Dummy(f"a{j}") for j, a in enumerate(sorted(atoms, key=sp.default_sort_key))}
        params = sorted(set().union(*(e.free_symbols for e in exprs)) - set(model.q), key=lambda s: s.name)
        gens = (pos + cos + [model.q[k] for k in angles] + list(model.v) + list(model.a) + params
                + list(self.atom_dummies.values()))
        self.ring = PolyRing(gens, QQ, "lex")
        g = iter(self.ring.gens)
        self.pos = [next(g) for _ in range(n)]
        self.cos = [None] * n
        for k in range(n):
            if self.revolute[k]:
                self.cos[k] = next(g)
        self.angle = [None if r else self.pos[k] for k, r in enumerate(self.revolute)]
        for k in angles:
            self.angle[k] = next(g)
        self.qd = [next(g) for _ in range(n)]
        self.qdd = [next(g) for _ in range(n)]
        g = self.ring.gens
        index = {x: j for j, x in enumerate(g)}
        # (s index, c index) of each revolute coordinate, for the reduction c^2 = 1 - s^2,
        self.pairs = [(index[self.pos[k]], index[self.cos[k]]) for k in range(n) if self.revolute[k]]
        # and of the sine and cosine of a mimic joint's offset (constants: cos^2 o = 1 - sin^2 o)
        where = {d: j for j, d in enumerate(gens)}
        for joint, _, _, o in model.mimic:
            so, co = (_nonpolynomial_atoms(f(o)) for f in (sp.sin, sp.cos))
            if len(so) == len(co) == 1 and model.joint_type[model.joint_names.index(joint)] == "revolute":
                pair = (where[self.atom_dummies[so.pop()]], where[self.atom_dummies[co.pop()]])
                if pair not in self.pairs:
                    self.pairs.append(pair)
        self.qd_index = [index[x] for x in self.qd]
        self.qdd_index = [index[x] for x in self.qdd]
        # back to sympy: s_k -> sin(q_k), c_k -> cos(q_k), atoms back to themselves
        self.trig_symbols = {}
        self.to_sympy = {v: k for k, v in self.atom_dummies.items()}
        for k in range(n):
            if self.revolute[k]:
                self.to_sympy[pos[k]] = sp.sin(model.q[k])
                self.to_sympy[cos[self._cos_number(k)]] = sp.cos(model.q[k])
        self._cos_dummies = cos
        self._pos_dummies = pos
        self.zero, self.one = self.ring.zero, self.ring.one
        self.couple_joints()

    def _cos_number(self, k: int) -> int:
        return sum(self.revolute[:k])

    # -- conversion ----------------------------------------------------------------------
    def const(self, e) -> "PolyElement":  # noqa: F821
        """A model expression (no joint symbols except prismatic ``q_k``) in the ring."""
        e = sp.sympify(e)
        if self.atom_dummies:
            e = e.xreplace(self.atom_dummies)
        return self.ring.from_expr(e) if e.free_symbols else self.ring(QQ.convert(e) if e.is_Rational else e)

    def vec(self, v) -> list:
        return [self.const(x) for x in v]

    def mat(self, m) -> list:
        return [[self.const(m[r, c]) for c in range(3)] for r in range(3)]

    @staticmethod
    def trig_names(k: int) -> tuple[sp.Symbol, sp.Symbol]:
        return trig_names(k)

    def expr(self, p, trig: str = "functions") -> sp.Expr:
        """``p`` as a sympy expression: ``trig="functions"`` writes ``sin(q1)``, ``cos(q1)``;
        ``trig="symbols"`` writes the plain symbols ``s1``, ``c1`` (for generated code)."""
        return p.as_expr().xreplace(self._code_values() if trig == "symbols" else self.to_sympy)

    def _code_values(self) -> dict:
        """Generator dummies -> their values in generated code: ``s_k``, ``c_k`` as the plain
        symbols of :meth:`trig_names`, atoms as themselves."""
        sub = {v: k for k, v in self.atom_dummies.items()}
        for k in range(self.model.nv):
            if self.revolute[k]:
                s, c = self.trig_names(k)
                sub[self._pos_dummies[k]] = s
                sub[self._cos_dummies[self._cos_number(k)]] = c
        return sub

    def generator_values(self) -> list:
        """The value of each generator in generated code (:meth:`_code_values`; other
        generators unchanged)."""
        sub = self._code_values()
        return [sub.get(g, g) for g in self.ring.symbols]

    # -- arithmetic ----------------------------------------------------------------------
    def reduce(self, p):
        """``p`` with every ``c_k^2`` replaced by ``1 - s_k^2`` (canonical form)."""
        pairs = self.pairs
        if not any(m[ci] >= 2 for m in p for _, ci in pairs):
            return p
        out = {}
        for mon, coef in p.items():
            terms = [(mon, coef)]
            for si, ci in pairs:
                if mon[ci] < 2:
                    continue
                new = []
                for m, cf in terms:
                    k, r = divmod(m[ci], 2)
                    for j in range(k + 1):
                        mm = list(m)
                        mm[ci] = r
                        mm[si] += 2 * j
                        new.append((tuple(mm), cf * (comb(k, j) * (-1) ** j)))
                terms = new
            for m, cf in terms:
                out[m] = out.get(m, 0) + cf
        res = self.ring.zero.copy()
        for m, cf in out.items():
            if cf:
                res[m] = cf
        return res

    def dq(self, p, k: int):
        """``dp/dq_k``: ``c_k dp/ds_k - s_k dp/dc_k`` (revolute, plus ``dp/dq_k`` when the angle
        itself is a generator) or ``dp/dx_k`` (prismatic)."""
        if not self.revolute[k]:
            return p.diff(self.pos[k])
        s, c = self.pos[k], self.cos[k]
        d = self.reduce(p.diff(s) * c - p.diff(c) * s)
        return d if self.angle[k] is None else d + p.diff(self.angle[k])

    def ddt(self, p):
        """Time derivative along the motion: ``sum_k dp/dq_k qd_k + dp/dqd_k qdd_k``."""
        out = self.zero
        for k in range(self.model.nv):
            out = out + self.dq(p, k) * self.qd[k] + p.diff(self.qd[k]) * self.qdd[k]
        return out

    def split(self, p):
        """Terms of ``p`` by their degree in ``qd`` and ``qdd``: ``{(deg qd, deg qdd): poly}``."""
        parts = {}
        for m, cf in p.items():
            key = (sum(m[j] for j in self.qd_index), sum(m[j] for j in self.qdd_index))
            parts.setdefault(key, {})[m] = cf
        out = {}
        for key, d in parts.items():
            e = self.ring.zero.copy()
            e.update(d)
            out[key] = e
        return out

    def coefficient(self, p, j: int, which: str = "qdd"):
        """The coefficient of ``qdd_j`` (or ``qd_j``) in ``p``, which is linear in it."""
        return p.diff(self.qdd[j] if which == "qdd" else self.qd[j])


def readable_numbers(e: sp.Expr) -> sp.Expr:
    """``e`` for display: rationals with denominators above 10^6 (the exact values of decimal
    model data such as ``10 / 6`` stored as ``1.666666666666667``) become the fraction with a
    denominator up to 1000 they round (``5/3``, ``10``) when there is one within 1e-12,
    otherwise floats of 15 significant digits (``0.612950000000000``; a lower precision would
    carry into every evaluation of the expression)."""
    reps = {}
    for r in e.atoms(sp.Rational):
        if r.q <= 10**6:
            continue
        x = float(r)
        near = Fraction(x).limit_denominator(1000)
        if abs(x - near.numerator / near.denominator) <= 1e-12 * abs(x):
            reps[r] = sp.Rational(near.numerator, near.denominator)
        else:
            reps[r] = sp.Float(x, 15)
    return e.xreplace(reps) if reps else e
