"""Planar robots in a vertical plane: ``pendulum``, ``double_pendulum`` and ``planar_2r``.

All three are serial chains of revolute joints with parallel axes, built with
:func:`robodyn.from_dh` (standard DH, ``a_i`` = link length, ``alpha_i = d_i = 0``) on a
rotated base frame, so that the DH frames ``frame0`` (first joint) to ``frame2`` are
available. World gravity is ``(0, 0, -9.81)``; every chain moves in the world x-z plane.

Pendulums (``theta = 0`` is UPRIGHT)
------------------------------------
Joint axes along world ``+y``; ``q = 0`` points every link straight up (``+z``) and a
positive angle tilts the link towards ``+x``. Each link is a **point mass** at its distal
end (the DH frame ``frame<i>``), with zero rotational inertia (a valid rigid body).

``pendulum``: m = 1 kg at L = 1 m. Link position ``(L sin q, 0, L cos q)``, and

    m L^2 qdd = tau + m g L sin(q)        (g = 9.81)

``double_pendulum``: m1 = m2 = 1 kg, L1 = L2 = 1 m, ``q2`` relative to link 1. With
``c2 = cos q2``, ``M qdd + C qd + g(q) = tau``:

    M = [[(m1 + m2) L1^2 + m2 L2^2 + 2 m2 L1 L2 c2,  m2 L2^2 + m2 L1 L2 c2],
         [m2 L2^2 + m2 L1 L2 c2,                     m2 L2^2             ]]
    g(q) = -g [(m1 + m2) L1 sin q1 + m2 L2 sin(q1 + q2),  m2 L2 sin(q1 + q2)]

``planar_2r`` (the two-link planar elbow arm)
---------------------------------------------
Thin uniform rods (no inertia about their own axis): m1 = 10 kg, m2 = 5 kg,
l1 = l2 = 1 m, centres of mass at r1 = l1 / 2, r2 = l2 / 2, inertias about the centres
``Iz_i = m_i l_i^2 / 12`` about the joint-axis direction. Joint axes along world ``-y``, so
that in the usual front view (x to the right, z up) angles are counter-clockwise: ``q1``
from the horizontal ``+x`` axis, ``q2`` relative to link 1, and positive angles raise
the arm. This is the textbook convention of Murray, Li & Sastry (1994, ch. 4, two-link
planar manipulator: the ``alpha, beta, delta`` notation) and of Spong, Hutchinson &
Vidyasagar (2006, ch. 7, planar elbow manipulator, gravity in the plane):

    alpha = Iz1 + Iz2 + m1 r1^2 + m2 (l1^2 + r2^2)   = 10
    beta  = m2 l1 r2                                  = 2.5
    delta = Iz2 + m2 r2^2                             = 5/3
    M(q)  = [[alpha + 2 beta cos q2,  delta + beta cos q2],
             [delta + beta cos q2,    delta             ]]
    g(q)  = [(m1 r1 + m2 l1) g cos q1 + m2 r2 g cos(q1 + q2),  m2 r2 g cos(q1 + q2)]

References: R. M. Murray, Z. Li, S. S. Sastry, *A Mathematical Introduction to Robotic
Manipulation*, CRC Press 1994, chapter 4; M. W. Spong, S. Hutchinson, M. Vidyasagar,
*Robot Modeling and Control*, Wiley 2006, chapter 7. The numbers are this library's choice.
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model
from ..inertia import cylinder
from ._common import homogeneous

# Base frame 0 of the pendulums in the world: x0 = world z (up), y0 = world x, z0 = world y.
PENDULUM_BASE = homogeneous(np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]))
# Base frame 0 of planar_2r: x0 = world x, y0 = world z (up), z0 = world -y (Rx(pi/2)).
PLANAR_2R_BASE = homogeneous(np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]))

PENDULUM = dict(m=1.0, L=1.0)
DOUBLE_PENDULUM = dict(m1=1.0, m2=1.0, L1=1.0, L2=1.0)
PLANAR_2R = dict(m1=10.0, m2=5.0, l1=1.0, l2=1.0)


def _chain(name: str, lengths, masses, coms, inertias, base) -> Model:
    links = [DHLink(a=l, alpha=0.0, d=0.0, mass=m, com=c, inertia=I)
             for l, m, c, I in zip(lengths, masses, coms, inertias)]
    return from_dh(links, base=base, name=name)


def _point_mass_chain(name: str, lengths, masses) -> Model:
    n = len(lengths)
    return _chain(name, lengths, masses, [(0.0, 0.0, 0.0)] * n, [np.zeros((3, 3))] * n, PENDULUM_BASE)


def pendulum() -> Model:
    """Simple pendulum, point mass, ``q = 0`` upright (see the module docstring)."""
    return _point_mass_chain("pendulum", [PENDULUM["L"]], [PENDULUM["m"]])


def double_pendulum() -> Model:
    """Double pendulum of two point masses, ``q = 0`` upright (see the module docstring)."""
    p = DOUBLE_PENDULUM
    return _point_mass_chain("double_pendulum", [p["L1"], p["L2"]], [p["m1"], p["m2"]])


def planar_2r() -> Model:
    """Two-link planar elbow arm of thin rods in a vertical plane (see the module docstring)."""
    p = PLANAR_2R
    lengths, masses = [p["l1"], p["l2"]], [p["m1"], p["m2"]]
    # DH frame i sits at the distal end of rod i, x_i along the rod: the centre is at -l_i/2.
    coms = [(-l / 2.0, 0.0, 0.0) for l in lengths]
    inertias = [cylinder(m, 0.0, l, "x") for m, l in zip(masses, lengths)]
    return _chain("planar_2r", lengths, masses, coms, inertias, PLANAR_2R_BASE)
