"""Forward kinematics: the placement of every body and of any named frame.

``forward_kinematics(model, q)`` returns the world pose (4 x 4 homogeneous matrix) of every
body, ``frame_pose(model, q, name)`` the world pose of one link or frame. The compiled
passes here (``placements``, ``world_placements``) are the first pass of every algorithm.

    liMi = X_tree[i] * X_J(q_i)        (body i in its parent body, RBDA eq. 4.3 / Table 4.1)
    oMi  = oM_parent(i) * liMi         (body i in the world)
"""

from __future__ import annotations

import numpy as np
from numba import boolean, int64, types

from .._jit import MAT, MODEL_INTS, MODEL_PACKED, TENSOR, VEC, fast, inline, scratch
from ..layout import IQ, IV, JTYPE, MOTION, NDOF, PARENT, UNIT_AXIS
from ..joint_kernels import body_placement
from ..spatial import compose, cross_into, motion_act
from ..coupling import expand_q, is_coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .status import BAD_QUATERNION, NONFINITE, OK, WRONG_SIZE, finite, finite2, result_status
from ._inputs import unpack
from ._workspace import row
from .driver import batch_kernel


@inline
def placements(ints, body, q, liR, lip, Rj, pj):
    """``liR[i], lip[i]``: placement of body ``i`` in its parent at configuration ``q``.

    Returns False when a free joint's quaternion is not of unit norm (see ``joints``).
    """
    for i in range(ints.shape[0]):
        if not body_placement(ints[i, JTYPE], body[i], q, ints[i, IQ], liR[i], lip[i], Rj):
            return False
    return True


@inline
def world_placement(i, par, liR, lip, oR, op):
    """``oR[i], op[i]``: placement of body ``i`` in the world, from its local placement and
    the world placement of its parent ``par`` (``-1``: the world)."""
    if par < 0:
        for r in range(3):
            op[i, r] = lip[i, r]
            for c in range(3):
                oR[i, r, c] = liR[i, r, c]
    else:
        compose(oR[par], op[par], liR[i], lip[i], oR[i], op[i])


@inline
def world_placements(ints, liR, lip, oR, op):
    """``oR[i], op[i]``: placement of body ``i`` in the world from the local placements."""
    for i in range(ints.shape[0]):
        world_placement(i, ints[i, PARENT], liR, lip, oR, op)


@inline
def world_motion_subspace(ints, dofs, oR, op, oS):
    """``oS[k]``: motion subspace column ``k`` in world coordinates (``J`` of its body). A
    joint along a body axis (``S = e_r``, ``ints[i, UNIT_AXIS] = r``) takes column ``r`` of the
    rotation: ``[R e_r; 0]`` for a translation, ``[p x R e_r; R e_r]`` for a rotation."""
    for i in range(ints.shape[0]):
        axis = ints[i, UNIT_AXIS]
        if axis >= 3:
            R, p, k, c = oR[i], op[i], ints[i, IV], axis - 3
            w0, w1, w2 = R[0, c], R[1, c], R[2, c]
            cross_into(p[0], p[1], p[2], w0, w1, w2, oS[k], 0)
            oS[k, 3], oS[k, 4], oS[k, 5] = w0, w1, w2
        elif axis >= 0:
            R, k = oR[i], ints[i, IV]
            oS[k, 0], oS[k, 1], oS[k, 2] = R[0, axis], R[1, axis], R[2, axis]
            oS[k, 3], oS[k, 4], oS[k, 5] = 0.0, 0.0, 0.0
        else:
            for k in range(ints[i, IV], ints[i, IV] + ints[i, NDOF]):
                motion_act(oR[i], op[i], dofs[k, MOTION:MOTION + 6], oS[k])


@inline
def poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op):
    """Local and world placements of every body, after the value checks of ``q`` and ``v``
    (``v`` may be empty); returns a status (see ``_inputs``): positions that overflow (huge
    prismatic coordinates) are a ``NONFINITE_RESULT``."""
    if check and not (finite(q) and finite(v)):
        return NONFINITE
    if not placements(ints, body, q, liR, lip, Rj, pj):
        return BAD_QUATERNION
    world_placements(ints, liR, lip, oR, op)
    return result_status(check, finite2(op))


@scratch
def workspace(nb):
    return np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((3, 3)), np.empty(3)


@inline
def fk_at(args, s, ws):
    """The world placements of state ``s`` of a batch."""
    ints, body, Q, OR, OP, check = args
    liR, lip, Rj, pj = ws
    return poses_checked(ints, body, Q[s], Q[s, :0], check, liR, lip, Rj, pj, OR[s], OP[s])


# A single state (the fast path) runs the batch's compiled code as a batch of one: these types.
ONE_STATE = ((MODEL_INTS, MAT, MAT, types.Array(types.float64, 4, "C"), TENSOR, boolean), (int64,))
_fk_batch = batch_kernel(fk_at, workspace, one_state=ONE_STATE)
_fk_call_one = _fk_batch.call_one


@fast(int64, MODEL_INTS, MODEL_PACKED, VEC, boolean, TENSOR, MAT)
def _fk_packed(address, ints, packed, q, check, oR, op):
    """One state's world placements ``oR`` (nb, 3, 3), ``op`` (nb, 3) (the fast path): the
    batch's code at ``address`` (``_fk_batch.one_address``) for a batch of one."""
    body = unpack(ints, packed)[0]
    nb = ints.shape[0]
    if not (oR.shape[0] == nb and op.shape[0] == nb):
        return WRONG_SIZE
    return _fk_call_one(address, (ints, body, row(q), row(oR), row(op), check), workspace(nb))


def world_poses(model, q: np.ndarray, batch: tuple, check: bool, what: str) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (..., nb, 3, 3) and positions (..., nb, 3) of every body, flat batch
    (of a coupled model: the full tree's at ``E(q)``)."""
    if is_coupled(model):
        return world_poses(model.full, expand_q(model, q), batch, check, what)
    k, nb = model.kernel, model.nbodies
    if batch == ():
        oR, op = np.empty((nb, 3, 3)), np.empty((nb, 3))
        try:
            if _fk_packed(_fk_batch.one_address, k.ints, k.packed[False, False], q, check, oR, op) == OK:
                return oR, op
        except TypeError:  # not a contiguous float64 vector (or check not a bool): the general path
            pass
    B = 1 if batch == () else q.shape[0]
    oR, op, status = np.empty((B, nb, 3, 3)), np.empty((B, nb, 3)), np.empty(B, dtype=np.int64)
    _fk_batch.run((k.ints, k.body, _inputs.batched(batch, q)[0], oR, op, check), (nb,), status, batch)
    raise_for_status(model, status, {"q": q}, what)
    return (oR[0], op[0]) if batch == () else (oR, op)


def _homogeneous(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def forward_kinematics(model, q, *, check_finite: bool = True) -> np.ndarray:
    """World pose of every body.

    q: (..., nq). Returns (..., nbodies, 4, 4): ``T[..., i, :, :]`` maps body-``i``
    coordinates to world coordinates (rotation block and origin position).
    """
    if any_lazy(q):
        return deferred(forward_kinematics, locals())
    batch, x = _inputs.states(model, q=q)
    oR, op = world_poses(model, x["q"], batch, check_finite, "forward_kinematics")
    return _inputs.unflatten(_homogeneous(oR, op), batch)


def frame_placement(model, oR: np.ndarray, op: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    """World rotation (..., 3, 3) and position (..., 3) of a link or frame from body poses."""
    b, R, p = model.frame_index(name)
    if b < 0:
        lead = oR.shape[:-3]
        return np.broadcast_to(R, lead + (3, 3)).copy(), np.broadcast_to(p, lead + (3,)).copy()
    Rb, pb = oR[..., b, :, :], op[..., b, :]
    return Rb @ R, pb + Rb @ p


def frame_pose(model, q, name: str, *, check_finite: bool = True) -> np.ndarray:
    """World pose (..., 4, 4) of a link or frame (a body, or a link merged into one)."""
    if any_lazy(q):
        return deferred(frame_pose, locals())
    batch, x = _inputs.states(model, q=q)
    oR, op = world_poses(model, x["q"], batch, check_finite, "frame_pose")
    R, p = frame_placement(model, oR, op, name)
    return _inputs.unflatten(_homogeneous(R, p), batch)
