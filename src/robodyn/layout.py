"""The tables a :class:`~robodyn.model.Model` hands to the compiled kernels, and the names of
their columns.

A kernel never reads a model's table by number: it writes ``ints[i, PARENT]``,
``body[i, INERTIA:INERTIA_END]``, ``dofs[k, ARMATURE]``, ``params[SMOOTHING]``. Numba reads
these module constants at compile time, so a name costs nothing at run time, and adding a
column means changing this file and :func:`pack` only.

The tables (built once per model by :func:`pack`, reached as ``model.kernel``):

``ints`` (nb, INTS_COLUMNS) int64, one row per body:
    ``PARENT`` (-1 for the world), ``JTYPE`` (``joints`` code), ``IQ`` and ``IV`` (the joint's
    first index in ``q`` and ``v``), ``NDOF`` (the joint's nv), ``UNIT_AXIS`` (``r`` when the
    joint has one dof whose motion subspace is the unit vector ``e_r`` of the body frame, as for
    most URDF joints, so that kernels skip the products with zeros; else -1) and
    ``SUBTREE_END`` (the dofs of the body and of its descendants lie in
    ``IV <= k < SUBTREE_END``; exactly those when bodies are numbered depth first, as the
    builder does).
``body`` (nb, BODY_COLUMNS) float: ``X_tree`` rotation (``XTREE_R``, 9, row-major) and
    translation (``XTREE_P``, 3), the joint axis (``JOINT_AXIS``, 3), the inertial parameters
    (``INERTIA``, 10, ``[m, m c, I_xx, I_xy, I_xz, I_yy, I_yz, I_zz]`` about the body origin)
    and the joint constants (``JOINT_CONSTANTS``, 27, ``joints.joint_constants``).
``dofs[(friction, armature)]`` (nv, DOF_COLUMNS) float, one row per dof: the motion
    subspace column in the child frame (``MOTION``, 6), then ``ARMATURE``, ``DAMPING``
    (viscous), ``COULOMB``, the joint spring's ``STIFFNESS`` (zeroed when switched off, with
    friction) and its rest position ``SPRING_REF``, the Stribeck excess ``STRIBECK`` (zeroed
    with friction) and the inverse of its velocity ``STRIBECK_RATE`` (``1 / v_s``, 0 where
    there is none).
``params[with_gravity]`` (PARAMS_SIZE,): gravity (``GRAVITY``, 3, or zeros) and the Coulomb
    smoothing velocity (``SMOOTHING``).
``zero_wrench`` (nb, 6): no external wrench. ``multi_dof_bodies``: the bodies whose joint has several dofs (free, spherical).
``packed[(friction, armature)]``: ``body``, that ``dofs``, ``params[True]`` and
    ``zero_wrench`` raveled into one array for the single-state fast paths, where each argument
    costs Numba's dispatcher about 0.1 us (``algorithms._inputs.unpack`` takes it apart).

The arrays stay writeable although the kernels only read them: Numba types a writeable
C-contiguous array from its cache of types, a read-only one in Python, about 0.25 us more per
argument of every call. The model's public arrays are read-only.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import joints as J

# ``ints`` columns
PARENT, JTYPE, IQ, IV, NDOF, UNIT_AXIS, SUBTREE_END = range(7)
INTS_COLUMNS = 7

# ``body`` columns
XTREE_R, XTREE_P, JOINT_AXIS, INERTIA, JOINT_CONSTANTS = 0, 9, 12, 15, 25
INERTIA_END = INERTIA + 10
BODY_COLUMNS = JOINT_CONSTANTS + J.JOINT_CONSTANTS_SIZE

# ``dofs`` columns
MOTION, ARMATURE, DAMPING, COULOMB, STIFFNESS, SPRING_REF, STRIBECK, STRIBECK_RATE = 0, 6, 7, 8, 9, 10, 11, 12
DOF_COLUMNS = 13

# ``params`` entries
GRAVITY, SMOOTHING = 0, 3
PARAMS_SIZE = 4


class KernelTables(NamedTuple):
    """A model's kernel tables (see the module docstring)."""

    ints: np.ndarray
    body: np.ndarray
    dofs: dict
    params: dict
    zero_wrench: np.ndarray
    packed: dict
    multi_dof_bodies: tuple


_AXIAL_CODE = np.isin(np.arange(len(J.NAMES)), J.AXIAL)  # joint type code -> has an axis


def _axial_constants(jtype, axis, R, pitch) -> np.ndarray:
    """:func:`joints.joint_constants` of bodies whose joints have an axis (revolute, helical,
    prismatic), all at once (n, JOINT_CONSTANTS_SIZE): the same operations, body for body
    (NumPy's products of one pair and of a stack give the same bits)."""
    n = jtype.shape[0]
    out = np.zeros((n, J.JOINT_CONSTANTS_SIZE))
    Ra = (R @ axis[:, :, None])[:, :, 0]  # R_tree @ axis
    turn = (jtype == J.REVOLUTE) | (jtype == J.HELICAL)
    a, Rt, C = axis[turn], R[turn], Ra[turn][:, :, None] * axis[turn][:, None, :]
    skew = np.zeros((a.shape[0], 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 0] = -a[:, 2], a[:, 1], a[:, 2]
    skew[:, 1, 2], skew[:, 2, 0], skew[:, 2, 1] = -a[:, 0], -a[:, 1], a[:, 0]
    out[turn, 0:9], out[turn, 9:18] = C.reshape(-1, 9), (Rt - C).reshape(-1, 9)
    out[turn, 18:27] = (Rt @ skew).reshape(-1, 9)
    helical = jtype == J.HELICAL
    out[helical, 27:30] = pitch[helical, None] * Ra[helical]
    out[jtype == J.PRISMATIC, 0:3] = Ra[jtype == J.PRISMATIC]
    return out


def _axial_subspaces(jtype, axis, pitch) -> np.ndarray:
    """:func:`joints.motion_subspace` of bodies whose joints have an axis (their one column,
    (n, 6)), the same values: ``[0, axis]`` revolute, ``[pitch axis, axis]`` helical, ``[axis, 0]``
    prismatic."""
    S = np.zeros((jtype.shape[0], 6))
    helical, prismatic = jtype == J.HELICAL, jtype == J.PRISMATIC
    S[~prismatic, 3:6] = axis[~prismatic]
    S[helical, 0:3] = pitch[helical, None] * axis[helical]
    S[prismatic, 0:3] = axis[prismatic]
    return S


def pack(model) -> KernelTables:
    """The kernel tables of ``model`` (any object with the :class:`Model`'s arrays)."""
    nb, nv = model.nbodies, model.nv
    jtype = np.asarray(model.joint_type)
    ints = np.zeros((nb, INTS_COLUMNS), dtype=np.int64)
    ints[:, PARENT] = model.parent
    ints[:, JTYPE] = model.joint_type
    ints[:, IQ] = model.idx_q
    ints[:, IV] = model.idx_v
    ints[:, NDOF] = J.NV[model.joint_type] if nb else 0
    end = (ints[:, IV] + ints[:, NDOF]).tolist()
    parents = ints[:, PARENT].tolist()
    for i in range(nb - 1, 0, -1):  # children after their parents: the ends gather to the root
        p = parents[i]
        if p >= 0 and end[i] > end[p]:
            end[p] = end[i]
    ints[:, SUBTREE_END] = end
    body = np.zeros((nb, BODY_COLUMNS))
    body[:, XTREE_R:XTREE_R + 9] = model.X_tree_R.reshape(nb, 9)
    body[:, XTREE_P:XTREE_P + 3] = model.X_tree_p
    body[:, JOINT_AXIS:JOINT_AXIS + 3] = model.joint_axis
    body[:, INERTIA:INERTIA_END] = model.theta
    full = np.zeros((nv, DOF_COLUMNS))
    axial = _AXIAL_CODE[jtype]
    if axial.any():
        args = (jtype[axial], np.asarray(model.joint_axis)[axial], np.asarray(model.joint_pitch)[axial])
        body[axial, JOINT_CONSTANTS:] = _axial_constants(args[0], args[1], np.asarray(model.X_tree_R)[axial], args[2])
        full[np.asarray(model.idx_v)[axial], MOTION:MOTION + 6] = _axial_subspaces(*args)
    for i in np.flatnonzero(~axial):  # free, spherical, planar: a few bodies
        body[i, JOINT_CONSTANTS:] = J.joint_constants(int(model.joint_type[i]), model.joint_axis[i],
                                                      model.X_tree_R[i], model.joint_pitch[i])
        k = model.idx_v[i]
        Si = J.motion_subspace(int(model.joint_type[i]), model.joint_axis[i], model.joint_pitch[i])
        full[k:k + Si.shape[0], MOTION:MOTION + 6] = Si
    full[:, ARMATURE], full[:, DAMPING], full[:, COULOMB] = model.armature, model.damping, model.coulomb
    full[:, STIFFNESS], full[:, SPRING_REF] = model.stiffness, model.spring_reference
    full[:, STRIBECK] = model.stribeck
    vs = model.stribeck_velocity
    full[:, STRIBECK_RATE] = np.divide(1.0, vs, out=np.zeros(nv), where=vs > 0)
    S = full[np.asarray(model.idx_v), MOTION:MOTION + 6]  # each body's first dof
    unit = (ints[:, NDOF] == 1) & (np.count_nonzero(S, axis=1) == 1) & (S.max(1, initial=-np.inf) == 1.0)
    ints[:, UNIT_AXIS] = np.where(unit, np.argmax(S, axis=1) if nb else 0, -1)
    dofs = {}
    for friction in (False, True):
        for armature in (False, True):
            keep = np.ones(DOF_COLUMNS)  # the columns switched off are multiplied by 0
            keep[ARMATURE] = armature
            keep[[DAMPING, COULOMB, STIFFNESS, STRIBECK]] = friction
            dofs[(friction, armature)] = full * keep
    params = {}
    for with_gravity in (True, False):
        p = np.zeros(PARAMS_SIZE)
        p[GRAVITY:GRAVITY + 3] = model.gravity if with_gravity else 0.0
        p[SMOOTHING] = model.coulomb_smoothing
        params[with_gravity] = p
    zero_wrench = np.zeros((nb, 6))
    packed = {key: np.concatenate([body.ravel(), d.ravel(), params[True], zero_wrench.ravel()])
              for key, d in dofs.items()}
    multi_dof_bodies = tuple(int(i) for i in np.flatnonzero(J.NV[model.joint_type] > 1)) if nb else ()
    return KernelTables(ints, body, dofs, params, zero_wrench, packed, multi_dof_bodies)
