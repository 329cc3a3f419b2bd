"""The compiled part of the joint table (``joints.py``): each joint type's transform and
friction, called by the kernels. Kept apart so that ``import robodyn`` does not import Numba.
"""

from __future__ import annotations

import numpy as np

from ._jit import inline
from .joints import PRISMATIC, QUAT_TOL, REVOLUTE, ROW_JOINT, ROW_XTREE_P
from .sincos import sincos
from .spatial import rotation_from_quaternion


@inline
def body_placement(jtype, row, q, iq, R, p, Rj):
    """Placement ``(R, p)`` of a body in its parent, ``X_tree * X_J(q)``, from the body's
    kernel row (``Model._pack``); ``Rj`` is a 3 x 3 workspace.

    Returns False when a free joint's quaternion is farther than ``QUAT_TOL`` from unit norm
    (a near-unit quaternion is normalised).
    """
    if jtype == REVOLUTE:
        s, c = sincos(q[iq])
        for r in range(3):
            p[r] = row[ROW_XTREE_P + r]
            for k in range(3):
                j = ROW_JOINT + 3 * r + k
                R[r, k] = row[j] + c * row[j + 9] + s * row[j + 18]
        return True
    if jtype == PRISMATIC:
        x = q[iq]
        for r in range(3):
            p[r] = row[ROW_XTREE_P + r] + row[ROW_JOINT + r] * x
            for k in range(3):
                R[r, k] = row[3 * r + k]
        return True
    # FREE: X_tree * (rotation of the quaternion, position)
    n = np.sqrt(q[iq + 3] * q[iq + 3] + q[iq + 4] * q[iq + 4] + q[iq + 5] * q[iq + 5] + q[iq + 6] * q[iq + 6])
    if not abs(n - 1.0) <= QUAT_TOL:
        return False
    rotation_from_quaternion(q[iq + 3] / n, q[iq + 4] / n, q[iq + 5] / n, q[iq + 6] / n, Rj)
    for r in range(3):
        p[r] = row[9 + r] + row[3 * r] * q[iq] + row[3 * r + 1] * q[iq + 1] + row[3 * r + 2] * q[iq + 2]
        for k in range(3):
            R[r, k] = row[3 * r] * Rj[0, k] + row[3 * r + 1] * Rj[1, k] + row[3 * r + 2] * Rj[2, k]
    return True


@inline
def friction_torque(dofs, eps, v, k):
    """Joint friction torque opposed by the actuator at dof ``k``: ``b v + Fc sgn(v)``.

    ``dofs[k, 6:9] = [armature, b (viscous), Fc (Coulomb)]``; ``sgn`` is ``sign`` when
    ``eps == 0`` and the smooth ``tanh(v / eps)`` otherwise (``Model.coulomb_smoothing``).
    """
    vk = v[k]
    s = np.tanh(vk / eps) if eps > 0.0 else (1.0 if vk > 0.0 else (-1.0 if vk < 0.0 else 0.0))
    return dofs[k, 7] * vk + dofs[k, 8] * s
