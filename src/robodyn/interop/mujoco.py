"""States and forces between robodyn and MuJoCo, for a model read by :func:`robodyn.load_mjcf`.

The loader keeps MuJoCo's order of bodies and coordinates, and hinge and slide coordinates are
MuJoCo's ``qpos``, ``qvel``, ``qacc`` exactly (``ref`` is folded into the joint placement).
Free joints differ in two conventions, which these functions convert:

=================== ============================================= ===============================
free joint          MuJoCo                                        robodyn (as Pinocchio)
=================== ============================================= ===============================
configuration       ``[x, y, z, qw, qx, qy, qz]``                 ``[x, y, z, qx, qy, qz, qw]``
velocity            ``[pdot (world), omega (body)]``              ``[R^T pdot, omega]`` (body)
acceleration        ``[pddot (world), omegadot (body)]``          ``d/dt [R^T pdot, omega]``
generalized force   ``[f (world), n (body)]``                     ``[R^T f, n]`` (body)
=================== ============================================= ===============================

Ball joints (robodyn's spherical joints) differ only in the quaternion order: their velocity
is the angular velocity in the body frame in both. So ``v = T qvel`` with ``T = diag(R^T, 1)`` on each free joint (``R`` the body's rotation),
``a = T qacc - [omega x R^T pdot; 0]``, and the mass matrices and bias forces relate as
``M_mujoco = T^T M T``, ``qfrc = T^T tau``. Arrays may carry leading batch dimensions.

One modelling difference remains on free joints with ``armature``: MuJoCo adds
``armature * qacc``, robodyn (as Pinocchio) ``armature * a``; the mass matrices agree, the
inverse dynamics differ by ``armature * (omega x R^T pdot)`` on the linear part. Joint damping
agrees (``damping * qvel`` is ``T^T damping * v``).
"""

from __future__ import annotations

import numpy as np

from .. import joints as J
from ..lie import quat_matrix
from ..model import Model

__all__ = ["force_to_qfrc", "q_to_qpos", "qacc_to_a", "qfrc_to_force", "qpos_to_q", "qvel_to_v", "v_to_qvel"]


def _quaternions(model: Model):
    """Where the quaternion of every free and ball (spherical) joint starts in ``q``."""
    return [int(model.idx_q[i] + J.QUAT_OFFSET[model.joint_type[i]]) for i in range(model.nbodies)
            if J.QUAT_OFFSET[model.joint_type[i]] >= 0]


def _free(model: Model):
    """``(q index, v index)`` of every free joint."""
    return [(int(model.idx_q[i]), int(model.idx_v[i])) for i in range(model.nbodies) if model.joint_type[i] == J.FREE]


def _array(x, n: int, what: str) -> np.ndarray:
    x = np.array(x, dtype=float)
    if x.ndim == 0 or x.shape[-1] != n:
        raise ValueError(f"{what} must have {n} entries on its last axis, got shape {x.shape}")
    return x


def _rotation(q: np.ndarray, iq: int) -> np.ndarray:
    """Rotations (..., 3, 3) of the free joint whose robodyn configuration starts at ``iq``."""
    return quat_matrix(q[..., iq + 3:iq + 7])


def qpos_to_q(model: Model, qpos) -> np.ndarray:
    """robodyn configuration (..., nq) from MuJoCo's ``qpos`` (quaternions reordered)."""
    q = _array(qpos, model.nq, "qpos")
    for k in _quaternions(model):
        q[..., k:k + 4] = np.roll(q[..., k:k + 4], -1, axis=-1)
    return q


def q_to_qpos(model: Model, q) -> np.ndarray:
    """MuJoCo's ``qpos`` (..., nq) from a robodyn configuration."""
    qpos = _array(q, model.nq, "q")
    for k in _quaternions(model):
        qpos[..., k:k + 4] = np.roll(qpos[..., k:k + 4], 1, axis=-1)
    return qpos


def _linear(model: Model, q, x, what: str, to_body: bool) -> np.ndarray:
    """``x`` (..., nv) with each free joint's linear part turned into body (``R^T``) or world
    (``R``) coordinates."""
    q = _array(q, model.nq, "q")
    out = _array(x, model.nv, what)
    for iq, iv in _free(model):
        R = _rotation(q, iq)
        sub = "...ji,...j->...i" if to_body else "...ij,...j->...i"
        out[..., iv:iv + 3] = np.einsum(sub, R, out[..., iv:iv + 3])
    return out


def qvel_to_v(model: Model, q, qvel) -> np.ndarray:
    """robodyn velocity ``v = T qvel`` (..., nv) at the robodyn configuration ``q``."""
    return _linear(model, q, qvel, "qvel", to_body=True)


def v_to_qvel(model: Model, q, v) -> np.ndarray:
    """MuJoCo's ``qvel`` (..., nv) from a robodyn velocity at configuration ``q``."""
    return _linear(model, q, v, "v", to_body=False)


def qacc_to_a(model: Model, q, qvel, qacc) -> np.ndarray:
    """robodyn acceleration from MuJoCo's ``qacc``: on a free joint ``R^T pddot - omega x v``
    (the derivative of the body-frame velocity ``v = R^T pdot``)."""
    a = _linear(model, q, qacc, "qacc", to_body=True)
    v = qvel_to_v(model, q, qvel)
    for _, iv in _free(model):
        a[..., iv:iv + 3] -= np.cross(v[..., iv + 3:iv + 6], v[..., iv:iv + 3])
    return a


def force_to_qfrc(model: Model, q, tau) -> np.ndarray:
    """MuJoCo's generalized force ``T^T tau`` (..., nv) from a robodyn one (``rnea``'s ``tau``)."""
    return _linear(model, q, tau, "tau", to_body=False)


def qfrc_to_force(model: Model, q, qfrc) -> np.ndarray:
    """robodyn generalized force (..., nv) from MuJoCo's (``T^-T qfrc``)."""
    return _linear(model, q, qfrc, "qfrc", to_body=True)
