"""Robots of the textbooks as symbolic models, named after the book they follow.

Built from the book's own description, joint twists and link frames at the centres of mass
(:func:`robodyn.symbolic.from_poe`), with the book's symbols: lengths ``l0, l1, l2``, centres
of mass at ``r0, r1, ...`` along the links, masses ``m1, ...`` and principal inertias
``Ix1, Iy1, Iz1, ...`` (link frames aligned with the base at ``q = 0``). Gravity is
``(0, 0, -g)`` with the symbol ``g``. Their ``equations_of_motion(...).M`` are the books'
inertia matrices (tested).

    planar_2r_mls()   Murray, Li & Sastry (1994), ch. 4: the two-link planar arm, eq. 4.11
    elbow_mls()       Murray, Li & Sastry (1994), ch. 3-4: the elbow manipulator (RRR: a
                      vertical waist, shoulder and elbow about -x), home pose along +y
    scara_mls()       Murray, Li & Sastry (1994), Example 4.4, Figure 4.6: the SCARA, RRRP
                      (three vertical revolute joints, a vertical prismatic one), unlike
                      ``robodyn.models.load("scara")`` (RRPR, Spong's)
"""

from __future__ import annotations

import sympy as sp

from .model import SymbolicModel, from_poe

G = sp.Symbol("g", positive=True)


def _twist(w, q) -> list:
    """The unit twist ``(-w x q, w)`` of a revolute joint about the line through ``q`` along ``w``."""
    w, q = sp.Matrix(w), sp.Matrix(q)
    return list(-w.cross(q)) + list(w)


def _at(p) -> sp.Matrix:
    """The pose with identity rotation at ``p``."""
    return sp.Matrix([[1, 0, 0, p[0]], [0, 1, 0, p[1]], [0, 0, 1, p[2]], [0, 0, 0, 1]])


def _links(n: int) -> list:
    """``(m_i, 0, diag(Ix_i, Iy_i, Iz_i))`` for i = 1..n: link frames at the centres of mass."""
    out = []
    for i in range(1, n + 1):
        m, ix, iy, iz = sp.symbols(f"m{i} Ix{i} Iy{i} Iz{i}", positive=True)
        out.append((m, (0, 0, 0), sp.diag(ix, iy, iz)))
    return out


def planar_2r_mls() -> SymbolicModel:
    """MLS's two-link planar arm: joints about z at the origin and at ``(l1, 0, 0)``, centres
    of mass at ``r1`` and ``l1 + r2`` along x (the arm moves in the x-y plane). ``M = [[a + 2 b c2, d + b c2], [d + b c2, d]]``, ``a = Iz1 + Iz2 + m1 r1^2 +
    m2 (l1^2 + r2^2)``, ``b = m2 l1 r2``, ``d = Iz2 + m2 r2^2`` (eq. 4.11)."""
    l1, r1, r2 = sp.symbols("l1 r1 r2", positive=True)
    twists = [_twist((0, 0, 1), (0, 0, 0)), _twist((0, 0, 1), (l1, 0, 0))]
    home = [_at((r1, 0, 0)), _at((l1 + r2, 0, 0))]
    return from_poe(twists, home, _links(2), gravity=(0, 0, -G), name="planar_2r_mls")


def elbow_mls() -> SymbolicModel:
    """MLS's elbow manipulator: the waist about z through the origin, shoulder and elbow about
    -x through ``(0, 0, l0)`` and ``(0, l1, l0)``; centres of mass at ``(0, 0, r0)``,
    ``(0, r1, l0)`` and ``(0, l1 + r2, l0)``. Its M has ``M11 = Iy2 s2^2 + Iy3 s23^2 + Iz1 +
    Iz2 c2^2 + Iz3 c23^2 + m2 r1^2 c2^2 + m3 (l1 c2 + r2 c23)^2``, ``M22 = Ix2 + Ix3 + m3 l1^2 +
    m2 r1^2 + m3 r2^2 + 2 m3 l1 r2 c3``, ``M23 = Ix3 + m3 r2^2 + m3 l1 r2 c3``,
    ``M33 = Ix3 + m3 r2^2`` and zeros elsewhere."""
    l0, l1, r0, r1, r2 = sp.symbols("l0 l1 r0 r1 r2", positive=True)
    twists = [_twist((0, 0, 1), (0, 0, 0)), _twist((-1, 0, 0), (0, 0, l0)), _twist((-1, 0, 0), (0, l1, l0))]
    home = [_at((0, 0, r0)), _at((0, r1, l0)), _at((0, l1 + r2, l0))]
    return from_poe(twists, home, _links(3), gravity=(0, 0, -G), name="elbow_mls")


def scara_mls() -> SymbolicModel:
    """MLS's SCARA (Example 4.4, Figure 4.6): three revolute joints about z through the
    origin, ``(0, l1, 0)`` and ``(0, l1 + l2, 0)``, then a prismatic joint along z; centres of
    mass at ``(0, r1, l0)``, ``(0, l1 + r2, l0)``, ``(0, l1 + l2, l0 - r3)``,
    ``(0, l1 + l2, l0 - r4)``. ``M = [[a + b + 2 c c2, b + c c2, d, 0], [b + c c2, b, d, 0],
    [d, d, d, 0], [0, 0, 0, m4]]`` with ``a = Iz1 + r1^2 m1 + l1^2 (m2 + m3 + m4)``,
    ``b = Iz2 + Iz3 + Iz4 + l2^2 (m3 + m4) + m2 r2^2``, ``c = l1 l2 (m3 + m4) + l1 m2 r2``,
    ``d = Iz3 + Iz4``."""
    l0, l1, l2, r1, r2, r3, r4 = sp.symbols("l0 l1 l2 r1 r2 r3 r4", positive=True)
    twists = [_twist((0, 0, 1), (0, 0, 0)), _twist((0, 0, 1), (0, l1, 0)), _twist((0, 0, 1), (0, l1 + l2, 0)),
              [0, 0, 1, 0, 0, 0]]
    home = [_at((0, r1, l0)), _at((0, l1 + r2, l0)), _at((0, l1 + l2, l0 - r3)), _at((0, l1 + l2, l0 - r4))]
    return from_poe(twists, home, _links(4), gravity=(0, 0, -G), name="scara_mls")
