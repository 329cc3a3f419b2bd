"""Forward kinematics: the placement of every body and of any named frame.

``forward_kinematics(model, q)`` returns the world pose (4 x 4 homogeneous matrix) of every
body, ``frame_pose(model, q, name)`` the world pose of one link or frame. The compiled
passes here (``placements``, ``world_placements``) are the first pass of every algorithm.

    liMi = X_tree[i] * X_J(q_i)        (body i in its parent body, RBDA eq. 4.3 / Table 4.1)
    oMi  = oM_parent(i) * liMi         (body i in the world)
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..joints import joint_transform
from ..spatial import compose, motion_act
from . import _inputs


@njit(cache=True, inline="always")
def placements(ints, body, q, liR, lip, Rj, pj):
    """``liR[i], lip[i]``: placement of body ``i`` in its parent at configuration ``q``."""
    for i in range(ints.shape[0]):
        joint_transform(ints[i, 1], body[i, 12:15], q, ints[i, 2], Rj, pj)
        for r in range(3):
            lip[i, r] = body[i, 9 + r] + body[i, 3 * r] * pj[0] + body[i, 3 * r + 1] * pj[1] + body[i, 3 * r + 2] * pj[2]
            for c in range(3):
                liR[i, r, c] = (body[i, 3 * r] * Rj[0, c] + body[i, 3 * r + 1] * Rj[1, c]
                                + body[i, 3 * r + 2] * Rj[2, c])


@njit(cache=True, inline="always")
def world_placements(ints, liR, lip, oR, op):
    """``oR[i], op[i]``: placement of body ``i`` in the world from the local placements."""
    for i in range(ints.shape[0]):
        par = ints[i, 0]
        if par < 0:
            oR[i, :, :] = liR[i]
            op[i, :] = lip[i]
        else:
            compose(oR[par], op[par], liR[i], lip[i], oR[i], op[i])


@njit(cache=True, inline="always")
def world_motion_subspace(ints, S, oR, op, oS):
    """``oS[k]``: motion subspace column ``k`` in world coordinates (``J`` of its body)."""
    for i in range(ints.shape[0]):
        for k in range(ints[i, 3], ints[i, 3] + ints[i, 4]):
            motion_act(oR[i], op[i], S[k], oS[k])


@njit(cache=True)
def _fk_one(ints, body, q, oR, op, liR, lip, Rj, pj):
    placements(ints, body, q, liR, lip, Rj, pj)
    world_placements(ints, liR, lip, oR, op)


@njit(cache=True, parallel=True)
def _fk_batch(ints, body, Q, OR, OP, nchunk):
    B, nb = Q.shape[0], ints.shape[0]
    for c in prange(nchunk):
        liR, lip = np.empty((nb, 3, 3)), np.empty((nb, 3))
        Rj, pj = np.empty((3, 3)), np.empty(3)
        for s in range(c * B // nchunk, (c + 1) * B // nchunk):
            _fk_one(ints, body, Q[s], OR[s], OP[s], liR, lip, Rj, pj)


def world_poses(model, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(oR, op)`` of shapes ``(B, nb, 3, 3)``, ``(B, nb, 3)`` for flat states ``Q``."""
    ints, body = model._kernel[0], model._kernel[1]
    B, nb = Q.shape[0], model.nbodies
    OR, OP = np.empty((B, nb, 3, 3)), np.empty((B, nb, 3))
    n = _inputs.chunks(B)
    if n:
        _fk_batch(ints, body, Q, OR, OP, n)
    else:
        _fk_one(ints, body, Q[0], OR[0], OP[0], np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((3, 3)), np.empty(3))
    return OR, OP


def _homogeneous(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def forward_kinematics(model, q, check_finite: bool = True) -> np.ndarray:
    """World pose of every body.

    q: (..., nq). Returns (..., nbodies, 4, 4): ``T[..., i]`` maps body-``i`` coordinates to
    world coordinates (rotation block and origin position).
    """
    batch, flat = _inputs.states(model, check_finite, q=q)
    OR, OP = world_poses(model, flat["q"])
    return _inputs.unflatten(_homogeneous(OR, OP), batch)


def frame_placement(model, OR: np.ndarray, OP: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    """World rotation (B, 3, 3) and position (B, 3) of a link or frame from body poses."""
    b, R, p = model.frame_index(name)
    if b < 0:
        B = OR.shape[0]
        return np.broadcast_to(R, (B, 3, 3)).copy(), np.broadcast_to(p, (B, 3)).copy()
    oR, op = OR[:, b], OP[:, b]
    return oR @ R, op + oR @ p


def frame_pose(model, q, name: str, check_finite: bool = True) -> np.ndarray:
    """World pose (..., 4, 4) of a link or frame (a body, or a link merged into one)."""
    batch, flat = _inputs.states(model, check_finite, q=q)
    OR, OP = world_poses(model, flat["q"])
    R, p = frame_placement(model, OR, OP, name)
    return _inputs.unflatten(_homogeneous(R, p), batch)
