"""The joint table: every joint type, its dimensions, motion subspace and transform.

Adding a joint type is a local change: a code, a row in ``NQ``/``NV``, its motion subspace
in :func:`motion_subspace` and its transform in :func:`joint_transform`. Every joint type
has a motion subspace ``S`` that is constant in the child frame, so the joint's velocity
is ``v_J = S qd`` and its bias acceleration ``c_J = Sdot qd`` is zero (RBDA section 4.4).

=========== ==== ==== ================================================================
type        nq   nv   configuration and velocity
=========== ==== ==== ================================================================
revolute    1    1    angle about ``axis`` (continuous joints are revolute joints)
prismatic   1    1    displacement along ``axis``
free        7    6    ``[x, y, z, qx, qy, qz, qw]``, ``[v_lin, omega]`` in the child frame
=========== ==== ==== ================================================================
"""

from __future__ import annotations

import numpy as np

from ._jit import inline
from .spatial import rotation_axis_angle, rotation_from_quaternion

REVOLUTE = 0
PRISMATIC = 1
FREE = 2

NAMES = ("revolute", "prismatic", "free")
NQ = np.array([1, 1, 7], dtype=np.int64)
NV = np.array([1, 1, 6], dtype=np.int64)


def motion_subspace(jtype: int, axis: np.ndarray) -> np.ndarray:
    """Columns of ``S`` (nv_joint, 6) in the child frame, spatial order ``[lin; ang]``."""
    if jtype == REVOLUTE:
        return np.concatenate([np.zeros(3), axis])[None, :]
    if jtype == PRISMATIC:
        return np.concatenate([axis, np.zeros(3)])[None, :]
    if jtype == FREE:
        return np.eye(6)
    raise ValueError(f"unknown joint type code {jtype}")


# A free joint's quaternion may be this far from unit norm; it is normalised, farther is an error.
QUAT_TOL = 1e-3


@inline
def joint_transform(jtype, axis, q, iq, R, p):
    """Placement ``(R, p)`` of the child frame in the joint frame at configuration ``q``.

    Returns False when a free joint's quaternion is farther than ``QUAT_TOL`` from unit norm
    (a near-unit quaternion is normalised).
    """
    if jtype == REVOLUTE:
        rotation_axis_angle(axis, q[iq], R)
        p[0] = 0.0
        p[1] = 0.0
        p[2] = 0.0
    elif jtype == PRISMATIC:
        for r in range(3):
            for c in range(3):
                R[r, c] = 1.0 if r == c else 0.0
            p[r] = axis[r] * q[iq]
    else:  # FREE
        n = np.sqrt(q[iq + 3] ** 2 + q[iq + 4] ** 2 + q[iq + 5] ** 2 + q[iq + 6] ** 2)
        if not abs(n - 1.0) <= QUAT_TOL:
            return False
        rotation_from_quaternion(q[iq + 3] / n, q[iq + 4] / n, q[iq + 5] / n, q[iq + 6] / n, R)
        p[0] = q[iq]
        p[1] = q[iq + 1]
        p[2] = q[iq + 2]
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
