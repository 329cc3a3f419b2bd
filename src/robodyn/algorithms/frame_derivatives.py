"""Derivatives of a frame's velocity and acceleration: ``d(J v)/d(q, v)`` and
``d(J a + Jdot v)/d(q, v, a)``, in the three frames of :func:`robodyn.jacobian`.

In world coordinates (spatial vectors at the world origin), with ``J_k`` the Jacobian columns
of the dofs on the path from the root to the frame's body ``b``, ``V = J v`` and ``A = J a +
Jdot v`` the body's spatial velocity and acceleration, and ``ov_k``, ``oa_k`` those of the
parent of dof ``k``'s body (zero at a root; no gravity): a step ``q ⊕ eps e_k`` turns the
subtree of ``k`` rigidly by ``J_k``, so ``J_j -> J_j + eps J_k x J_j`` for the dofs ``j`` after
``k`` and the velocities of their bodies ``ov -> ov + eps J_k x (ov - ov_k)``; with the Jacobi
identity of the cross product::

    dV/dq_k = J_k x (V - ov_k)
    dA/dq_k = J_k x (A - oa_k) - (J_k x ov_k) x (V - ov_k)
    dA/dv_k = ov_bk x J_k + J_k x (V - ov_k)        (ov_bk: the velocity of k's body)
    dV/dv = dA/da = J

The frame's own coordinates (``"local"``) move with it, ``d(fX_0) = -fX_0 (J_k x)``:
``dV_f/dq_k = fX_0 (ov_k x J_k)`` and ``dA_f/dq_k = -fX_0 (J_k x oa_k + (J_k x ov_k) x (V -
ov_k))`` (Pinocchio's ``dVdq``, ``dAdq``). In ``"local_world_aligned"`` the velocity is that of
the frame origin ``p`` (``v_p = V_lin + w x p``) and the acceleration the classical one
(``a_p = A_lin + alpha x p + w x v_p``, as :func:`robodyn.jacobian_dot_times_v`), differentiated
with ``dp/dq_k = v_k + w_k x p``. (Pinocchio's ``LOCAL_WORLD_ALIGNED`` derivatives hold the
point fixed instead: the world derivative re-expressed at ``p``.)

Reference: Carpentier and Mansard, RSS 2018 (the kinematic derivatives); Pinocchio's
``getFrameVelocityDerivatives`` and ``getFrameAccelerationDerivatives``.
"""

from __future__ import annotations

import numpy as np

from ..layout import NDOF
from ..coupling import expand_q, expand_v, is_coupled
from ._lazy import any_lazy, deferred
from . import _inputs
from .jacobian import FRAMES, jacobian_pass, moving_frame


def _cross(a, b):
    """Spatial cross product ``a x b`` of motions (..., 6) (``[w x v' + v x w'; w x w']``),
    broadcast over the leading dimensions."""
    va, wa, vb, wb = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    return np.concatenate([np.cross(wa, vb) + np.cross(va, wb), np.cross(wa, wb)], -1)


def _path_motions(model, J, v, a, b):
    """Per dof (B, nv, 6): the velocity and acceleration of the parent of its body and the
    velocity of its body (zero off the path of body ``b``), world coordinates."""
    B, nv = J.shape[0], model.nv
    ov_parent, oa_parent, ov_body = (np.zeros((B, nv, 6)) for _ in range(3))
    path = []
    j = b
    while j >= 0:
        path.append(j)
        j = model.parent[j]
    ov, oa = np.zeros((B, 6)), np.zeros((B, 6))
    nv_of = model.kernel.ints[:, NDOF]
    for j in reversed(path):
        dofs = slice(model.idx_v[j], model.idx_v[j] + nv_of[j])
        cols = np.swapaxes(J[:, :, dofs], 1, 2)  # (B, n, 6)
        ov_parent[:, dofs], oa_parent[:, dofs] = ov[:, None], oa[:, None]
        vJ = np.einsum("bkr,bk->br", cols, v[:, dofs])
        ov = ov + vJ
        oa = oa + np.einsum("bkr,bk->br", cols, a[:, dofs]) + _cross(ov, vJ)
        ov_body[:, dofs] = ov[:, None]
    return ov_parent, oa_parent, ov_body


def _world(model, x, b, what, check):
    """World ``(J, V, A, dV/dq, dA/dq, dA/dv, oR_b, op_b)`` of body ``b`` for the states ``x``
    (flat batch; the Jacobian and the derivatives as columns, (B, nv, 6)). A coupled model
    (mimic joints): the full tree's at ``(E(q), G v, G a)``, the columns mapped by ``G``."""
    if is_coupled(model):
        full = {"q": expand_q(model, x["q"]), **{k: expand_v(model, x[k], k) for k in ("v", "a") if k in x}}
        Jc, V, A, dV, dAq, dAv, OR, OP = _world(model.full, full, b, what, check)
        Jc, dV, dAq, dAv = (np.einsum("bkr,kc->bcr", m, model.G) for m in (Jc, dV, dAq, dAv))
        return Jc, V, A, dV, dAq, dAv, OR, OP
    JJ, OR, OP, ACC, _ = jacobian_pass(model, x, b, check, what)
    q = _inputs.as_batch(x["q"])
    v = np.broadcast_to(_inputs.as_batch(x["v"]), (q.shape[0], model.nv))
    a = np.broadcast_to(_inputs.as_batch(x["a"]), v.shape) if "a" in x else np.zeros_like(v)
    Jc = np.swapaxes(JJ, 1, 2)  # (B, nv, 6): the columns
    V = np.einsum("bkr,bk->br", Jc, v)
    acc_lin = np.einsum("bij,bj->bi", OR, ACC[:, :3])
    acc_ang = np.einsum("bij,bj->bi", OR, ACC[:, 3:])
    A = np.concatenate([acc_lin + np.cross(OP, acc_ang), acc_ang], -1) + np.einsum("bkr,bk->br", Jc, a)
    ovp, oap, ovb = _path_motions(model, JJ, v, a, b)
    dV = _cross(Jc, V[:, None] - ovp)
    dAq = _cross(Jc, A[:, None] - oap) - _cross(_cross(Jc, ovp), V[:, None] - ovp)
    dAv = _cross(ovb, Jc) + _cross(Jc, V[:, None] - ovp)
    return Jc, V, A, dV, dAq, dAv, OR, OP


def _to_frame(frame, Rf, pf, M):
    """Spatial motions ``M`` (B, n, 6) at the world origin in world axes, in the ``"local"``
    coordinates of the frame at ``(Rf, pf)`` (``"world"``: unchanged)."""
    if frame == "world":
        return M
    lin = M[..., :3] - np.cross(pf[:, None], M[..., 3:])
    return np.concatenate([np.einsum("bji,bkj->bki", Rf, lin), np.einsum("bji,bkj->bki", Rf, M[..., 3:])], -1)


def _velocity_aligned(pf, Jc, V, dV):
    """``(dv_p/dq, dv_p/dv)`` (B, nv, 6) of the frame origin's velocity in world axes."""
    dp = Jc[..., :3] + np.cross(Jc[..., 3:], pf[:, None])  # the origin's velocity per dof: also dv_p/dv
    lin_q = dV[..., :3] + np.cross(dV[..., 3:], pf[:, None]) + np.cross(V[:, None, 3:], dp)
    return np.concatenate([lin_q, dV[..., 3:]], -1), np.concatenate([dp, Jc[..., 3:]], -1), dp


def _finish(out, batch):
    """(B, nv, 6) columns as (..., 6, nv) matrices."""
    out = [np.ascontiguousarray(np.swapaxes(m, 1, 2)) for m in out]
    return tuple(m[0] if batch == () else m.reshape(batch + m.shape[1:]) for m in out)


def _setup(model, body, frame, **arrays):
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    b, Rbf, pbf = moving_frame(model, body)
    batch, x = _inputs.states(model, **arrays)
    return b, Rbf, pbf, batch, x


def frame_velocity_derivatives(model, q, v, body, frame: str = "world", *,
                               check_finite: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """``(dV/dq, dV/dv)`` (..., 6, nv) of the velocity ``V = J(q) v`` of a body or frame
    (:func:`robodyn.jacobian` with the same ``body`` and ``frame``); ``dV/dv = J``, ``q``
    in the tangent space of :func:`robodyn.integrate` (see the module docstring)."""
    if any_lazy(q, v):
        return deferred(frame_velocity_derivatives, locals())
    b, Rbf, pbf, batch, x = _setup(model, body, frame, q=q, v=v)
    Jc, V, _, dV, _, _, OR, OP = _world(model, x, b, "frame_velocity_derivatives", check_finite)
    Rf, pf = OR @ Rbf, OP + OR @ pbf
    if frame == "local_world_aligned":
        dq, dv, _ = _velocity_aligned(pf, Jc, V, dV)
        return _finish((dq, dv), batch)
    if frame == "local":
        dV = dV - _cross(Jc, V[:, None])  # the frame turns with the subtree
    return _finish((_to_frame(frame, Rf, pf, dV), _to_frame(frame, Rf, pf, Jc)), batch)


def frame_acceleration_derivatives(model, q, v, a, body, frame: str = "world", *,
                                   check_finite: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(dA/dq, dA/dv, dA/da)`` (..., 6, nv) of the acceleration ``A = J(q) a + Jdot(q, v) v``
    of a body or frame (:func:`robodyn.jacobian` and :func:`robodyn.jacobian_dot_times_v` with
    the same ``body`` and ``frame``: spatial for ``"world"``/``"local"``, classical for
    ``"local_world_aligned"``); ``dA/da = J`` (see the module docstring)."""
    if any_lazy(q, v, a):
        return deferred(frame_acceleration_derivatives, locals())
    b, Rbf, pbf, batch, x = _setup(model, body, frame, q=q, v=v, a=a)
    Jc, V, A, dV, dAq, dAv, OR, OP = _world(model, x, b, "frame_acceleration_derivatives", check_finite)
    Rf, pf = OR @ Rbf, OP + OR @ pbf
    if frame == "local_world_aligned":
        dvq, dvv, dp = _velocity_aligned(pf, Jc, V, dV)
        p, w, alpha = pf[:, None], V[:, None, 3:], A[:, None, 3:]
        vp = V[:, None, :3] + np.cross(w, p)

        def classical(dA, dW, dvp, dpos):
            return (dA[..., :3] + np.cross(dA[..., 3:], p) + np.cross(alpha, dpos) + np.cross(dW, vp)
                    + np.cross(w, dvp))

        lin_q = classical(dAq, dV[..., 3:], dvq[..., :3], dp)
        lin_v = classical(dAv, Jc[..., 3:], dvv[..., :3], np.zeros_like(dp))
        return _finish((np.concatenate([lin_q, dAq[..., 3:]], -1), np.concatenate([lin_v, dAv[..., 3:]], -1), dvv),
                       batch)
    if frame == "local":
        dAq = dAq - _cross(Jc, A[:, None])  # the frame turns with the subtree
    return _finish(tuple(_to_frame(frame, Rf, pf, m) for m in (dAq, dAv, Jc)), batch)
