"""Interaction control: a frame of the robot behaves as a spring and damper about a desired
pose, so that contact forces stay bounded and predictable.

Conventions of the whole module: ``J`` (6, nv) is the Jacobian of the frame's origin in world
axes (``"local_world_aligned"``), rows ``[linear; angular]`` (vx, vy, vz, wx, wy, wz), so
that ``J v = [p'; w]`` (the origin's velocity and the frame's angular velocity, world axes).
The pose error of a frame at ``(p, R)`` from a desired ``(p_d, R_d)`` is the 6-vector

    e = [p_d - p; log(R_d R^T)]                                                   (world axes)

``log(R_d R^T)`` the rotation vector ``theta u`` (:func:`rotation_vector`) of the rotation that
takes the frame onto the desired orientation: the "angle and axis" orientation error of
Siciliano et al., *Robotics* (2009), section 3.7.3, with ``theta u`` in place of their
``sin(theta) u`` so that it stays exact for large rotations. A subset of task rows selects
the same entries of ``e``, of the velocity error and of the reference acceleration.

:class:`CartesianImpedance` (Hogan 1985; Siciliano et al. (2009), section 9.3), without
inertia shaping (the default), with gravity compensation:

    tau = J^T (K e - D J v) - D_q v + g(q)

``K``, ``D`` (6,) the stiffness and damping of the spring ``[linear; angular]`` and ``D_q`` a
joint damping for the redundant directions. At rest under an external wrench ``h_e = [f; n]``
on the frame (world axes, torque about its origin) the frame sits where the spring balances
it: ``K e = -h_e``, a displacement ``f / K`` and a rotation by the vector ``n / K`` (the
rotation error is the exact rotation vector, so this holds for large rotations too),
whatever the arm's configuration, as long as ``J`` has full row rank. Orientation may be left
free (``orientation=None``: three task rows, the position only).

With inertia shaping (``inertia=M_d``, and ``force``: the measured external wrench ``h_e``)
the frame behaves as a desired mass-spring-damper,

    M_d x~'' + D x~' + K x~ = h_e,     x~ = -e,  x~' = J v,  x~'' = J v' + J' v

(``M_d e'' + D e' + K e = -h_e`` for the position rows), imposed through the task-space
dynamics ``Lambda x'' + mu + p = F + h_e`` of :func:`robodyn.task_space_dynamics`:

    a = M_d^-1 (K e - D J v + h_e),    F = Lambda a + mu + p - h_e
    tau = J^T F + (1 - J^T Jbar^T) (-D_q v + g(q))

With an exact model ``x~'' = a`` exactly, and the joint damping, projected into the null
space of the task, does not disturb it (a redundant arm keeps its self-motion damped). The
angular rows obey ``M_d w' + D w - K log(R_d R^T) = n`` exactly; about a fixed axis, this is
the linear equation of the angle.

:class:`HybridForcePosition` (Raibert & Craig 1981, with the selection given by a surface
normal ``n``; Siciliano et al. (2009), section 9.6): the frame pushes with force ``f_d`` along
``-n`` (into the surface) and follows a path in the surface's plane,

    F = P (K (x_d(t) - x) - D x') - f_d n - D_n n n^T x',   P = 1 - n n^T,
    tau = J^T F - D_q v + g(q)

(``J`` the (3, nv) Jacobian of the frame's origin in world axes). Against a rigid surface the
normal contact force settles at ``f_d`` exactly (the commanded force is what the surface must
return at rest), and stays there while the frame slides along the path.

:class:`OperationalSpace` (Khatib 1987) and :class:`WorkspaceComputedTorque` (Murray, Li &
Sastry 1994) drive the selected rows of the pose error to zero with the task acceleration

    x'' = x_d'' + Kd (x_d' - J v) + Kp e        (selected rows)

the reference being ``(x_d, x_d', x_d'')`` for position rows, and ``(pose_d, twist_d,
twist_d')`` for rows with angular ones (``twist_d = [p_d'; w_d]``, ``R_d' = [w_d]x R_d``).
With an exact model the position rows obey ``e'' + Kd e' + Kp e = 0`` and the angular rows
``dw' + Kd dw + Kp e_o = 0``, with ``e_o = log(R_d R^T)`` and ``dw = w_d - w`` (the
resolved-acceleration orientation control of Siciliano et al. (2009), sections 3.7.3 and
8.6, with the geometric Jacobian). The rate of ``e_o`` is ``J_l(e_o)^-1 (w_d - R_d R^T w)``
(``J_l`` the left Jacobian of SO(3)): ``dw`` to first order in the error, and exactly when
the error's axis, ``w_d`` and ``w`` stay parallel (a set point reached from rest by a turn
about one axis, a reference turning about it), the angle then obeying
``e'' + Kd e' + Kp e = 0``. The orientation converges locally.

References: N. Hogan, "Impedance control: an approach to manipulation", ASME J. Dynamic
Systems, Measurement and Control 107, 1985; O. Khatib, "A unified approach for motion and
force control of robot manipulators: the operational space formulation", IEEE J. Robotics
and Automation 3(1), 1987; Murray, Li & Sastry, *A Mathematical Introduction to Robotic
Manipulation* (1994), chapter 4, section 5.3; Siciliano, Sciavicco, Villani, Oriolo,
*Robotics: Modelling, Planning and Control* (2009), sections 3.7.3, 8.6, 9.3, 9.6.
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


def _rotation_matrix(name: str, R) -> np.ndarray:
    """``R`` as a (3, 3) rotation matrix (``R R^T = 1`` within 1e-9, ``det R = +1``), or a
    ValueError naming ``name``."""
    R = np.array(R, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise ValueError(f"{name}: expected a 3 x 3 rotation matrix, got shape {R.shape}")
    if np.abs(R @ R.T - np.eye(3)).max() > 1e-9 or np.linalg.det(R) <= 0:
        raise ValueError(f"{name}: expected a 3 x 3 rotation matrix (R R^T = 1 within 1e-9, det R = +1), got "
                         f"{np.round(R, 6).tolist()}")
    return R


def _pose(name: str, value) -> tuple[np.ndarray, np.ndarray]:
    """``(p (3,), R (3, 3))`` of a pose given as a (4, 4) homogeneous matrix ``[[R, p], [0, 1]]``
    or a pair ``(p, R)`` (world frame), or a ValueError naming ``name``."""
    if isinstance(value, (tuple, list)) and len(value) == 2:
        p, R = value
    else:
        T = np.asarray(value, dtype=float)
        if T.shape != (4, 4) or not np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0]):
            raise ValueError(f"{name}: expected a pose, a (4, 4) homogeneous matrix with last row [0, 0, 0, 1] or "
                             f"a pair (position (3,), rotation (3, 3)), got shape {T.shape}")
        p, R = T[:3, 3], T[:3, :3]
    p = np.array(p, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"{name}: the position must be 3 finite numbers, got shape {p.shape}")
    return p, _rotation_matrix(f"{name} (rotation)", R)


def _pose_error(T: np.ndarray, p_d: np.ndarray, R_d: np.ndarray) -> np.ndarray:
    """``e = [p_d - p; log(R_d R^T)]`` (6,), world axes, of a frame at ``T = [[R, p], [0, 1]]``
    (module docstring)."""
    return np.concatenate([p_d - T[:3, 3], rotation_vector(R_d @ T[:3, :3].T)])


class CartesianImpedance(Controller):
    """Impedance control of a link or frame ``body`` about a desired pose (module docstring),
    with or without inertia shaping.

    Without ``inertia`` (Siciliano et al. (2009), section 9.3, without force measurement):
    ``tau = J^T (K e - D J v) - D_q v + g(q)``; the apparent inertia of the frame is the arm's.

    With ``inertia=M_d`` and ``force`` (Hogan 1985; Siciliano et al. (2009), section 9.3, with
    force measurement): ``M_d x~'' + D x~' + K x~ = h_e`` exactly with an exact model
    (``x~ = -e`` the displacement, ``h_e`` the measured external wrench), through the
    task-space dynamics ``Lambda, mu, p, Jbar`` of :func:`robodyn.task_space_dynamics`:
    ``tau = J^T (Lambda M_d^-1 (K e - D J v + h_e) + mu + p - h_e) + (1 - J^T Jbar^T)
    (-D_q v + g(q))``. Under a constant ``h_e`` it settles at ``K e = -h_e`` as without shaping.

    Args:
        body: a link or frame name of ``model``.
        position: (3,) desired origin in the world frame.
        orientation: (3, 3) desired rotation in the world frame, or None to leave it free.
        stiffness, damping: the spring's ``K`` and ``D``: numbers or (3,) for the position,
            and (with an orientation) (6,) vectors ``[linear; angular]`` or pairs
            ``(linear, angular)``.
        joint_damping: ``D_q``, > 0 (numbers or (nv,)); with ``inertia``, projected into the
            null space of the task (the self-motion of a redundant arm).
        inertia: the desired apparent inertia ``M_d`` (kg, and kg m^2 for the angular rows),
            > 0, given as the gains; None (default): no inertia shaping.
        force: with ``inertia``, the force sensor: a callable ``(t, q, v) -> h_e`` (3,) (the
            force on the frame) or, with an orientation, (6,) ``[f; n]`` (the torque about
            the frame's origin), world axes, as :class:`Admittance`'s ``force``.
    """

    def __init__(self, model, body: str, position, orientation=None, *, stiffness, damping, joint_damping=1.0,
                 inertia=None, force=None):
        super().__init__(model)
        self.body = body
        model.frame_index(body)  # raises for an unknown name
        self.x_d = np.array(position, dtype=float)
        if self.x_d.shape != (3,) or not np.all(np.isfinite(self.x_d)):
            raise ValueError(f"position: expected 3 finite numbers, got shape {self.x_d.shape}")
        self.R_d = None if orientation is None else _rotation_matrix("orientation", orientation)
        m = 3 if self.R_d is None else 6
        self.rows = "linear" if m == 3 else "all"
        self.K, self.D = self._gains("stiffness", stiffness, m), self._gains("damping", damping, m)
        self.joint_damping = gain("joint_damping", joint_damping, model.nv)
        if inertia is None:
            if force is not None:
                raise ValueError("force: the measured wrench is used by inertia shaping only; give inertia= too "
                                 "(or leave force out)")
            self.M_d = None
        else:
            self.M_d = self._gains("inertia", inertia, m)
            if not callable(force):
                raise ValueError(f"force: inertia shaping needs the measured external wrench, a callable "
                                 f"(t, q, v) -> h_e ({m},), got {type(force).__name__}")
        self.force = force

    @staticmethod
    def _gains(name, value, m):
        if m == 6 and isinstance(value, tuple) and len(value) == 2:
            value = np.concatenate([np.broadcast_to(np.asarray(v, dtype=float), (3,)) for v in value])
        return gain(name, value, m)

    def error(self, q) -> np.ndarray:
        """``e = [x_d - x; log(R_d R^T)]`` (3 or 6,) in world axes."""
        T = frame_pose(self.model, q, self.body)
        return self.x_d - T[:3, 3] if self.R_d is None else _pose_error(T, self.x_d, self.R_d)

    def __call__(self, t, q, v):
        if self.M_d is None:
            J = jacobian(self.model, q, self.body, "local_world_aligned")[:self.K.shape[0]]
            f = self.K * self.error(q) - self.D * (J @ v)
            return J.T @ f - self.joint_damping * v + gravity(self.model, q)
        m = self.K.shape[0]
        h = np.asarray(self.force(t, q, v), dtype=float)
        if h.shape != (m,):
            raise ValueError(f"force: the sensor returned shape {h.shape}, expected ({m},)")
        T = task_space_dynamics(self.model, q, v, self.body, "local_world_aligned", self.rows)
        a = (self.K * self.error(q) - self.D * (T.J @ v) + h) / self.M_d
        F = T.Lambda @ a + T.mu + T.p - h
        tau0 = gravity(self.model, q) - self.joint_damping * v
        return T.J.T @ F + tau0 - T.J.T @ (T.Jbar.T @ tau0)


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
    """Khatib's operational-space control of a frame's position and orientation with a
    posture in the null space (Khatib 1987; Siciliano et al. (2009), section 8.6, inverse
    dynamics control in the operational space):

        F = Lambda (x_d'' + Kd (x_d' - J v) + Kp e) + mu + p
        tau = J^T F + (1 - J^T Jbar^T) (Kp_n (q_p - q) - Kd_n v + g(q))

    with ``Lambda, mu, p, Jbar, J`` of :func:`robodyn.task_space_dynamics` for the task rows
    ``rows`` of the frame's velocity ``[p'; w]`` (world axes, ``"local_world_aligned"``) and
    ``e`` those rows of the pose error ``[p_d - p; log(R_d R^T)]`` (module docstring). With an
    exact model the position rows obey ``e'' + Kd e' + Kp e = 0`` and the angular rows
    ``dw' + Kd dw + Kp log(R_d R^T) = 0`` (``dw = w_d - w``) whatever the posture does, and
    the posture torques never disturb the task.

    Args:
        body: the link or frame.
        target: the task's reference. Position rows only (indices 0-2, as the default
            ``"linear"``): a fixed (m,) position (the selected coordinates of the origin,
            world frame) or a callable ``t -> (x_d, x_d', x_d'')``, each (m,).
            With angular rows (3-5: ``"angular"``, ``"all"``, ``[0, 1, 5]``, ...): a fixed pose,
            a (4, 4) homogeneous matrix ``[[R_d, p_d], [0, 1]]`` or a pair ``(p_d (3,), R_d
            (3, 3))``, world frame; or a callable ``t -> (pose_d, twist_d, twist_d')`` with
            ``pose_d`` as the fixed pose and ``twist_d = [p_d'; w_d]`` (6,) the origin's
            velocity and the angular velocity in world axes (``R_d' = [w_d]x R_d``),
            ``twist_d'`` (6,) their derivatives, always all six rows (``rows`` selects).
        kp, kd: task gains (numbers or (m,), 1/s^2 and 1/s).
        posture: (nv,) and posture_kp, posture_kd: the null-space PD.
        rows: ``"linear"`` (default), ``"angular"``, ``"all"`` or distinct row indices 0-5
            of ``[vx, vy, vz, wx, wy, wz]``, as in :func:`robodyn.task_space_dynamics`.
    """

    def __init__(self, model, body: str, target, kp, kd, *, posture=None, posture_kp=10.0, posture_kd=2.0,
                 rows="linear"):
        super().__init__(model)
        model.frame_index(body)
        self.body = body
        self.index = task_rows(rows)[0]
        #: True when the task has angular rows: the target is then a pose and twists.
        self.angular = bool(np.any(self.index > 2))
        m = self.index.size
        if callable(target):
            self._reference(*target(0.0))  # its shapes, once
        elif self.angular:
            p, R = _pose("target", target)
            T, zero = np.eye(4), np.zeros(6)
            T[:3, :3], T[:3, 3] = R, p
            target = lambda t: (T, zero, zero)  # noqa: E731
        else:
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

    def _reference(self, x_d, xd_d, xdd_d):
        """``(x_d, x_d', x_d'')`` checked, the rates reduced to the task rows; ``x_d`` is
        ``(p_d, R_d)`` with angular rows, else (m,)."""
        n = 6 if self.angular else self.index.size
        xd_d, xdd_d = np.asarray(xd_d, dtype=float), np.asarray(xdd_d, dtype=float)
        names = ("twist_d", "twist_d'") if self.angular else ("x_d'", "x_d''")
        for name, y in zip(names, (xd_d, xdd_d)):
            if y.shape != (n,):
                what = " ([p'; w] in world axes, all six rows)" if self.angular else ""
                raise ValueError(f"target: {name} has shape {y.shape}, expected ({n},){what}")
        if self.angular:
            return _pose("target: pose_d", x_d), xd_d[self.index], xdd_d[self.index]
        x_d = np.asarray(x_d, dtype=float)
        if x_d.shape != (n,):
            raise ValueError(f"target: x_d has shape {x_d.shape}, expected ({n},) (the position rows "
                             f"{self.index.tolist()})")
        return x_d, xd_d, xdd_d

    def _error(self, q, x_d) -> np.ndarray:
        if self.angular:
            return _pose_error(frame_pose(self.model, q, self.body), *x_d)[self.index]
        return x_d - self.position(q)

    def error(self, t, q) -> np.ndarray:
        """The task rows (m,) of the pose error ``e = [p_d - p; log(R_d R^T)]`` (world axes)
        from the target at time ``t`` (``x_d - x`` for position rows)."""
        return self._error(q, self._reference(*self.target(t))[0])

    def position(self, q) -> np.ndarray:
        """The selected rows of the frame's origin (world), for position rows only (0-2);
        with angular rows use :meth:`error` or :func:`robodyn.frame_pose`."""
        if self.angular:
            raise ValueError(f"position: the task rows {self.index.tolist()} include angular ones; use "
                             "error(t, q) or robodyn.frame_pose")
        return frame_pose(self.model, q, self.body)[:3, 3][self.index]

    def __call__(self, t, q, v):
        return self.law(q, v, *self.target(t))

    def law(self, q, v, x_d, xd_d, xdd_d, force=0.0):
        """The joint torques for the task reference ``(x_d, x_d', x_d'')`` (the target's form),
        compensating a known external force ``force`` (m,) on the frame."""
        T = task_space_dynamics(self.model, q, v, self.body, "local_world_aligned", self.index)
        x_d, xd_d, xdd_d = self._reference(x_d, xd_d, xdd_d)
        e, ed = self._error(q, x_d), xd_d - T.J @ v
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
    ``force``: a callable ``(t, q, v) -> f`` (m,), the force sensor's reading. Position rows
    (0-2) only: a virtual mass-spring-damper in orientation would need one on SO(3).
    """

    def __init__(self, model, body: str, rest, force, *, mass, damping, stiffness, kp, kd, **options):
        rows = options.get("rows", "linear")
        if np.any(task_rows(rows)[0] > 2):
            raise ValueError(f"Admittance: position rows (0-2) only, got rows {rows!r}")
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

        tau = M J^-1 (x_d'' - Jdot v + Kd (x_d' - J v) + Kp e) + C v + g

    ``J`` the task rows of the frame's Jacobian in world axes and ``e`` those rows of the pose
    error ``[p_d - p; log(R_d R^T)]`` (module docstring): a 6-dof arm with ``rows="all"``
    controls the full pose, the target then a pose and twists as in
    :class:`OperationalSpace`. The position rows obey ``e'' + Kd e' + Kp e = 0``, the angular
    rows ``dw' + Kd dw + Kp log(R_d R^T) = 0``. For such arms it is :class:`OperationalSpace`
    without a null space (``J^T Lambda = M J^-1``); written here in the book's form."""

    def __init__(self, model, body: str, target, kp, kd, *, rows="linear"):
        super().__init__(model, body, target, kp, kd, rows=rows)
        if self.index.size != model.nv:
            raise ValueError(f"WorkspaceComputedTorque: a non-redundant arm needs as many task rows as joints "
                             f"({model.nv}), got {self.index.size}; use OperationalSpace")

    def law(self, q, v, x_d, xd_d, xdd_d, force=0.0):
        J = jacobian(self.model, q, self.body, "local_world_aligned")[self.index]
        Jdv = jacobian_dot_times_v(self.model, q, v, self.body, "local_world_aligned")[self.index]
        x_d, xd_d, xdd_d = self._reference(x_d, xd_d, xdd_d)
        e, ed = self._error(q, x_d), xd_d - J @ v
        y = np.linalg.solve(J, xdd_d - Jdv + self.kd * ed + self.kp * e)
        return crba(self.model, q) @ y + nonlinear_effects(self.model, q, v) - J.T @ np.broadcast_to(force, (len(y),))
