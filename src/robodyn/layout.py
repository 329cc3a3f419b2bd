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


def pack(model) -> KernelTables:
    """The kernel tables of ``model`` (any object with the :class:`Model`'s arrays)."""
    nb, nv = model.nbodies, model.nv
    ints = np.zeros((nb, INTS_COLUMNS), dtype=np.int64)
    ints[:, PARENT] = model.parent
    ints[:, JTYPE] = model.joint_type
    ints[:, IQ] = model.idx_q
    ints[:, IV] = model.idx_v
    ints[:, NDOF] = J.NV[model.joint_type] if nb else 0
    ints[:, SUBTREE_END] = ints[:, IV] + ints[:, NDOF]
    for i in range(nb - 1, 0, -1):  # children after their parents: the ends gather to the root
        p = model.parent[i]
        if p >= 0:
            ints[p, SUBTREE_END] = max(ints[p, SUBTREE_END], ints[i, SUBTREE_END])
    body = np.zeros((nb, BODY_COLUMNS))
    body[:, XTREE_R:XTREE_R + 9] = model.X_tree_R.reshape(nb, 9)
    body[:, XTREE_P:XTREE_P + 3] = model.X_tree_p
    body[:, JOINT_AXIS:JOINT_AXIS + 3] = model.joint_axis
    body[:, INERTIA:INERTIA_END] = model.theta
    for i in range(nb):
        body[i, JOINT_CONSTANTS:] = J.joint_constants(int(model.joint_type[i]), model.joint_axis[i],
                                                      model.X_tree_R[i], model.joint_pitch[i])
    full = np.zeros((nv, DOF_COLUMNS))
    for i in range(nb):
        k = model.idx_v[i]
        Si = J.motion_subspace(int(model.joint_type[i]), model.joint_axis[i], model.joint_pitch[i])
        full[k:k + Si.shape[0], MOTION:MOTION + 6] = Si
    full[:, ARMATURE], full[:, DAMPING], full[:, COULOMB] = model.armature, model.damping, model.coulomb
    full[:, STIFFNESS], full[:, SPRING_REF] = model.stiffness, model.spring_reference
    full[:, STRIBECK] = model.stribeck
    vs = model.stribeck_velocity
    full[:, STRIBECK_RATE] = np.divide(1.0, vs, out=np.zeros(nv), where=vs > 0)
    for i in range(nb):
        S = full[model.idx_v[i], MOTION:MOTION + 6]
        unit = ints[i, NDOF] == 1 and np.count_nonzero(S) == 1 and S.max() == 1.0
        ints[i, UNIT_AXIS] = int(np.argmax(S)) if unit else -1
    dofs = {}
    for friction in (False, True):
        for armature in (False, True):
            d = full.copy()
            d[:, ARMATURE] *= armature
            d[:, DAMPING] *= friction
            d[:, COULOMB] *= friction
            d[:, STIFFNESS] *= friction
            d[:, STRIBECK] *= friction
            dofs[(friction, armature)] = d
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
