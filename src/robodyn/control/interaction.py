"""Interaction control: a frame of the robot behaves as a spring and damper about a desired
pose, so that contact forces stay bounded and predictable.

:class:`CartesianImpedance` (Hogan 1985; Siciliano et al., *Robotics* (2009), section 9.3,
impedance control without inertia shaping, with gravity compensation):

    tau = J^T (K e - D J v) - D_q v + g(q),    e = [x_d - x; log(R_d R^T)]   (world axes)

``J`` (6, nv) is the Jacobian of the frame's origin in world axes (``"local_world_aligned"``),
``log(R_d R^T)`` the rotation vector of the orientation error, ``K``, ``D`` (6,) the
stiffness and damping of the spring ``[linear; angular]`` and ``D_q`` a joint damping for the
redundant directions. At rest under an external wrench ``w = [f; n]`` on the frame (world
axes, torque about its origin) the frame sits where the spring balances it:
``K e = -w``, a displacement ``f / K`` and a rotation by the vector ``n / K`` (the rotation
error is the exact rotation vector, so this holds for large rotations too), whatever the
arm's configuration, as long as ``J`` has full row rank. Orientation may be left free
(``orientation=None``: three task rows, the position only).

:class:`HybridForcePosition` (Raibert & Craig 1981, with the selection given by a surface
normal ``n``; Siciliano et al. (2009), section 9.6): the frame pushes with force ``f_d`` along
``-n`` (into the surface) and follows a path in the surface's plane,

    F = P (K (x_d(t) - x) - D x') - f_d n - D_n n n^T x',   P = 1 - n n^T,
    tau = J^T F - D_q v + g(q)

(``J`` the (3, nv) Jacobian of the frame's origin in world axes). Against a rigid surface the
normal contact force settles at ``f_d`` exactly (the commanded force is what the surface must
return at rest), and stays there while the frame slides along the path.
"""

from __future__ import annotations

import numpy as np

from ..algorithms.crba import crba
from ..algorithms.jacobian import jacobian, jacobian_dot_times_v
from ..algorithms.kinematics import frame_pose
from ..algorithms.task_space import task_rows, task_space_dynamics
from ..algorithms.terms import gravity, nonlinear_effects
from .controllers import Controller, gain


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """The rotation vector ``theta u`` of a rotation matrix (the log map of SO(3)), with
    ``theta`` in ``[0, pi]``; accurate near 0 and near pi."""
    cos = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sin = 0.5 * np.linalg.norm(w)
    theta = np.arctan2(sin, cos)
    if sin > 1e-6:
        return theta / (2.0 * sin) * w
    if cos > 0:  # near the identity: theta / sin(theta) -> 1
        return 0.5 * (1.0 + theta * theta / 6.0) * w
    # near pi: the axis from the symmetric part, R + R^T = 2 cos 1 + 2 (1 - cos) u u^T
    B = (R + R.T - 2.0 * cos * np.eye(3)) / (2.0 * (1.0 - cos))
    k = int(np.argmax(np.diag(B)))
    u = B[:, k] / np.sqrt(B[k, k])
    return theta * (u if w @ u >= 0 else -u)


class CartesianImpedance(Controller):
    """Impedance control of a link or frame ``body`` about a desired pose (module docstring).

    Args:
        body: a link or frame name of ``model``.
        position: (3,) desired origin in the world frame.
        orientation: (3, 3) desired rotation in the world frame, or None to leave it free.
        stiffness, damping: the spring's ``K`` and ``D``: numbers or (3,) for the position,
            and (with an orientation) (6,) vectors ``[linear; angular]`` or pairs
            ``(linear, angular)``.
        joint_damping: ``D_q``, > 0 (numbers or (nv,)).
    """

    def __init__(self, model, body: str, position, orientation=None, *, stiffness, damping, joint_damping=1.0):
        super().__init__(model)
        self.body = body
        model.frame_index(body)  # raises for an unknown name
        self.x_d = np.array(position, dtype=float)
        if self.x_d.shape != (3,) or not np.all(np.isfinite(self.x_d)):
            raise ValueError(f"position: expected 3 finite numbers, got shape {self.x_d.shape}")
        self.R_d = None if orientation is None else np.array(orientation, dtype=float)
        if self.R_d is not None and (self.R_d.shape != (3, 3) or not np.allclose(self.R_d @ self.R_d.T, np.eye(3),
                                                                               atol=1e-9)):
            raise ValueError("orientation: expected a 3 x 3 rotation matrix")
        m = 3 if self.R_d is None else 6
        self.K, self.D = self._gains("stiffness", stiffness, m), self._gains("damping", damping, m)
        self.joint_damping = gain("joint_damping", joint_damping, model.nv)

    @staticmethod
    def _gains(name, value, m):
        if m == 6 and isinstance(value, tuple) and len(value) == 2:
            value = np.concatenate([np.broadcast_to(np.asarray(v, dtype=float), (3,)) for v in value])
        return gain(name, value, m)

    def error(self, q) -> np.ndarray:
        """``e = [x_d - x; log(R_d R^T)]`` (3 or 6,) in world axes."""
        T = frame_pose(self.model, q, self.body)
        e = self.x_d - T[:3, 3]
        if self.R_d is None:
            return e
        return np.concatenate([e, rotation_vector(self.R_d @ T[:3, :3].T)])

    def __call__(self, t, q, v):
        J = jacobian(self.model, q, self.body, "local_world_aligned")[:self.K.shape[0]]
        f = self.K * self.error(q) - self.D * (J @ v)
        return J.T @ f - self.joint_damping * v + gravity(self.model, q)


class HybridForcePosition(Controller):
    """Force along a surface normal, position in its plane (module docstring).

    Args:
        body: the link or frame in contact.
        normal: (3,) the surface's outward unit normal in world axes (the surface pushes the
            frame along it).
        force: ``f_d`` (N), the normal force to hold, > 0.
        path: a callable ``t -> x_d`` (3,) (world), its component along ``normal`` ignored.
        stiffness, damping: ``K``, ``D`` of the position control in the plane (numbers).
        normal_damping: ``D_n``, damping of the approach along the normal.
        joint_damping: ``D_q`` (numbers or (nv,)).
    """

    def __init__(self, model, body: str, normal, force: float, path, *, stiffness, damping,
                 normal_damping=None, joint_damping=1.0):
        super().__init__(model)
        model.frame_index(body)
        self.body = body
        self.n = np.array(normal, dtype=float)
        if self.n.shape != (3,) or abs(np.linalg.norm(self.n) - 1.0) > 1e-9:
            raise ValueError(f"normal: expected a unit vector (3,), got {normal!r}")
        if not (np.isfinite(force) and force > 0):
            raise ValueError(f"force: expected a number > 0, got {force!r}")
        if not callable(path):
            raise ValueError(f"path: expected a callable t -> (3,) position, got {type(path).__name__}")
        self.force, self.path = float(force), path
        self.K, self.D = gain("stiffness", stiffness, 1)[0], gain("damping", damping, 1)[0]
        self.Dn = self.D if normal_damping is None else gain("normal_damping", normal_damping, 1)[0]
        self.joint_damping = gain("joint_damping", joint_damping, model.nv)
        self.P = np.eye(3) - np.outer(self.n, self.n)

    def __call__(self, t, q, v):
        x = frame_pose(self.model, q, self.body)[:3, 3]
        J = jacobian(self.model, q, self.body, "local_world_aligned")[:3]
        xdot = J @ v
        x_d = np.asarray(self.path(t), dtype=float)
        F = self.P @ (self.K * (x_d - x) - self.D * xdot) - self.force * self.n - self.Dn * self.n * (self.n @ xdot)
        return J.T @ F - self.joint_damping * v + gravity(self.model, q)


class OperationalSpace(Controller):
    """Khatib's operational-space control of a frame's position with a posture in the null
    space (Khatib 1987; Siciliano et al. (2009), section 8.6.2):

        F = Lambda (x_d'' + Kd (x_d' - x') + Kp (x_d - x)) + mu + p
        tau = J^T F + (1 - J^T Jbar^T) (Kp_n (q_p - q) - Kd_n v + g(q))

    with ``Lambda, mu, p, Jbar`` of :func:`robodyn.task_space_dynamics` (rows of the frame's
    origin velocity in world axes: ``rows``, default the three linear ones). With an exact
    model the task error obeys ``e'' + Kd e' + Kp e = 0`` whatever the posture does, and the
    posture torques never disturb the task.

    Args:
        body: the link or frame. target: ``t -> (x_d, x_d', x_d'')`` for the selected rows, or
            a fixed (m,) position. kp, kd: task gains (numbers or (m,)). posture: (nv,) and
            posture_kp, posture_kd: the null-space PD.
    """

    def __init__(self, model, body: str, target, kp, kd, *, posture=None, posture_kp=10.0, posture_kd=2.0,
                 rows="linear"):
        super().__init__(model)
        model.frame_index(body)
        self.body = body
        self.index = task_rows(rows)[0]
        if np.any(self.index > 2):
            raise ValueError(f"{type(self).__name__}: position rows (0-2) only, got rows {rows!r}")
        m = self.index.size
        if not callable(target):
            fixed = np.array(target, dtype=float)
            if fixed.shape != (m,) or not np.all(np.isfinite(fixed)):
                raise ValueError(f"target: expected {m} finite numbers or a callable t -> (x, x', x''), "
                                 f"got shape {fixed.shape}")
            target = lambda t: (fixed, np.zeros(m), np.zeros(m))  # noqa: E731
        self.target = target
        self.kp, self.kd = gain("kp", kp, m), gain("kd", kd, m)
        self.posture = np.zeros(model.nv) if posture is None else np.array(posture, dtype=float).reshape(model.nv)
        self.posture_kp, self.posture_kd = gain("posture_kp", posture_kp, model.nv), gain("posture_kd", posture_kd,
                                                                                          model.nv)

    def position(self, q) -> np.ndarray:
        """The selected rows of the frame's origin (world): position rows only (0-2)."""
        return frame_pose(self.model, q, self.body)[:3, 3][self.index]

    def __call__(self, t, q, v):
        return self.law(q, v, *self.target(t))

    def law(self, q, v, x_d, xd_d, xdd_d, force=0.0):
        """The joint torques for the task reference ``(x_d, x_d', x_d'')`` (module docstring),
        compensating a known external force ``force`` (m,) on the frame."""
        T = task_space_dynamics(self.model, q, v, self.body, "local_world_aligned", self.index)
        x_d, xd_d, xdd_d = (np.asarray(y, dtype=float) for y in (x_d, xd_d, xdd_d))
        e, ed = x_d - self.position(q), xd_d - T.J @ v
        F = T.Lambda @ (xdd_d + self.kd * ed + self.kp * e) + T.mu + T.p - force
        tau0 = self.posture_kp * (self.posture - q) - self.posture_kd * v + gravity(self.model, q)
        return T.J.T @ F + tau0 - T.J.T @ (T.Jbar.T @ tau0)


class Admittance(OperationalSpace):
    """Admittance control (Siciliano et al. (2009), section 9.4): a measured external force
    ``f`` on the frame drives a virtual mass-spring-damper about ``rest``,

        M_a x_a'' + D_a x_a' + K_a (x_a - rest) = f,

    whose position ``x_a`` the frame tracks with the stiff inner loop of
    :class:`OperationalSpace` (the force compensated). At rest under a constant force the frame
    sits at ``rest + f / K_a``. The virtual state ``[x_a, x_a']`` is the controller's state.
    ``force``: a callable ``(t, q, v) -> f`` (m,), the force sensor's reading.
    """

    def __init__(self, model, body: str, rest, force, *, mass, damping, stiffness, kp, kd, **options):
        super().__init__(model, body, rest, kp, kd, **options)
        if not callable(force):
            raise ValueError(f"force: expected a callable (t, q, v) -> f, got {type(force).__name__}")
        m = self.index.size
        self.rest = np.array(rest, dtype=float).reshape(m)
        self.force = force
        self.Ma, self.Da, self.Ka = gain("mass", mass, m), gain("damping", damping, m), gain("stiffness", stiffness, m)
        self.state0 = np.concatenate([self.rest, np.zeros(m)])

    def _accel(self, t, q, v, z):
        m = self.index.size
        f = np.asarray(self.force(t, q, v), dtype=float)
        return f, (f - self.Da * z[m:] - self.Ka * (z[:m] - self.rest)) / self.Ma

    def torque(self, t, q, v, z):
        m = self.index.size
        f, acc = self._accel(t, q, v, z)
        return self.law(q, v, z[:m], z[m:], acc, force=f)

    def state_rate(self, t, q, v, z):
        m = self.index.size
        return np.concatenate([z[m:], self._accel(t, q, v, z)[1]])


class WorkspaceComputedTorque(OperationalSpace):
    """Murray, Li & Sastry's workspace computed torque (ch. 4, section 5.3) for a
    non-redundant arm (as many task rows as joints, ``J`` square and invertible):

        tau = M J^-1 (x_d'' - Jdot v + Kd (x_d' - x') + Kp (x_d - x)) + C v + g

    the task error obeying ``e'' + Kd e' + Kp e = 0``. For such arms it is
    :class:`OperationalSpace` without a null space (``J^T Lambda = M J^-1``); written here in
    the book's form."""

    def __init__(self, model, body: str, target, kp, kd, *, rows="linear"):
        super().__init__(model, body, target, kp, kd, rows=rows)
        if self.index.size != model.nv:
            raise ValueError(f"WorkspaceComputedTorque: a non-redundant arm needs as many task rows as joints "
                             f"({model.nv}), got {self.index.size}; use OperationalSpace")

    def law(self, q, v, x_d, xd_d, xdd_d, force=0.0):
        J = jacobian(self.model, q, self.body, "local_world_aligned")[self.index]
        Jdv = jacobian_dot_times_v(self.model, q, v, self.body, "local_world_aligned")[self.index]
        e, ed = np.asarray(x_d, float) - self.position(q), np.asarray(xd_d, float) - J @ v
        y = np.linalg.solve(J, np.asarray(xdd_d, float) - Jdv + self.kd * ed + self.kp * e)
        return crba(self.model, q) @ y + nonlinear_effects(self.model, q, v) - J.T @ np.broadcast_to(force, (len(y),))
