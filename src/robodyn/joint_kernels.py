"""The compiled part of the joint table (``joints.py``): each joint type's transform and
friction, called by the kernels. Kept apart so that ``import robodyn`` does not import Numba.
"""

from __future__ import annotations

import numpy as np

from ._jit import inline
from .layout import (COULOMB, DAMPING, IQ, JOINT_CONSTANTS, JTYPE, SPRING_REF, STIFFNESS, STRIBECK, STRIBECK_RATE,
                     XTREE_P, XTREE_R)
from .joints import HELICAL, NQ, PLANAR, PRISMATIC, QUAT_TOL, REVOLUTE, SPHERICAL
from .sincos import sincos
from .spatial import rotation_from_quaternion


@inline
def _mix(row, j, c, s):
    """``row[j] + c row[j + 9] + s row[j + 18]``: an entry of a revolute joint's rotation."""
    return row[j] + c * row[j + 9] + s * row[j + 18]


@inline
def local_placement(jtype, row, q, iq, Rj):
    """``(ok, R, p)``: the placement of a body in its parent, ``X_tree * X_J(q)``, from the
    body's kernel row (``layout.pack``), as values: ``R`` a 9-tuple (row by row), ``p`` a
    3-tuple; ``Rj`` is a 3 x 3 workspace. ``ok`` is False when a joint's quaternion (or a
    planar joint's (cos, sin)) is farther than ``QUAT_TOL`` from unit norm (a near-unit one is
    normalised)."""
    P, J, R = XTREE_P, JOINT_CONSTANTS, XTREE_R
    if jtype == REVOLUTE:
        s, c = sincos(q[iq])
        return True, _revolute_rotation(row, c, s), (row[P], row[P + 1], row[P + 2])
    if jtype == PRISMATIC:
        x = q[iq]
        return (True, (row[R], row[R + 1], row[R + 2], row[R + 3], row[R + 4], row[R + 5], row[R + 6], row[R + 7],
                       row[R + 8]),
                (row[P] + row[J] * x, row[P + 1] + row[J + 1] * x, row[P + 2] + row[J + 2] * x))
    if jtype == HELICAL:  # the revolute rotation, and pitch * q along the axis
        x = q[iq]
        s, c = sincos(x)
        return (True, _revolute_rotation(row, c, s),
                (row[P] + row[J + 27] * x, row[P + 1] + row[J + 28] * x, row[P + 2] + row[J + 29] * x))
    if jtype == PLANAR:  # X_tree * (Rz(t), (x, y, 0)) with (cos t, sin t) normalised
        c, s = q[iq + 2], q[iq + 3]
        n = np.sqrt(c * c + s * s)
        if not abs(n - 1.0) <= QUAT_TOL:
            return False, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        c, s, x, y = c / n, s / n, q[iq], q[iq + 1]
        return (True, (row[R] * c + row[R + 1] * s, row[R + 1] * c - row[R] * s, row[R + 2],
                       row[R + 3] * c + row[R + 4] * s, row[R + 4] * c - row[R + 3] * s, row[R + 5],
                       row[R + 6] * c + row[R + 7] * s, row[R + 7] * c - row[R + 6] * s, row[R + 8]),
                (row[P] + row[R] * x + row[R + 1] * y, row[P + 1] + row[R + 3] * x + row[R + 4] * y,
                 row[P + 2] + row[R + 6] * x + row[R + 7] * y))
    if jtype == SPHERICAL:  # X_tree * rotation of the quaternion
        if not unit_rotation(q, iq, Rj):
            return False, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        return True, _tree_rotation(row, Rj), (row[P], row[P + 1], row[P + 2])
    # FREE: X_tree * (rotation of the quaternion, position)
    if not unit_rotation(q, iq + 3, Rj):
        return False, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    x, y, z = q[iq], q[iq + 1], q[iq + 2]
    return (True, _tree_rotation(row, Rj),
            (row[9] + row[0] * x + row[1] * y + row[2] * z, row[10] + row[3] * x + row[4] * y + row[5] * z,
             row[11] + row[6] * x + row[7] * y + row[8] * z))


@inline
def _revolute_rotation(row, c, s):
    """``R_tree Rot(a, q) = C + cos q A + sin q B`` (a 9-tuple) from the joint constants."""
    J = JOINT_CONSTANTS
    return (_mix(row, J, c, s), _mix(row, J + 1, c, s), _mix(row, J + 2, c, s), _mix(row, J + 3, c, s),
            _mix(row, J + 4, c, s), _mix(row, J + 5, c, s), _mix(row, J + 6, c, s), _mix(row, J + 7, c, s),
            _mix(row, J + 8, c, s))


@inline
def unit_rotation(q, k, Rj):
    """The rotation of the quaternion ``q[k:k + 4]`` (normalised) into ``Rj``; False when its
    norm is farther than ``QUAT_TOL`` from 1."""
    n = np.sqrt(q[k] * q[k] + q[k + 1] * q[k + 1] + q[k + 2] * q[k + 2] + q[k + 3] * q[k + 3])
    if not abs(n - 1.0) <= QUAT_TOL:
        return False
    rotation_from_quaternion(q[k] / n, q[k + 1] / n, q[k + 2] / n, q[k + 3] / n, Rj)
    return True


@inline
def _tree_rotation(row, Rj):
    """``X_tree_R Rj`` (row by row, a 9-tuple) from the body's kernel row."""
    return (row[0] * Rj[0, 0] + row[1] * Rj[1, 0] + row[2] * Rj[2, 0],
            row[0] * Rj[0, 1] + row[1] * Rj[1, 1] + row[2] * Rj[2, 1],
            row[0] * Rj[0, 2] + row[1] * Rj[1, 2] + row[2] * Rj[2, 2],
            row[3] * Rj[0, 0] + row[4] * Rj[1, 0] + row[5] * Rj[2, 0],
            row[3] * Rj[0, 1] + row[4] * Rj[1, 1] + row[5] * Rj[2, 1],
            row[3] * Rj[0, 2] + row[4] * Rj[1, 2] + row[5] * Rj[2, 2],
            row[6] * Rj[0, 0] + row[7] * Rj[1, 0] + row[8] * Rj[2, 0],
            row[6] * Rj[0, 1] + row[7] * Rj[1, 1] + row[8] * Rj[2, 1],
            row[6] * Rj[0, 2] + row[7] * Rj[1, 2] + row[8] * Rj[2, 2])


@inline
def body_placement(jtype, row, q, iq, R, p, Rj):
    """:func:`local_placement` written into ``R`` (3, 3) and ``p`` (3,); returns its ``ok``."""
    ok, Rv, pv = local_placement(jtype, row, q, iq, Rj)
    R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2] = Rv
    p[0], p[1], p[2] = pv
    return ok


@inline
def coulomb_level(dofs, vk, k):
    """The Coulomb friction level at velocity ``vk`` of dof ``k`` with the Stribeck effect,
    ``F(v) = Fc + Fx exp(-(v / v_s)^2)``: the breakaway torque ``Fc + Fx`` at rest falling to
    ``Fc`` as the joint speeds up (``dofs[k, STRIBECK] = Fx``, ``dofs[k, STRIBECK_RATE] =
    1 / v_s``). Reference: Armstrong-Helouvry, Dupont & Canudas de Wit, "A survey of models,
    analysis tools and compensation methods for the control of machines with friction",
    Automatica 30(7), 1994."""
    fx = dofs[k, STRIBECK]
    if fx == 0.0:
        return dofs[k, COULOMB]
    x = vk * dofs[k, STRIBECK_RATE]
    return dofs[k, COULOMB] + fx * np.exp(-x * x)


@inline
def passive_torque(dofs, eps, q, iq, v, k):
    """Passive joint torque opposed by the actuator at dof ``k``: friction and the joint
    spring, ``b v + F(v) sgn(v) + K (q - q_ref)``.

    ``dofs[k, DAMPING] = b`` (viscous), ``F(v)`` the Coulomb level with the Stribeck effect
    (:func:`coulomb_level`); ``sgn`` is ``sign`` when ``eps == 0`` and the smooth
    ``tanh(v / eps)`` otherwise (``Model.coulomb_smoothing``); ``dofs[k, STIFFNESS] = K``,
    ``dofs[k, SPRING_REF] = q_ref`` and ``q[iq]`` the joint's coordinate (springs sit on joints
    of one dof only; ``K`` is 0 on the others, whatever ``q[iq]`` then holds).
    """
    vk = v[k]
    s = np.tanh(vk / eps) if eps > 0.0 else (1.0 if vk > 0.0 else (-1.0 if vk < 0.0 else 0.0))
    return (dofs[k, DAMPING] * vk + coulomb_level(dofs, vk, k) * s
            + dofs[k, STIFFNESS] * (q[iq] - dofs[k, SPRING_REF]))


@inline
def passive_torque_dv(dofs, eps, vk, k):
    """``d/dv`` of :func:`passive_torque` at velocity ``vk`` of dof ``k``:
    ``b + F(v) sgn'(v) + F'(v) sgn(v)`` with ``F'(v) = -2 v / v_s^2 Fx exp(-(v / v_s)^2)``
    (``sgn' = (1 - tanh^2) / eps`` when smoothed, 0 for the exact sign away from 0)."""
    s, ds = (1.0 if vk > 0.0 else (-1.0 if vk < 0.0 else 0.0)), 0.0
    if eps > 0.0:
        s = np.tanh(vk / eps)
        ds = (1.0 - s * s) / eps
    out = dofs[k, DAMPING] + coulomb_level(dofs, vk, k) * ds
    fx = dofs[k, STRIBECK]
    if fx != 0.0:
        r = dofs[k, STRIBECK_RATE]
        x = vk * r
        out -= 2.0 * x * r * fx * np.exp(-x * x) * s
    return out


@inline
def nq_of(ints):
    """Length of the configuration vector of the model whose kernel table is ``ints``."""
    nb = ints.shape[0]
    return 0 if nb == 0 else ints[nb - 1, IQ] + NQ[ints[nb - 1, JTYPE]]
