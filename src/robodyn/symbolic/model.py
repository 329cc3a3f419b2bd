"""Symbolic models: the fields of :class:`robodyn.Model` with sympy entries.

A :class:`SymbolicModel` is a fixed-base tree of revolute and prismatic joints whose
placements, joint axes, inertial parameters and gravity are sympy expressions (symbols or
exact numbers). Body ``i`` hangs from body ``parent[i] < i``; its frame is placed in the
parent frame at ``(X_tree_R[i], X_tree_p[i]) * X_J(q_i)`` exactly as in the numeric model, and
its inertial parameters are ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` about the
body origin in the body frame (``robodyn`` order). Joint ``k`` (1-based) has the coordinate
``q{k}``, velocity ``qd{k}`` and acceleration ``qdd{k}`` (the tuples ``SymbolicModel.q``,
``.v`` and ``.a``; the symbols print as q, q-dot and q-double-dot).

Three ways to get one:

* :func:`from_model`: a numeric :class:`robodyn.Model` with its numbers made exact (each
  float becomes the rational of its shortest decimal representation, so ``0.4318`` is
  ``2159/5000``; rotation entries within ``1e-12`` of 0 or +-1, the round-off of
  ``cos(pi/2)``, become exactly 0 or +-1);
* :func:`from_dh`: a Denavit-Hartenberg table (:class:`robodyn.DHLink` rows) whose entries
  are sympy expressions or numbers, standard or modified convention;
* :func:`with_inertia_symbols`: any of them with the inertial parameters replaced by the
  named symbols ``m1, mx1, my1, mz1, Ixx1, Ixy1, Iyy1, Ixz1, Iyz1, Izz1, m2, ...``.

Mimic joints (:mod:`.mimic`): ``mimic`` lists ``(joint, source, multiplier, offset)``, the
joint following its source as ``q_joint = multiplier q_source + offset`` (the couplings of
:class:`robodyn.CoupledModel`, which :func:`from_model` converts); ``q``, ``v``, ``a`` are then
the symbols of the independent joints only (``nv`` of them, ``nbodies`` bodies).

Per joint the model carries, as the numeric one, the passive elements: ``armature`` (on the
diagonal of ``M``), viscous ``damping`` ``b``, ``coulomb`` friction ``Fc`` and a joint spring of
``stiffness`` ``K`` about ``spring_reference`` ``q_ref``, with ``coulomb_smoothing`` ``eps``
(one for the model). They give the passive joint forces of :mod:`.equations`,
``tau_p = b qd + Fc sgn(qd) + K (q - q_ref)`` (:func:`passive_torque`), ``sgn = sign`` when
``eps`` is 0 and ``tanh(qd / eps)`` otherwise, as the numeric ``rnea``. Each may be a number or
an expression; numbers are checked as :class:`robodyn.Model` checks them (``damping``,
``coulomb``, ``stiffness``, ``armature`` and ``coulomb_smoothing`` finite and non-negative,
``spring_reference`` finite), and so are symbols declared negative or infinite.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Sequence

import numpy as np
import sympy as sp

import warnings

from .._deprecated import renamed_attribute, renamed_keywords
from .. import joints as J
from ..coupling import is_coupled
from ..errors import ModelError, RobodynWarning
from .mimic import resolve as resolve_mimic, rule_text

JOINT_TYPES = ("revolute", "prismatic")
PARAMETER_NAMES = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
# Rotation entries this close to 0 or +-1 are the round-off of cos(pi/2) and the like.
SNAP_TOL = 1e-12


def exact(x, snap: bool = False) -> sp.Expr:
    """A sympy number or expression for ``x``: floats become the rational of their shortest
    decimal representation; with ``snap``, values within ``SNAP_TOL`` of 0, 1 or -1 become
    those integers."""
    if isinstance(x, sp.Basic):
        if isinstance(x, sp.Float):
            return exact(float(x), snap)
        return x.xreplace({f: exact(float(f), snap) for f in x.atoms(sp.Float)}) if x.atoms(sp.Float) else x
    if isinstance(x, (int, np.integer)):
        return sp.Integer(int(x))
    v = float(x)
    if not np.isfinite(v):
        raise ValueError(f"expected a finite number, got {x!r}")
    if snap:
        for k in (0, 1, -1):
            if abs(v - k) <= SNAP_TOL:
                return sp.Integer(k)
    f = Fraction(repr(v))
    return sp.Rational(f.numerator, f.denominator)


def exact_vector(x, n: int, what: str) -> sp.Matrix:
    """``x`` as an ``n x 1`` sympy matrix of exact entries (:func:`exact`); ``what`` names it in errors."""
    m = sp.Matrix(x) if not isinstance(x, sp.MatrixBase) else x
    if m.shape not in ((n, 1), (1, n)):
        raise ValueError(f"{what}: expected {n} entries, got shape {m.shape}")
    return sp.Matrix(n, 1, [exact(e) for e in m])


def exact_matrix3(x, what: str, snap: bool = False) -> sp.Matrix:
    """``x`` as a 3 x 3 sympy matrix of exact entries (:func:`exact`); ``what`` names it in errors."""
    m = sp.Matrix(x)
    if m.shape != (3, 3):
        raise ValueError(f"{what}: expected shape (3, 3), got {m.shape}")
    return m.applyfunc(lambda e: exact(e, snap))


def skew(v) -> sp.Matrix:
    """``[v]x``, the 3 x 3 cross-product matrix of ``v``."""
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def inertial_parameters(mass, com, inertia_com) -> list:
    """The 10 inertial parameters about the frame origin from the mass, the centre of mass
    (3,) and the inertia (3, 3) about the centre of mass (same frame), by the parallel-axis
    theorem ``I_o = I_c + m [c]x^T [c]x``; entries may be symbols."""
    m = exact(mass)
    c = exact_vector(com, 3, "com")
    Io = exact_matrix3(inertia_com, "inertia") + m * (skew(c).T * skew(c))
    h = m * c
    return [m, h[0], h[1], h[2], Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]]


def inertia_symbols(body: int) -> list[sp.Symbol]:
    """``m{k}, mx{k}, my{k}, mz{k}, Ixx{k}, Ixy{k}, Iyy{k}, Ixz{k}, Iyz{k}, Izz{k}`` for body
    ``k = body`` (1-based), in robodyn's parameter order (``mx = m cx`` and so on, inertias
    about the body origin)."""
    return [sp.Symbol(f"{n}{body}", real=True) for n in PARAMETER_NAMES]


OLD_FIELDS = dict(axis="joint_axis", R_tree="X_tree_R", p_tree="X_tree_p", inertia="theta")
# The per-joint passive elements: (field, must be non-negative).
PASSIVE_FIELDS = (("damping", True), ("coulomb", True), ("stiffness", True), ("spring_reference", False))


def passive_value(x, what: str, nonnegative: bool) -> sp.Expr:
    """``x`` exact (:func:`exact`), checked as :class:`robodyn.Model` checks its friction and
    spring entries: finite, and non-negative when ``nonnegative``; symbols pass unless their
    assumptions contradict it (``ModelError`` naming ``what``)."""
    try:
        e = exact(x)
    except (TypeError, ValueError) as err:
        raise ModelError(f"{what}: {err}") from None
    if e.is_finite is False or e.has(sp.nan, sp.zoo):
        raise ModelError(f"{what} must be finite, got {e}")
    if nonnegative and e.is_negative:
        raise ModelError(f"{what} must be non-negative, got {e}")
    return e


def joint_motion(model: "SymbolicModel", i: int) -> tuple[sp.Expr, sp.Expr]:
    """``(q_i, qd_i)`` of body ``i``'s joint in the model's symbols: ``(q_k, qd_k)`` of an
    independent joint, ``(r q_k + o, r qd_k)`` of a mimic joint following coordinate ``k``."""
    k, r, o = model.coupling[i]
    return r * model.q[k] + o, r * model.v[k]


def passive_torque(model: "SymbolicModel", i: int) -> sp.Expr:
    """The passive force of body ``i``'s joint (0-based) opposed by its actuator:
    ``damping qd + coulomb sgn(qd) + stiffness (q - spring_reference)`` with ``sgn = sign``
    when ``coulomb_smoothing`` is 0 and ``tanh(qd / coulomb_smoothing)`` otherwise (the numeric
    ``robodyn.joint_kernels.passive_torque``), at the joint's ``(q, qd)``
    (:func:`joint_motion`); zero coefficients fold away."""
    (q, qd), eps = joint_motion(model, i), model.coulomb_smoothing
    sgn = sp.sign(qd) if eps == 0 else sp.tanh(qd / eps)
    return (model.damping[i] * qd + model.coulomb[i] * sgn
            + model.stiffness[i] * (q - model.spring_reference[i]))


def passive_forces(model: "SymbolicModel") -> list:
    """The passive forces on the coordinates, ``tau_p = G^T tau_p,joints`` (nv,): each
    joint's :func:`passive_torque` times its multiplier, on its coordinate (a mimic joint's
    friction and spring act on its source, as in the numeric ``rnea`` of a coupled model)."""
    out = [sp.Integer(0)] * model.nv
    for i, (k, r, _) in enumerate(model.coupling):
        out[k] = out[k] + r * passive_torque(model, i)
    return out


def spring_energy(model: "SymbolicModel") -> sp.Expr:
    """The energy stored in the joint springs, ``sum_i stiffness_i (q_i - spring_reference_i)^2 / 2``
    (``q_i`` the joint's coordinate, :func:`joint_motion`)."""
    return sum((model.stiffness[i] * (joint_motion(model, i)[0] - model.spring_reference[i]) ** 2 / 2
                for i in range(model.nbodies)), sp.Integer(0))


@dataclass(frozen=True)
class SymbolicModel:
    """A fixed-base tree with sympy entries (see the module docstring).

    Per body ``i`` (``nb`` bodies, each with one joint): ``parent[i]`` (``-1``: the world),
    ``joint_type[i]`` (``"revolute"`` or ``"prismatic"``), ``joint_axis[i]`` (3 x 1, unit,
    body frame), ``X_tree_R[i]`` (3 x 3) and ``X_tree_p[i]`` (3 x 1) (joint frame in the parent
    frame), ``theta[i]`` (10 inertial parameters): the names of :class:`robodyn.Model`. Per
    joint: ``armature`` (rotor inertia on the diagonal of ``M``), ``damping``, ``coulomb``,
    ``stiffness`` and ``spring_reference`` (the passive forces, module docstring; empty tuples
    mean zeros). ``coulomb_smoothing``: the smoothing velocity of the Coulomb friction (0:
    ``sign``). ``gravity`` (3 x 1, world frame). ``mimic``: ``(joint, source, multiplier,
    offset)`` couplings (:mod:`.mimic`; kept with each source followed to its independent
    joint). ``q``, ``v``, ``a``: the symbols of the coordinates, one per independent joint
    (``nv``); ``independent`` (nv,): their bodies; ``coupling[i] = (k, r, o)``: body ``i``'s
    joint is ``r q_k + o`` (``(k, 1, 0)`` for an independent joint).
    """

    parent: tuple
    joint_type: tuple
    joint_axis: tuple
    X_tree_R: tuple
    X_tree_p: tuple
    theta: tuple
    gravity: sp.Matrix
    armature: tuple = ()
    name: str = "robot"
    link_names: tuple = ()
    joint_names: tuple = ()
    damping: tuple = ()
    coulomb: tuple = ()
    stiffness: tuple = ()
    spring_reference: tuple = ()
    coulomb_smoothing: sp.Expr = 0
    mimic: tuple = ()
    q: tuple = field(init=False)
    v: tuple = field(init=False)
    a: tuple = field(init=False)
    coupling: tuple = field(init=False)
    independent: tuple = field(init=False)

    def __post_init__(self):
        nb = len(self.parent)
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen dataclass)
        for what in ("joint_type", "joint_axis", "X_tree_R", "X_tree_p", "theta"):
            if len(getattr(self, what)) != nb:
                raise ModelError(f"{what}: expected {nb} entries (one per body), got {len(getattr(self, what))}")
        for i, p in enumerate(self.parent):
            if not -1 <= int(p) < i:
                raise ModelError(f"body {i}: parent index {p} must satisfy -1 <= parent < {i}")
            if self.joint_type[i] not in JOINT_TYPES:
                raise ModelError(f"body {i}: joint type must be one of {JOINT_TYPES}, got {self.joint_type[i]!r}")
            if len(self.theta[i]) != 10:
                raise ModelError(f"body {i}: expected 10 inertial parameters, got {len(self.theta[i])}")
        set_("parent", tuple(int(p) for p in self.parent))
        set_("joint_axis", tuple(exact_vector(a, 3, f"joint_axis[{i}]") for i, a in enumerate(self.joint_axis)))
        set_("X_tree_R", tuple(exact_matrix3(R, f"X_tree_R[{i}]") for i, R in enumerate(self.X_tree_R)))
        set_("X_tree_p", tuple(exact_vector(p, 3, f"X_tree_p[{i}]") for i, p in enumerate(self.X_tree_p)))
        set_("theta", tuple(tuple(exact(t) for t in th) for th in self.theta))
        set_("gravity", exact_vector(self.gravity, 3, "gravity"))
        for what, nonnegative in (("armature", True), *PASSIVE_FIELDS):
            values = tuple(getattr(self, what))
            if values and len(values) != nb:
                raise ModelError(f"{what}: expected {nb} entries (one per joint), got {len(values)}")
            set_(what, tuple(passive_value(x, f"{what}[{k}]", nonnegative) for k, x in enumerate(values))
                 if values else (sp.Integer(0),) * nb)
        set_("coulomb_smoothing", passive_value(self.coulomb_smoothing, "coulomb_smoothing", True))
        set_("link_names", tuple(self.link_names) or tuple(f"link{i + 1}" for i in range(nb)))
        set_("joint_names", tuple(self.joint_names) or tuple(f"joint{i + 1}" for i in range(nb)))
        rules = []
        for e in self.mimic:
            if len(e) != 4:
                raise ModelError(f"{self.name}: mimic entries are (joint, source, multiplier, offset), got {e!r}")
            rules.append((e[0], e[1], passive_value(e[2], f"mimic joint {e[0]!r}: multiplier", False),
                          passive_value(e[3], f"mimic joint {e[0]!r}: offset", False)))
        for what, value in zip(("mimic", "coupling", "independent"),
                               resolve_mimic(self.name, self.joint_names, self.joint_type, rules)):
            set_(what, value)
        n = len(self.independent)
        set_("q", tuple(sp.Symbol(f"q{k + 1}", real=True) for k in range(n)))
        set_("v", tuple(sp.Symbol(f"qd{k + 1}", real=True) for k in range(n)))
        set_("a", tuple(sp.Symbol(f"qdd{k + 1}", real=True) for k in range(n)))

    @property
    def nbodies(self) -> int:
        return len(self.parent)

    @property
    def nv(self) -> int:
        """The number of coordinates: the independent joints (all joints without ``mimic``)."""
        return len(self.independent)

    def inertial_parameters(self) -> list:
        """All inertial parameters (10 * nbodies), body after body."""
        return [t for th in self.theta for t in th]

    def parameters(self) -> list[sp.Symbol]:
        """The free symbols of the model (lengths, masses, ..., gravity), sorted by name;
        the joint symbols are not parameters."""
        syms = set(self.gravity.free_symbols)
        for i in range(self.nbodies):
            for x in (self.joint_axis[i], self.X_tree_R[i], self.X_tree_p[i]):
                syms |= x.free_symbols
            for t in (*self.theta[i], self.armature[i], *(getattr(self, f)[i] for f, _ in PASSIVE_FIELDS)):
                syms |= t.free_symbols
        for _, _, r, o in self.mimic:
            syms |= r.free_symbols | o.free_symbols
        syms |= self.coulomb_smoothing.free_symbols
        return sorted(syms, key=lambda s: s.name)

    def rigid(self) -> "SymbolicModel":
        """The model without the passive elements (``damping``, ``coulomb``, ``stiffness``,
        ``spring_reference`` and ``armature`` zero), as :meth:`robodyn.Model.rigid`."""
        return self.replace(armature=(), damping=(), coulomb=(), stiffness=(), spring_reference=())

    @renamed_keywords(**OLD_FIELDS)
    def replace(self, **changes) -> "SymbolicModel":
        """A new model with some fields changed."""
        return replace(self, **changes)

    axis = renamed_attribute("axis", "joint_axis")
    R_tree = renamed_attribute("R_tree", "X_tree_R")
    p_tree = renamed_attribute("p_tree", "X_tree_p")
    inertia = renamed_attribute("inertia", "theta")
    qd = renamed_attribute("qd", "v")
    qdd = renamed_attribute("qdd", "a")

    def __repr__(self) -> str:
        rules = f", mimic: {', '.join(rule_text(e) for e in self.mimic)}" if self.mimic else ""
        return (f"SymbolicModel {self.name!r}: {self.nbodies} bodies, joints "
                f"{''.join('R' if t == 'revolute' else 'P' for t in self.joint_type)}{rules}, "
                f"parameters {[s.name for s in self.parameters()]}")


SymbolicModel.__init__ = renamed_keywords(**OLD_FIELDS)(SymbolicModel.__init__)


def from_model(model) -> SymbolicModel:
    """The :class:`SymbolicModel` of a numeric :class:`robodyn.Model` with exact numbers
    (module docstring): geometry, inertias, gravity and the joints' armature, damping,
    Coulomb friction (with its smoothing) and springs. Revolute and prismatic joints on a
    fixed base only. Stribeck friction, when the model has it, is not in the closed forms
    (a :class:`robodyn.RobodynWarning` says so). A :class:`robodyn.CoupledModel` gives the
    model of its full tree with its mimic joints (:mod:`.mimic`): the coordinates ``q1..qn``
    are its independent joints, as the numeric algorithms' (``M = G^T M_full G``,
    ``tau = G^T tau_full(P q + offset, G v, G a)``); couplings that are not trigonometric
    polynomials raise :class:`robodyn.ModelError`."""
    if isinstance(model, SymbolicModel):
        return model
    if is_coupled(model):  # the full tree, its mimic joints following their sources
        return from_model(model.full).replace(mimic=tuple((j, s, exact(r), exact(o)) for j, s, r, o in model.mimic))
    for kind in (J.SPHERICAL, J.HELICAL, J.PLANAR):
        if np.any(model.joint_type == kind):
            raise ModelError(f"model {model.name!r} has a {J.NAMES[kind]} joint; robodyn.symbolic derives "
                             "fixed-base trees of revolute and prismatic joints only")
    if model.floating_base or np.any(model.joint_type == J.FREE):
        raise ModelError(
            f"model {model.name!r} has a floating base (free joint); robodyn.symbolic derives "
            "fixed-base trees of revolute and prismatic joints only"
        )
    stribeck = np.asarray(getattr(model, "stribeck", np.zeros(0)), dtype=float)
    if np.any(stribeck != 0):
        warnings.warn(f"model {model.name!r}: the Stribeck friction of dofs {np.flatnonzero(stribeck).tolist()} is "
                      "not in the symbolic closed forms (damping, Coulomb friction and springs are)",
                      RobodynWarning, stacklevel=2)
    return SymbolicModel(
        parent=tuple(model.parent.tolist()),
        joint_type=tuple(J.NAMES[t] for t in model.joint_type),
        joint_axis=tuple([exact(a, snap=True) for a in ax] for ax in model.joint_axis),
        X_tree_R=tuple(sp.Matrix(3, 3, [exact(x, snap=True) for x in R.ravel()]) for R in model.X_tree_R),
        X_tree_p=tuple([exact(x) for x in p] for p in model.X_tree_p),
        theta=tuple([exact(x) for x in th] for th in model.theta),
        gravity=[exact(x) for x in model.gravity],
        armature=tuple(exact(a) for a in model.armature),
        name=model.name,
        link_names=model.link_names,
        joint_names=model.body_joint_names,
        damping=tuple(exact(x) for x in model.damping),
        coulomb=tuple(exact(x) for x in model.coulomb),
        stiffness=tuple(exact(x) for x in model.stiffness),
        spring_reference=tuple(exact(x) for x in model.spring_reference),
        coulomb_smoothing=exact(model.coulomb_smoothing),
    )


def with_inertia_symbols(model) -> SymbolicModel:
    """``model`` (numeric or symbolic) with the inertial parameters of body ``k`` replaced
    by ``m{k}, mx{k}, my{k}, mz{k}, Ixx{k}, Ixy{k}, Iyy{k}, Ixz{k}, Iyz{k}, Izz{k}``
    (1-based, :func:`inertia_symbols`); ``model.inertial_parameters()`` of the result is
    the parameter vector ``theta`` of ``tau = Y theta``."""
    sm = from_model(model)
    return sm.replace(theta=tuple(inertia_symbols(i + 1) for i in range(sm.nbodies)))


def _rx(a) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(a) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _T(R=None, p=(0, 0, 0)) -> sp.Matrix:
    T = sp.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = sp.Matrix(p)
    return T


def from_dh(links: Sequence, convention: str = "standard", gravity=(0, 0, -sp.Rational(981, 100)),
            name: str = "dh_robot") -> SymbolicModel:
    """A serial chain from a DH table whose entries are sympy expressions or numbers.

    ``links``: :class:`robodyn.DHLink` rows (``a, alpha, d, offset, joint, theta, mass, com,
    inertia, armature, damping, coulomb`` are read; ``inertia`` is 3 x 3 about the centre of
    mass in DH frame ``i``, ``com`` in DH frame ``i``, as in :func:`robodyn.from_dh`). Standard DH:
    ``T_{i-1,i} = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; modified (Craig):
    ``T_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``, with
    ``theta_i = q_i + offset`` (revolute) or ``d_i = q_i + offset`` (prismatic).
    Body ``i``'s frame is the joint frame (z along the joint axis); the part of the DH
    transform after the joint (standard DH: ``Tz(d) Tx(a) Rx(alpha)`` of a revolute joint)
    is folded into the next body's placement and into body ``i``'s inertial parameters.
    ``gravity`` defaults to ``(0, 0, -9.81)`` as an exact number; pass ``(0, 0, -g)`` with a
    symbol ``g`` for textbook forms.
    """
    if convention not in ("standard", "modified"):
        raise ValueError(f"convention must be 'standard' or 'modified', got {convention!r}")
    links = list(links)
    if not links:
        raise ModelError("from_dh: empty DH table")
    post_prev = sp.eye(4)
    R_tree, p_tree, inertia, types = [], [], [], []
    for i, L in enumerate(links, start=1):
        where = f"DH table ({convention}): link {i}"
        if L.joint not in JOINT_TYPES:
            raise ModelError(f"{where}: joint must be 'revolute' or 'prismatic', got {L.joint!r}")
        a, alpha, d, off, th = (exact(x) for x in (L.a, L.alpha, L.d, L.offset, L.theta))
        rev = L.joint == "revolute"
        if convention == "standard":
            pre = _T(_rz(off)) if rev else _T(_rz(th)) * _T(p=(0, 0, off))
            post = (_T(p=(0, 0, d)) if rev else sp.eye(4)) * _T(p=(a, 0, 0)) * _T(_rx(alpha))
        else:
            pre = _T(_rx(alpha)) * _T(p=(a, 0, 0))
            pre = pre * (_T(p=(0, 0, d)) * _T(_rz(off)) if rev else _T(_rz(th)) * _T(p=(0, 0, off)))
            post = sp.eye(4)
        X = post_prev * pre
        R_tree.append(X[:3, :3])
        p_tree.append(X[:3, 3])
        # inertia given in DH frame i = body frame * post: move it into the body frame
        Rp, pp = post[:3, :3], post[:3, 3]
        com = Rp * exact_vector(L.com, 3, f"{where}: com") + pp
        Ic = Rp * exact_matrix3(L.inertia, f"{where}: inertia") * Rp.T
        inertia.append([sp.expand(t) for t in inertial_parameters(L.mass, com, Ic)])
        types.append(L.joint)
        post_prev = post
    n = len(links)
    return SymbolicModel(
        parent=tuple(range(-1, n - 1)), joint_type=tuple(types), joint_axis=tuple([0, 0, 1] for _ in range(n)),
        X_tree_R=tuple(R_tree), X_tree_p=tuple(p_tree), theta=tuple(inertia), gravity=list(gravity),
        armature=tuple(getattr(L, "armature", 0) for L in links), name=name,
        damping=tuple(getattr(L, "damping", 0) for L in links), coulomb=tuple(getattr(L, "coulomb", 0) for L in links),
    )


def from_poe(twists, home, inertias: Sequence, *, parents=None, gravity=(0, 0, -sp.Rational(981, 100)),
             name: str = "poe_robot") -> SymbolicModel:
    """A :class:`SymbolicModel` from joint twists, home link poses and link inertias with
    sympy entries (or numbers): :func:`robodyn.from_poe`'s construction (Murray, Li & Sastry
    ch. 3-4), revolute and prismatic joints. ``inertias``: per link ``(mass, com, inertia)``
    in the link frame (``inertia`` 3 x 3 about the centre of mass)."""
    from ..io.poe import poe_tree

    sym = lambda x: sp.Matrix(x).applyfunc(exact)  # noqa: E731 (floats become exact rationals)
    tree = poe_tree([sym(list(t)) for t in twists], [sym(g) for g in home], parents, where="symbolic.from_poe")
    inertias = list(inertias)
    if len(inertias) != len(tree):
        raise ModelError(f"symbolic.from_poe: {len(tree)} twists need {len(tree)} inertias, got {len(inertias)}")
    types, theta = [], []
    for i, ((kind, *_rest, offset), (mass, com, Ic)) in enumerate(zip(tree, inertias)):
        if kind not in JOINT_TYPES:
            raise ModelError(f"symbolic.from_poe: joint {i + 1}: {kind} joints are not derived symbolically")
        types.append(kind)
        theta.append([sp.expand(t) for t in inertial_parameters(mass, exact_vector(com, 3, "com") + offset, Ic)])
    return SymbolicModel(parent=tuple(t[1] for t in tree), joint_type=tuple(types),
                         joint_axis=tuple(t[2] for t in tree), X_tree_R=tuple(t[4] for t in tree),
                         X_tree_p=tuple(t[5] for t in tree), theta=tuple(theta), gravity=list(gravity), name=name)
