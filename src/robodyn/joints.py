"""The joint table: every joint type, its dimensions, motion subspace and transform.

Adding a joint type is a local change: a code, a row in ``NQ``/``NV``, its motion subspace
in :func:`motion_subspace`, and its transform in ``joint_kernels.body_placement`` (with
constants precomputed by :func:`joint_constants`). Every joint type
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


def joint_constants(jtype: int, axis: np.ndarray, R_tree: np.ndarray) -> np.ndarray:
    """Constants (27,) that make ``joint_kernels.body_placement`` cheap for a joint type.

    Revolute, with Rodrigues' formula ``Rot(a, q) = a a^T + cos q (1 - a a^T) + sin q [a]x``:
    ``R_tree Rot(a, q) = C + cos q A + sin q B`` with ``C = (R_tree a) a^T``,
    ``A = R_tree - C`` and ``B = R_tree [a]x`` (row-major, in this order).
    Prismatic: ``R_tree a`` (the joint's direction in the parent frame) first.
    """
    out = np.zeros(27)
    if jtype == REVOLUTE:
        C = np.outer(R_tree @ axis, axis)
        ax = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        out[0:9], out[9:18], out[18:27] = C.ravel(), (R_tree - C).ravel(), (R_tree @ ax).ravel()
    elif jtype == PRISMATIC:
        out[0:3] = R_tree @ axis
    return out
