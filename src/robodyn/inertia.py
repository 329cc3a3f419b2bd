"""Rotational inertias (3 x 3) of uniform bodies, the parallel-axis shift and rotation::

    import robodyn as rd
    I = rd.inertia.rod(10.0, 1.0, "x")                       # m L^2 / 12 about its centre
    I_end = rd.inertia.shift(I, 10.0, (0.5, 0, 0))            # m L^2 / 3 about its end
    b.add_link("link1", mass=10.0, com=(0.5, 0, 0), inertia=I)  # ModelBuilder takes I about the CoM

Every shape's inertia is about its centre of mass, in a frame whose axes are the shape's:
``axis`` is ``"x"``, ``"y"``, ``"z"`` or a unit vector. Formulas (uniform density, mass ``m``)::

    rod(m, L, axis)               m L^2 / 12 about the axes across it, 0 along it
    cylinder(m, r, L, axis)       m r^2 / 2 about its axis, m (3 r^2 + L^2) / 12 across it
    box(m, (a, b, c))             m / 12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2)
    sphere(m, r)                  2/5 m r^2 (solid), 2/3 m r^2 (hollow=True: a thin shell)
    point(m, p)                   m (|p|^2 1 - p p^T): a point mass at p, about the origin
    shift(I_c, m, d)              I_c + m (|d|^2 1 - d d^T): about the point from which the
                                  centre of mass is at d (the parallel-axis theorem)
    rotate(I, R)                  R I R^T: the same inertia in axes rotated by R
    parameters(m, c, I_c)         the 10 inertial parameters robodyn's models hold (theta)

Numbers give NumPy arrays; sympy symbols or expressions anywhere in the arguments give sympy
matrices (exact), for :mod:`robodyn.symbolic`. Reference: Siciliano et al., *Robotics:
Modelling, Planning and Control* (2009), section 7.2.1; any table of moments of inertia.
"""

from __future__ import annotations

import numpy as np

from ._algebra import Algebra, is_symbolic

__all__ = ["rod", "cylinder", "box", "sphere", "point", "shift", "rotate", "axisymmetric", "parameters"]


def _nonnegative(x, what: str):
    if not is_symbolic(x) and not (np.isfinite(x) and x >= 0):
        raise ValueError(f"{what}: expected a finite number >= 0, got {x!r}")
    return x


def _axis(alg: Algebra, axis):
    if isinstance(axis, str):
        if axis not in ("x", "y", "z"):
            raise ValueError(f"axis: expected 'x', 'y', 'z' or a unit vector, got {axis!r}")
        return alg.vector([1 if axis == c else 0 for c in "xyz"], "axis")
    a = alg.vector(axis, "axis")
    n = alg.dot(a, a)
    if not alg.symbolic and abs(n - 1.0) > 1e-9:
        raise ValueError(f"axis: expected a unit vector, got {axis!r} (norm {np.sqrt(n):.6g})")
    return a


def axisymmetric(axial, transverse, axis="z"):
    """``axial a a^T + transverse (1 - a a^T)``: moment ``axial`` about the unit axis ``a``,
    ``transverse`` about every axis across it."""
    alg = Algebra(is_symbolic(axial, transverse, 0 if isinstance(axis, str) else axis))
    a = _axis(alg, axis)
    aa = alg.outer(a)
    return aa * axial + (alg.eye() - aa) * transverse


def rod(mass, length, axis="x"):
    """A thin uniform rod of ``length`` along ``axis``, about its centre: ``m L^2 / 12``
    across it, 0 along it."""
    _nonnegative(mass, "mass"), _nonnegative(length, "length")
    return axisymmetric(0 * mass, mass * length**2 / 12, axis)


def cylinder(mass, radius, length, axis="z"):
    """A uniform solid cylinder about its centre: ``m r^2 / 2`` about its axis,
    ``m (3 r^2 + L^2) / 12`` across it (``radius = 0``: a rod; ``length = 0``: a disk)."""
    _nonnegative(mass, "mass"), _nonnegative(radius, "radius"), _nonnegative(length, "length")
    return axisymmetric(mass * radius**2 / 2, mass * (3 * radius**2 + length**2) / 12, axis)


def box(mass, size):
    """A uniform box with edges ``size = (a, b, c)`` along x, y, z, about its centre:
    ``m / 12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2)``."""
    alg = Algebra(is_symbolic(mass, size))
    if len(size) != 3:
        raise ValueError(f"size: expected 3 edge lengths, got {size!r}")
    a, b, c = (_nonnegative(x, "size") for x in size)
    _nonnegative(mass, "mass")
    diag = [mass * (b**2 + c**2) / 12, mass * (a**2 + c**2) / 12, mass * (a**2 + b**2) / 12]
    return alg.sp.diag(*diag) if alg.symbolic else np.diag(np.array(diag, dtype=float))


def sphere(mass, radius, hollow: bool = False):
    """A uniform solid sphere about its centre, ``2/5 m r^2`` (a thin shell with
    ``hollow=True``: ``2/3 m r^2``)."""
    _nonnegative(mass, "mass"), _nonnegative(radius, "radius")
    alg = Algebra(is_symbolic(mass, radius))
    k = (alg.sp.Rational(2, 3) if hollow else alg.sp.Rational(2, 5)) if alg.symbolic else (2 / 3 if hollow else 0.4)
    return alg.eye() * (k * mass * radius**2)


def point(mass, position):
    """A point mass at ``position``, about the origin: ``m (|p|^2 1 - p p^T)``."""
    _nonnegative(mass, "mass")
    alg = Algebra(is_symbolic(mass, position))
    p = alg.vector(position, "position")
    return (alg.eye() * alg.dot(p, p) - alg.outer(p)) * mass


def shift(inertia_com, mass, d):
    """The parallel-axis theorem: the inertia ``I_c`` of a body of ``mass`` about its centre
    of mass, moved to the point from which the centre of mass is at ``d`` (same axes):
    ``I_c + m (|d|^2 1 - d d^T)``."""
    alg = Algebra(is_symbolic(mass, d, inertia_com))
    return alg.matrix(inertia_com, "inertia_com") + point(mass, d)


def rotate(inertia, R):
    """``R I R^T``: the inertia ``I`` expressed in axes rotated by ``R`` (the columns of ``R``
    are the old axes in the new ones)."""
    alg = Algebra(is_symbolic(inertia, R))
    R = alg.matrix(R, "R")
    return R @ alg.matrix(inertia, "inertia") @ R.T


def parameters(mass, com, inertia_com):
    """The 10 inertial parameters ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``
    about the frame origin (a row of ``Model.theta``) from the mass, the centre of mass and
    the inertia about it."""
    if is_symbolic(mass, com, inertia_com):
        from .symbolic.model import inertial_parameters

        return inertial_parameters(mass, com, inertia_com)
    from .model import inertial_parameters_from

    return inertial_parameters_from(mass, com, inertia_com)
