"""Generated code from the recursions: fast closed-form functions without expanded terms.

    M(q)          composite-rigid-body algorithm (:mod:`.crba`)
    tau(q, v, a), g(q) = tau(q, 0, 0), C_v(q, v) = tau(q, v, 0) without gravity
                  recursive Newton-Euler algorithm (:mod:`.newton_euler`)
    tau_p(q, v)   the joints' passive forces (no recursion: one expression per joint,
                  :func:`.model.passive_forces`), added to ``tau`` unless ``friction=False``

run once on symbols (:class:`._emit.Emitter`) and written as straight-line code, one
assignment per intermediate scalar: ``sin q_k`` and ``cos q_k`` once each, then the entries
of the joint rotations, velocities, composite inertias and forces, with every zero and one of
the model's numbers folded away. Nothing is expanded, so the code of the Panda's ``M`` has
about 200 assignments (550 arithmetic operations) where its expanded form
(:func:`.equations_of_motion`) has 6,155 monomials, and it is generated and compiled in one
to two seconds. The values are the same
functions of ``q`` (exact arithmetic on the model's numbers until the code is printed).
Models with free symbols (:func:`.with_inertia_symbols`, symbolic DH tables) give functions
that take ``params`` as the expanded forms do. Reference: W. Khalil, E. Dombre, *Modeling,
Identification and Control of Robots*, Hermes 2002, chapter 9 ("customised" symbolic
models); R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, tables 5.1, 6.2.
"""

from __future__ import annotations

from . import codegen, crba, newton_euler
from ._emit import Emitter
from ._terms import GeneratedCode, check_form, check_term, signature
from .model import SymbolicModel, from_model, passive_forces

# the terms of the generated code by the recursions, and how each is evaluated
RECURSIONS = {
    "M": "evaluated by the composite-rigid-body recursion",
    "C_v": "evaluated by the Newton-Euler recursion (a = 0, no gravity)",
    "g": "evaluated by the Newton-Euler recursion (v = a = 0)",
    "tau": "evaluated by the Newton-Euler recursion",
    "tau_p": "written out joint by joint",
}


def tau_description(name: str, how: str, friction: bool) -> str:
    """``how`` a term is evaluated, saying for ``tau`` and ``tau_p`` whether the passive
    forces are in (``friction``)."""
    if name in ("tau", "tau_p") and not friction:
        return f"{how}; without the joints' friction and springs (friction=False)"
    return how


def recursive_program(model: SymbolicModel, name: str, friction: bool = True) -> codegen.Program:
    """The straight-line :class:`~.codegen.Program` of term ``name`` (one of ``RECURSIONS``);
    ``tau`` and ``tau_p`` with the joints' passive forces unless ``friction=False``."""
    name = check_term(name, RECURSIONS)
    n = model.nv
    passive = passive_forces(model) if friction else [0] * n
    if name == "M":
        em = Emitter(model)
        outputs, shape = [x for row in crba.mass_matrix(em) for x in row], (n, n)
    elif name == "tau_p":
        em = Emitter(model)
        outputs, shape = passive, (n,)
    else:
        moving = model.replace(gravity=[0, 0, 0]) if name == "C_v" else model
        em = Emitter(moving, rates=name != "g", accelerations=name == "tau")
        outputs, shape = newton_euler.recursion(em)[0], (n,)
        if name == "tau":
            outputs = [t + p for t, p in zip(outputs, passive)]
    args, doc = signature(model, name, tau_description(name, RECURSIONS[name], friction))
    return codegen.straight_line(name, em.assignments, outputs, shape, args, em.trig(), doc)


class RecursiveDynamics(GeneratedCode):
    """Generated functions of ``M``, ``C_v``, ``g``, ``tau`` and ``tau_p`` of one model by the
    recursions (module docstring), without deriving the expanded equations of motion;
    ``friction``: whether ``tau`` includes the passive forces ``tau_p``."""

    default_c_terms = ("M", "C_v", "g", "tau")

    def __init__(self, model: SymbolicModel, friction: bool = True):
        self.model = model
        self.friction = bool(friction)
        self.n = model.nv
        self.parameters = model.parameters()
        self._programs = {}

    def __repr__(self) -> str:
        return f"RecursiveDynamics({self.model.name!r}, n={self.n}{'' if self.friction else ', friction=False'})"

    def program(self, name: str, form: str = "auto") -> codegen.Program:
        """The straight-line :class:`~.codegen.Program` of a term: ``"M"``, ``"C_v"``,
        ``"g"``, ``"tau"`` or ``"tau_p"``. ``form`` is ``"auto"`` or ``"recursive"`` (the same
        here); expanded forms need :func:`.equations_of_motion`."""
        check_form(form)
        if form == "expanded":
            raise ValueError("form='expanded' needs the derived equations: use equations_of_motion(model)")
        name = check_term(name, RECURSIONS)
        if name not in self._programs:
            self._programs[name] = recursive_program(self.model, name, self.friction)
        return self._programs[name]


def recursive_dynamics(model, *, friction: bool = True) -> RecursiveDynamics:
    """Fast generated code for ``M``, ``C_v``, ``g``, ``tau`` and ``tau_p`` of ``model`` (a
    :class:`robodyn.Model` with revolute and prismatic joints on a fixed base, a
    :class:`robodyn.CoupledModel` of one (the terms of its independent coordinates,
    :mod:`.mimic`), or a :class:`SymbolicModel`) by the recursions, without the expanded
    derivation::

        rec = rd.symbolic.recursive_dynamics(rd.models.load("panda"))
        M = rec.to_numba("M")          # M(q): (..., 7, 7), one state in about a microsecond
        rec.to_c("gen/")               # gen/panda_dynamics.{h,c}: panda_M, _C_v, _g, _tau

    The functions equal those of :meth:`.EquationsOfMotion.to_function` (which uses the
    same recursions for these terms by default). ``tau`` includes the joints' passive forces
    ``tau_p`` (damping, Coulomb friction, springs) as ``robodyn.rnea`` does, unless
    ``friction=False``.
    """
    return RecursiveDynamics(from_model(model), friction)
