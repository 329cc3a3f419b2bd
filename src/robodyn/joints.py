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
spherical   4    3    ``[qx, qy, qz, qw]`` (a ball joint), ``omega`` in the child frame
helical     1    1    angle about ``axis`` with a translation ``pitch * angle`` along it
                      (a screw; ``S = [pitch axis; axis]``, Pinocchio's
                      ``JointModelHelicalUnaligned``)
planar      4    3    ``[x, y, cos t, sin t]``: a translation in the joint frame's x-y plane
                      and a rotation ``t`` about its z axis; ``[vx, vy, wz]`` in the child
                      frame (Pinocchio's ``JointModelPlanar``)
=========== ==== ==== ================================================================

Free and spherical joints hold a unit quaternion (scalar last) at ``QUAT_OFFSET`` in their
``q`` and move on SO(3) by the right: ``q (+) v`` rotates by ``exp(omega)`` in the child
frame, as Pinocchio's ``JointModelFreeFlyer`` and ``JointModelSpherical`` do.
"""

from __future__ import annotations

import numpy as np


REVOLUTE = 0
PRISMATIC = 1
FREE = 2
SPHERICAL = 3
HELICAL = 4
PLANAR = 5

NAMES = ("revolute", "prismatic", "free", "spherical", "helical", "planar")
NQ = np.array([1, 1, 7, 4, 1, 4], dtype=np.int64)
NV = np.array([1, 1, 6, 3, 1, 3], dtype=np.int64)
# Where a joint's unit quaternion starts in its q (-1: none).
QUAT_OFFSET = np.array([-1, -1, 3, 0, -1, -1], dtype=np.int64)
# Where the unit vector of a joint's rotation (a quaternion, or a planar joint's (cos, sin))
# starts in its q, and its length (0: none). Joints with nq == 1 are scalar: q + v moves them.
UNIT_OFFSET = np.array([-1, -1, 3, 0, -1, 2], dtype=np.int64)
UNIT_SIZE = np.array([0, 0, 4, 4, 0, 2], dtype=np.int64)
# Joints with an axis (normalised by the model; zero is an error).
AXIAL = (REVOLUTE, PRISMATIC, HELICAL)


# Names of the entries of a joint's q and v (a joint of one entry goes by the joint's name alone).
Q_COMPONENTS = ((), (), ("x", "y", "z", "qx", "qy", "qz", "qw"), ("qx", "qy", "qz", "qw"), (), ("x", "y", "c", "s"))
V_COMPONENTS = ((), (), ("vx", "vy", "vz", "wx", "wy", "wz"), ("wx", "wy", "wz"), (), ("vx", "vy", "wz"))


def coordinate_names(joint_types, joint_names, kind: str = "v") -> list[str]:
    """One name per entry of ``v`` (``kind="v"``) or ``q`` (``"q"``): the joint's name, or
    ``name:vx``, ``name:wx`` ... for the entries of a multi-dof joint (``Model.dof_names``,
    ``Model.q_names``)."""
    parts = V_COMPONENTS if kind == "v" else Q_COMPONENTS
    out = []
    for jt, name in zip(joint_types, joint_names):
        comps = parts[int(jt)]
        out.extend(f"{name}:{c}" for c in comps) if comps else out.append(name)
    return out


def motion_subspace(jtype: int, axis: np.ndarray, pitch: float = 0.0) -> np.ndarray:
    """Columns of ``S`` (nv_joint, 6) in the child frame, spatial order ``[lin; ang]``."""
    if jtype == HELICAL:
        return np.concatenate([pitch * axis, axis])[None, :]
    if jtype == REVOLUTE:
        return np.concatenate([np.zeros(3), axis])[None, :]
    if jtype == PRISMATIC:
        return np.concatenate([axis, np.zeros(3)])[None, :]
    if jtype == FREE:
        return np.eye(6)
    if jtype == SPHERICAL:
        return np.eye(6)[3:]
    if jtype == PLANAR:
        return np.eye(6)[[0, 1, 5]]
    raise ValueError(f"unknown joint type code {jtype}")


# A quaternion (or a planar joint's (cos, sin)) may be this far from unit norm; it is normalised,
# farther is an error.
QUAT_TOL = 1e-3


JOINT_CONSTANTS_SIZE = 30


def joint_constants(jtype: int, axis: np.ndarray, R_tree: np.ndarray, pitch: float = 0.0) -> np.ndarray:
    """Constants (30,) that make ``joint_kernels.body_placement`` cheap for a joint type.

    Revolute, with Rodrigues' formula ``Rot(a, q) = a a^T + cos q (1 - a a^T) + sin q [a]x``:
    ``R_tree Rot(a, q) = C + cos q A + sin q B`` with ``C = (R_tree a) a^T``,
    ``A = R_tree - C`` and ``B = R_tree [a]x`` (row-major, in this order). Helical: the same,
    then ``pitch R_tree a`` (the translation per radian in the parent frame).
    Prismatic: ``R_tree a`` (the joint's direction in the parent frame) first.
    """
    out = np.zeros(JOINT_CONSTANTS_SIZE)
    if jtype in (REVOLUTE, HELICAL):
        C = np.outer(R_tree @ axis, axis)
        ax = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        out[0:9], out[9:18], out[18:27] = C.ravel(), (R_tree - C).ravel(), (R_tree @ ax).ravel()
        if jtype == HELICAL:
            out[27:30] = pitch * (R_tree @ axis)
    elif jtype == PRISMATIC:
        out[0:3] = R_tree @ axis
    return out
