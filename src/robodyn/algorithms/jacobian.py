"""Frame Jacobians and the Jacobian-derivative bias ``Jdot v``.

The Jacobian ``J`` (6 x nv) maps ``v`` to the velocity of a frame attached to a body, rows
``[linear; angular]``. ``frame`` chooses the coordinates (the names follow Pinocchio's):

* ``"world"``: world axes; the linear part is the velocity of the body point that coincides
  with the world origin (the spatial velocity). Column ``k`` is the world-frame motion
  subspace ``oS_k`` of an ancestor joint, zero for other joints (RBDA section 8.1).
* ``"local"``: the frame's own axes, linear velocity of the frame origin.
* ``"local_world_aligned"``: world axes, linear velocity of the frame origin.

``jacobian_dot_times_v`` gives ``Jdot v`` in the same coordinates: the acceleration of the
frame when ``qdd = 0`` (and no gravity), spatial for ``"local"``/``"world"`` and classical
(``d/dt`` of the linear velocity of the frame origin) for ``"local_world_aligned"``.
"""

from __future__ import annotations

import numpy as np

from .._jit import core, inline
from ..layout import IV, MOTION, NDOF, PARENT
from ..spatial import motion_act
from ..coupling import expand_q, expand_v, is_coupled, reduce_columns
from ._lazy import any_lazy, deferred
from . import _inputs
from .status import raise_for_status
from .status import OK, finite, finite2, result_status
from .kinematics import poses_checked
from .rnea import motion_pass, motion_workspace
from .driver import batch_kernel

FRAMES = ("world", "local", "local_world_aligned")


@core
def jacobian_one(ints, body, dofs, q, v, b, check, J, oRb, opb, acc_b, vel_b, ws):
    """World Jacobian ``J`` (6, nv) of body ``b``, its pose, and (when ``v`` has entries) the
    body-frame velocity and acceleration of ``b`` at ``qdd = 0`` without gravity."""
    liR, lip, oR, op, Rj, pj, vel, acc, vJ, t1, a0, zero_a, zero_g = ws
    status = poses_checked(ints, body, q, v, check, liR, lip, Rj, pj, oR, op)
    if status != OK:
        return status
    J[:, :] = 0.0
    j = b
    while j >= 0:
        for k in range(ints[j, IV], ints[j, IV] + ints[j, NDOF]):
            motion_act(oR[j], op[j], dofs[k, MOTION:MOTION + 6], J[:, k])
        j = ints[j, PARENT]
    for r in range(3):
        opb[r] = op[b, r]
        for c in range(3):
            oRb[r, c] = oR[b, r, c]
    if v.shape[0] > 0:
        motion_pass(ints, dofs, liR, lip, v, zero_a, zero_g, vel, acc, vJ, t1, a0)
        for r in range(6):
            acc_b[r] = acc[b, r]
            vel_b[r] = vel[b, r]
    return result_status(check, finite2(J) and (v.shape[0] == 0 or finite(acc_b)))


@inline
def jacobian_at(args, s, ws):
    """The Jacobian pass of state ``s`` of a batch (``V`` has one row per state, or one row for all)."""
    ints, body, dofs, Q, V, b, check, JJ, OR, OP, ACC, VEL = args
    return jacobian_one(ints, body, dofs, Q[s], V[s if V.shape[0] > 1 else 0], b, check, JJ[s], OR[s], OP[s],
                        ACC[s], VEL[s], ws)


_jacobian_batch = batch_kernel(jacobian_at, motion_workspace)


def jacobian_pass(model, x, b, check, what):
    """The pass behind the Jacobian functions, for the checked states ``x`` (``"q"``, optionally
    ``"v"``, see ``_inputs.states``) and body ``b``: flat-batch arrays ``(J, oR_b, op_b, acc_b,
    vel_b)`` of :func:`jacobian_one`: the world Jacobian (B, 6, nv), the body's world rotation
    (B, 3, 3) and position (B, 3), and (with ``"v"``) its body-frame acceleration at
    ``qdd = 0`` without gravity and velocity (B, 6); errors name ``what``. For a coupled model
    (mimic joints) the full tree's at ``(E(q), G v)``, the Jacobian ``J_full G``."""
    if is_coupled(model):
        full = {"q": expand_q(model, x["q"]), **({"v": expand_v(model, x["v"])} if "v" in x else {})}
        JJ, OR, OP, ACC, VEL = jacobian_pass(model.full, full, b, check, what)
        return reduce_columns(model, JJ), OR, OP, ACC, VEL
    k = model.kernel
    q = _inputs.as_batch(x["q"])
    v = _inputs.as_batch(x["v"]) if "v" in x else np.zeros((1, 0))
    B = q.shape[0]
    JJ, OR, OP = np.empty((B, 6, model.nv)), np.empty((B, 3, 3)), np.empty((B, 3))
    ACC, VEL, status = np.empty((B, 6)), np.empty((B, 6)), np.empty(B, dtype=np.int64)
    _jacobian_batch.run((k.ints, k.body, k.dofs[(False, False)], q, v, b, check, JJ, OR, OP, ACC, VEL),
                        (model.nbodies, model.nv), status, () if x["q"].ndim == 1 else (B,))
    raise_for_status(model, status, x, what)
    return JJ, OR, OP, ACC, VEL


def moving_frame(model, body):
    """``(b, R, p)``: body index and placement in it of a body index or link/frame name; a frame
    fixed to the world (whose Jacobian is zero) is an error."""
    if isinstance(body, (int, np.integer)):
        return model.body_index(body), np.eye(3), np.zeros(3)
    b, R, p = model.frame_index(body)
    if b < 0:
        raise ValueError(f"frame {body!r} is fixed to the world; its Jacobian is zero")
    return b, R, p


def _cross(a, b):
    """Row-wise cross product of (B, 3) ``a`` with each column of (B, 3, n) ``b``."""
    return np.cross(a[:, :, None], b, axis=1)


def jacobian(model, q, body, frame: str = "world", *, check_finite: bool = True) -> np.ndarray:
    """Jacobian of a body or frame: (..., 6, nv), rows ``[linear; angular]``.

    ``body`` is a body index or a link/frame name; ``frame`` is ``"world"``, ``"local"`` or
    ``"local_world_aligned"`` (module docstring). ``J v`` is the frame's velocity and
    ``J^T [f; n]`` the joint forces balancing a wrench ``[f; n]`` in the same coordinates.
    """
    if any_lazy(q):
        return deferred(jacobian, locals())
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    b, Rbf, pbf = moving_frame(model, body)
    batch, x = _inputs.states(model, q=q)
    JJ, OR, OP, _, _ = jacobian_pass(model, x, b, check_finite, "jacobian")
    if frame != "world":
        Rf, pf = OR @ Rbf, OP + OR @ pbf
        lin = JJ[:, :3] - _cross(pf, JJ[:, 3:])
        JJ = np.concatenate([lin, JJ[:, 3:]], axis=1)
        if frame == "local":
            JJ = _rotate_T(Rf, JJ)
    return JJ[0] if batch == () else JJ.reshape(batch + JJ.shape[1:])


def _rotate_T(R, X):
    """``[R^T X_lin; R^T X_ang]`` for R (B, 3, 3) and X (B, 6, ...)."""
    out = np.empty_like(X)
    out[:, :3] = np.einsum("bji,bj...->bi...", R, X[:, :3])
    out[:, 3:] = np.einsum("bji,bj...->bi...", R, X[:, 3:])
    return out


def jacobian_dot_times_v(model, q, v, body, frame: str = "world", *, check_finite: bool = True) -> np.ndarray:
    """``Jdot(q, v) v`` (..., 6), rows ``[linear; angular]``, for the Jacobian of
    :func:`jacobian` with the same ``body`` and ``frame``: the frame's acceleration when
    ``qdd = 0``, so that its acceleration is ``J qdd + Jdot v``."""
    if any_lazy(q, v):
        return deferred(jacobian_dot_times_v, locals())
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    b, Rbf, pbf = moving_frame(model, body)
    batch, x = _inputs.states(model, q=q, v=v)
    _, OR, OP, ACC, VEL = jacobian_pass(model, x, b, check_finite, "jacobian_dot_times_v")
    # spatial acceleration and velocity in the frame's own coordinates (frame rigid on body b)
    acc_f = _rotate_T(np.broadcast_to(Rbf, OR.shape), _shift(ACC, pbf))
    if frame == "local":
        out = acc_f
    elif frame == "world":
        lin, ang = np.einsum("bij,bj->bi", OR, ACC[:, :3]), np.einsum("bij,bj->bi", OR, ACC[:, 3:])
        out = np.concatenate([lin + np.cross(OP, ang), ang], axis=1)
    else:
        vel_f = _rotate_T(np.broadcast_to(Rbf, OR.shape), _shift(VEL, pbf))
        Rf = OR @ Rbf
        classical = acc_f[:, :3] + np.cross(vel_f[:, 3:], vel_f[:, :3])
        out = np.concatenate([np.einsum("bij,bj->bi", Rf, classical), np.einsum("bij,bj->bi", Rf, acc_f[:, 3:])], axis=1)
    return out[0] if batch == () else out.reshape(batch + (6,))


def _shift(m, p):
    """Motion vectors (B, 6) re-expressed at the point ``p`` (same axes): ``v - p x w``."""
    out = m.copy()
    out[:, :3] -= np.cross(p, m[:, 3:])
    return out
