"""Mimic joints of a symbolic model: joints that follow another joint, as :class:`robodyn.CoupledModel`.

A mimic joint ``j`` follows a source joint ``s``: ``q_j = r q_s + o`` (URDF ``<mimic joint="s"
multiplier="r" offset="o"/>``). It is not a coordinate: the symbols ``q1..qn`` (``v``, ``a``)
of a :class:`~.model.SymbolicModel` with mimic joints are those of its independent joints, in
body order, and every derivation runs on the full tree with

    q_full = P q + o,      v_full = G v,      a_full = G a,
    tau = G^T tau_full,    M = G^T M_full G,   T = T_full(q_full, G v),   U = U_full(q_full)

(``G`` (nb, n): a one in the row of each independent joint, ``r`` in the row of a mimic joint,
in the column of its source). The passive forces of a mimic joint (damping, Coulomb friction,
spring) and its armature act through ``G^T``, as the numeric ``robodyn.rnea`` of a coupled
model. The equations stay in the exact trigonometric polynomials of :mod:`._ring`:

* a revolute joint following a revolute joint with an integer multiplier ``r``:
  ``sin(r q + o) = sin(r q) cos o + cos(r q) sin o`` with ``sin(r q)``, ``cos(r q)`` by the
  multiple-angle rules (``r = +-1``, the usual gripper, is ``+-sin q``, ``cos q``), and
  ``cos o``, ``sin o`` exact constants;
* a prismatic joint following a prismatic or a revolute joint, with any multiplier:
  ``x_j = r q_s + o`` is linear (a revolute source's angle ``q_s`` itself joins ``sin q_s``,
  ``cos q_s`` among the generators);

other couplings (a revolute joint following a revolute joint with a non-integer multiplier,
or following a prismatic joint) are not trigonometric polynomials of the coordinates:
:func:`resolve` refuses them with a :class:`robodyn.ModelError` naming the joint and the
multiplier. Chains (a mimic of a mimic) resolve to the independent joint, as in
:class:`robodyn.CoupledModel`.
"""

from __future__ import annotations

from typing import Sequence

import sympy as sp

from ..coupling import follow_chains
from ..errors import ModelError


def resolve(name: str, joint_names: Sequence[str], joint_type: Sequence[str], mimic: Sequence[tuple]):
    """The couplings of a model named ``name`` with joints ``joint_names`` (one per body) of
    types ``joint_type``, from ``mimic``: ``(joint, source, multiplier, offset)`` entries with
    the joints by name and exact sympy ``multiplier``, ``offset``.

    Returns ``(entries, coupling, independent)``: the entries with each source followed to its
    independent joint (``q_j = r q_s + o`` composed along the chain), per body the triple
    ``(k, r, o)`` (the body's joint is ``r q_k + o`` of coordinate ``k``; ``(k, 1, 0)`` for
    independent joint ``k``) and the bodies of the coordinates (n,). ``ModelError`` for unknown
    joints, a joint that mimics itself or two joints, cycles, and the couplings that are not
    trigonometric polynomials (module docstring).
    """
    body_of = {joint: i for i, joint in enumerate(joint_names)}
    entries = []
    for joint, (source, r, o) in follow_chains(name, joint_names, mimic).items():
        r, o = sp.expand(r), sp.expand(o)
        check_coupling(name, joint, source, joint_type[body_of[joint]], joint_type[body_of[source]], r)
        entries.append((joint, source, r, o))
    follows = {body_of[j]: (body_of[s], r, o) for j, s, r, o in entries}
    independent = tuple(i for i in range(len(joint_names)) if i not in follows)
    column = {b: k for k, b in enumerate(independent)}
    coupling = []
    for i in range(len(joint_names)):
        s, r, o = follows.get(i, (i, sp.Integer(1), sp.Integer(0)))
        coupling.append((column[s], r, o))
    return tuple(entries), tuple(coupling), independent


def check_coupling(name: str, joint: str, source: str, kind: str, source_kind: str, r) -> None:
    """``ModelError`` unless ``joint`` (of type ``kind``) following ``source`` (``source_kind``)
    with multiplier ``r`` keeps the equations trigonometric polynomials (module docstring)."""
    r = sp.sympify(r)
    shown = f"{float(r):g}" if r.is_number else str(r)
    how = (f"{name}: mimic joint {joint!r} ({kind}) follows {source!r} ({source_kind}) with multiplier {shown}; "
           "robodyn.symbolic derives a revolute mimic joint of a revolute source with an integer multiplier "
           "(and prismatic mimic joints with any multiplier)")
    instead = ("; derive model.full instead (the mimic joints as independent joints: load_urdf(..., "
               "mimic='independent'))")
    if kind == "revolute" and source_kind != "revolute":
        raise ModelError(f"{how}: sin and cos of a multiple of a length are not trigonometric polynomials of "
                         f"the coordinates{instead}")
    if kind == "revolute" and not r.is_Integer:
        raise ModelError(f"{how}: sin({shown} q) and cos({shown} q) are not polynomials in sin q, cos q{instead}")


def rule_text(entry) -> str:
    """``"joint = r source + o"`` of a resolved entry, numbers as ``%g`` (as the summary of a
    :class:`robodyn.CoupledModel`), for summaries."""
    joint, source, r, o = entry
    if o == 0:
        return f"{joint} = {_number(r)} {source}"
    sign, o = ("-", -o) if o.is_number and o < 0 else ("+", o)
    return f"{joint} = {_number(r)} {source} {sign} {_number(o)}"


def _number(x) -> str:
    return f"{float(x):g}" if x.is_number else f"({x})"
