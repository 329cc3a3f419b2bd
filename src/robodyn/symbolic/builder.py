"""A builder of symbolic models: links and joints whose masses, lengths, inertias and axes are
sympy expressions, as :class:`robodyn.ModelBuilder` builds numeric ones.

    import sympy as sp
    from robodyn import symbolic as S
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    b = S.ModelBuilder("arm", gravity=(0, -g, 0))
    b.add_link("link1", mass=m1, com=(l1 / 2, 0, 0), inertia=rd.inertia.rod(m1, l1, "x"))
    b.add_link("link2", mass=m2, com=(l2 / 2, 0, 0), inertia=rd.inertia.rod(m2, l2, "x"))
    b.add_joint("joint1", "revolute", "world", "link1", axis=(0, 0, 1))
    b.add_joint("joint2", "revolute", "link1", "link2", xyz=(l1, 0, 0), axis=(0, 0, 1))
    model = b.build()                                   # a SymbolicModel

The graph is checked as the numeric builder checks it (names, one root, no cycles; a parent
``"world"`` needs no link), bodies are ordered depth first with children in the order their
joints were added, and fixed joints merge their child link into the parent body (its
inertial parameters moved by the exact parallel-axis rule). Joints: ``revolute`` (or
``continuous``), ``prismatic`` and ``fixed``; the base is fixed. A joint's frame is at ``xyz``
with rotation ``rotation`` (3 x 3) in the parent link's frame; ``axis`` is a unit vector in it.
A moving joint takes its passive elements as keywords, numbers or expressions:
``armature``, ``damping``, ``coulomb``, ``stiffness`` and ``spring_reference`` (the fields of
:class:`.model.SymbolicModel`; checked as the numeric builder checks them), and the builder
the model's ``coulomb_smoothing``.
"""

from __future__ import annotations

import sympy as sp

from ..builder import WORLD, JointEntry, LinkEntry, ModelBuilder as NumericBuilder
from ..model import ModelError
from .model import (PASSIVE_FIELDS, SymbolicModel, exact_matrix3, exact_vector, inertial_parameters,
                    passive_value, skew)

KINDS = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed"}


def _theta_in_parent(R, p, theta):
    """10 inertial parameters of a body given in a child frame placed at ``(R, p)`` in the
    parent frame, expressed in the parent frame: ``h' = R h + m p``,
    ``I' = R I R^T + m [p]x^T [p]x - [p]x [R h]x - [R h]x [p]x`` (about the parent origin)."""
    m, h = theta[0], sp.Matrix(theta[1:4])
    Io = sp.Matrix([[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]])
    Rh = R * h
    P, H = skew(p), skew(Rh)
    I = R * Io * R.T + m * P.T * P - P * H - H * P
    hp = Rh + m * p
    return [m, hp[0], hp[1], hp[2], I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]]


class ModelBuilder(NumericBuilder):
    """Collects links and joints with sympy entries; :meth:`build` returns a
    :class:`SymbolicModel` (module docstring)."""

    def __init__(self, name: str = "robot", gravity=(0, 0, -sp.Rational(981, 100)), source: str = "<symbolic model>",
                 *, coulomb_smoothing=0):
        super().__init__(name, source=source)
        self.symbolic_gravity = exact_vector(gravity, 3, "gravity")
        self.coulomb_smoothing = passive_value(coulomb_smoothing, "coulomb_smoothing", True)

    def add_link(self, name: str, mass=0, com=(0, 0, 0), inertia=None, where: str | None = None) -> None:
        """A rigid body: ``mass``, ``com`` (3,) in the link frame, ``inertia`` (3 x 3) about
        the centre of mass (sympy expressions or numbers)."""
        where = where or f"{self.source}: link {name!r}"
        if name in self._links:
            raise ModelError(f"{where}: duplicate link name {name!r} (first defined at {self._links[name].where})")
        Ic = sp.zeros(3) if inertia is None else exact_matrix3(inertia, f"{where}: inertia")
        if Ic != Ic.T:
            raise ModelError(f"{where}: inertia is not symmetric")
        self._links[name] = LinkEntry(name, inertial_parameters(mass, com, Ic), where)

    def add_joint(self, name: str, type: str, parent: str, child: str, xyz=(0, 0, 0), rotation=None,
                  axis=(1, 0, 0), armature=0, where: str | None = None, *, damping=0, coulomb=0, stiffness=0,
                  spring_reference=0) -> None:
        """A joint from ``parent`` to ``child`` at ``xyz`` / ``rotation`` in the parent link's
        frame, moving about or along the unit ``axis`` (module docstring), with rotor inertia
        ``armature``, viscous ``damping``, ``coulomb`` friction and a spring
        ``stiffness (q - spring_reference)`` (the passive forces of
        :func:`.model.passive_torque`; a fixed joint has none)."""
        where = where or f"{self.source}: joint {name!r}"
        if type not in KINDS:
            raise ModelError(f"{where}: joint type {type!r}: a symbolic model has {sorted(KINDS)} joints")
        R = sp.eye(3) if rotation is None else exact_matrix3(rotation, f"{where}: rotation")
        ax = exact_vector(axis, 3, f"{where}: axis")
        if type != "fixed" and not (ax.free_symbols or sp.simplify(ax.dot(ax) - 1) == 0):
            raise ModelError(f"{where}: axis must be a unit vector, got {list(ax)}")
        passive = dict(damping=damping, coulomb=coulomb, stiffness=stiffness, spring_reference=spring_reference)
        limits = dict(armature=passive_value(armature, f"{where}: armature", True))
        for what, nonnegative in PASSIVE_FIELDS:
            limits[what] = passive_value(passive[what], f"{where}: {what}", nonnegative)
        if type == "fixed" and any(x != 0 for x in limits.values()):
            raise ModelError(f"{where}: a fixed joint has no armature, friction or spring")
        self._joints.append(JointEntry(name, KINDS[type], parent, child, R, exact_vector(xyz, 3, f"{where}: xyz"), ax,
                                   limits, where))

    def build(self) -> SymbolicModel:
        """The :class:`SymbolicModel` (fixed base)."""
        root, children = self._check_graph()
        parent, types, axes, XR, Xp, theta, links, joints = [], [], [], [], [], [], [], []
        passive = {what: [] for what in ("armature", *(f for f, _ in PASSIVE_FIELDS))}
        place = {root: (-1, sp.eye(3), sp.zeros(3, 1))}   # link -> (body, R, p) of its frame in the body
        stack = list(reversed(children[root]))            # depth first, children in the order added
        while stack:
            jt = stack.pop()
            body, R, p = place[jt.parent]
            Rj, pj = R * jt.R, p + R * jt.p
            if jt.type == "fixed":
                place[jt.child] = (body, Rj, pj)
            else:
                parent.append(body)
                types.append(jt.type)
                axes.append(jt.axis)
                XR.append(Rj)
                Xp.append(pj)
                theta.append([0] * 10)
                for what, values in passive.items():
                    values.append(jt.limits[what])
                links.append(jt.child)
                joints.append(jt.name)
                place[jt.child] = (len(parent) - 1, sp.eye(3), sp.zeros(3, 1))
            stack.extend(reversed(children[jt.child]))
        for name, (body, R, p) in place.items():
            if body >= 0:
                moved = _theta_in_parent(R, p, self._links[name].theta)
                theta[body] = [sp.expand(a + b) for a, b in zip(theta[body], moved)]
        if not parent:
            raise ModelError(f"{self.source}: no moving joint")
        return SymbolicModel(parent=tuple(parent), joint_type=tuple(types), joint_axis=tuple(axes),
                             X_tree_R=tuple(XR), X_tree_p=tuple(Xp), theta=tuple(theta),
                             gravity=self.symbolic_gravity, name=self.name, link_names=tuple(links),
                             joint_names=tuple(joints), coulomb_smoothing=self.coulomb_smoothing,
                             **{what: tuple(values) for what, values in passive.items()})


__all__ = ["ModelBuilder", "WORLD"]
