"""Model-based joint controllers: callables ``(t, q, v) -> tau`` for :func:`robodyn.simulate`.

Every controller holds its own model (the plant may be another one: model mismatch) and
exposes ``lyapunov(t, q, v)`` when the theory gives a Lyapunov function of the closed loop
with an exact model, and ``desired(t) -> (q_d, v_d, a_d)`` when it tracks a reference.
Errors are ``e = q_d - q``, ``ed = v_d - v`` (except Slotine-Li, written as in its paper
with ``q~ = q - q_d``). Gains are scalars or (nv,) vectors (diagonal gain matrices), > 0.

=================== ======================================================== ===================================
controller          law                                                      Lyapunov function
=================== ======================================================== ===================================
PDGravity           ``Kp e - Kd v + g(q)``                                   ``v^T M v / 2 + e^T Kp e / 2``
PIDGravity          ``Kp e + Ki int(e) - Kd v + g(q)``                       (none reported)
ComputedTorque      ``M (a_d + Kd ed + Kp e) + C v + g (+ friction)``        ``ed^T ed / 2 + e^T Kp e / 2``
TaskSpacePD         ``J^T (Kp (x_d - x) - Kd J v) - D v + g(q)``             ``v^T M v / 2 + ex^T Kp ex / 2``
SlotineLi           ``M a_r + C v_r + g (+ friction) - Kd s``                ``s^T M s / 2 + q~^T Lambda Kd q~``
AdaptiveSlotineLi   ``Y(q, v, v_r, a_r) theta_hat - Kd s``,                  ``s^T M s / 2 + q~^T Lambda Kd q~``
                    ``theta_hat' = -Gamma^-1 Y^T s``                         ``+ theta~^T Gamma theta~ / 2``
JointPD             ``tau_ff + Kp e - Kd v`` on the actuated joints of any   (none reported)
                    robot (a floating base unactuated)
=================== ======================================================== ===================================

References: Spong, Hutchinson, Vidyasagar, *Robot Modeling and Control* (2006), chapter 8
(PD with gravity compensation, inverse dynamics control, passivity-based control);
Takegaki and Arimoto (1981); Slotine and Li, "On the adaptive control of robot
manipulators", IJRR 6(3), 1987; Siciliano et al., *Robotics* (2009), section 8.6 (task-space PD).
"""

from __future__ import annotations

import numpy as np

from .._deprecated import renamed_attribute, renamed_keyword, renamed_keywords
from .. import joints as J
from ..coupling import is_coupled, joint_tree
from ..algorithms.status import raise_for_status
from ..algorithms.coriolis import coriolis_matrix
from ..algorithms.crba import crba
from ..algorithms.regressor import extended_parameters, kinetic_energy_regressor, slotine_li_regressor
from ..algorithms.rnea import rnea
from ..algorithms.terms import gravity
from . import laws
from .references import PointToPoint, Sampled


def gain(name: str, value, n: int) -> np.ndarray:
    """A diagonal gain as an (n,) vector of positive numbers (from a scalar or a vector)."""
    try:
        g = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a positive number or shape ({n},), got {np.shape(value)}") from None
    if not np.all(np.isfinite(g)) or np.any(g <= 0):
        raise ValueError(f"{name}: gains must be finite and > 0, got {g.tolist()}")
    return g


class Controller:
    """A control law ``tau = controller(t, q, v)`` computed with ``model`` (fixed base).

    A controller with an internal state ``z`` (integral action, parameter estimates of an
    adaptive law) sets ``state0`` (nz,) and defines ``torque(t, q, v, z)`` and
    ``state_rate(t, q, v, z) -> z'``; :func:`robodyn.simulate` integrates ``z`` with the
    robot (and passes it to ``lyapunov(t, q, v, z)``). See :class:`PIDGravity`.
    """

    #: ``lyapunov(t, q, v) -> float`` where theory gives one, else None.
    lyapunov = None
    #: ``desired(t) -> (q_d, qd_d, qdd_d)`` (each (nv,)) for a joint-space reference, else None.
    desired = None
    #: Initial internal state (nz,) of a controller that has one, else None.
    state0 = None
    #: True when ``lyapunov(t, q, v)`` and ``desired(t)`` also take a whole trajectory:
    #: ``t`` (N,), ``q``, ``v`` (N, nv) (evaluated at once after a simulation).
    vectorized = False

    def __init__(self, model):
        if model.nq != model.nv:
            raise ValueError(f"{type(self).__name__}: joint-space control needs a fixed-base model "
                             f"(nq == nv), got nq={model.nq}, nv={model.nv}")
        self.model = model

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        raise NotImplementedError(f"{type(self).__name__} does not define its control law")

    def kernel_law(self):
        """``(law code, gains (2, nv), breaks, coefs)`` when :func:`robodyn.simulate` can run
        this controller in compiled code (``laws.law_torque``), else None."""
        return None


def _reference(model, reference):
    if not callable(reference):
        raise ValueError(f"reference: expected a callable t -> (q_d, qd_d, qdd_d), got {type(reference).__name__}")
    q, v, a = (np.asarray(x, dtype=float) for x in reference(0.0))
    for name, x in (("q_d", q), ("qd_d", v), ("qdd_d", a)):
        if x.shape != (model.nv,):
            raise ValueError(f"reference: {name} has shape {x.shape}, expected ({model.nv},)")
    return reference


class Tracking(Controller):
    """A controller that tracks a joint reference ``t -> (q_d, qd_d, qdd_d)``."""

    def __init__(self, model, reference):
        super().__init__(model)
        self.reference = _reference(model, reference)

    def desired(self, t):
        return self.reference(t)

    @property
    def vectorized(self):
        return isinstance(self.reference, (PointToPoint, Sampled))


class PDGravity(Controller):
    """PD control with gravity compensation to a set point ``q_desired``:
    ``tau = Kp (q_d - q) - Kd v + g(q)``. With the exact gravity the set point is globally
    asymptotically stable: ``V = v^T M v / 2 + e^T Kp e / 2`` has ``dV/dt = -v^T Kd v``
    (minus the friction power). Spong et al. (2006), section 8.4."""

    def __init__(self, model, q_desired, kp, kd):
        super().__init__(model)
        self.q_d = np.array(q_desired, dtype=float)
        if self.q_d.shape != (model.nv,) or not np.all(np.isfinite(self.q_d)):
            raise ValueError(f"q_desired: expected ({model.nv},) finite numbers, got shape {self.q_d.shape}")
        self.kp, self.kd = gain("kp", kp, model.nv), gain("kd", kd, model.nv)
        self._zero = np.zeros(model.nv)

    def __call__(self, t, q, v):
        return self.kp * (self.q_d - q) - self.kd * v + gravity(self.model, q)

    def desired(self, t):
        if np.ndim(t):
            shape = (np.shape(t)[0], self.model.nv)
            return np.broadcast_to(self.q_d, shape).copy(), np.zeros(shape), np.zeros(shape)
        return self.q_d, self._zero, self._zero

    def kernel_law(self):
        if type(self).__call__ is not PDGravity.__call__:
            return None
        return laws.PD_GRAVITY, np.stack([self.kp, self.kd]), np.array([0.0, 1.0]), self.q_d.reshape(1, 1, -1).copy()

    vectorized = True

    def lyapunov(self, t, q, v):
        e = self.q_d - q
        return 0.5 * np.einsum("...i,...ij,...j->...", v, crba(self.model, q), v) + 0.5 * np.sum(self.kp * e * e, -1)


class JointPD(Controller):
    """Joint-space PD about a fixed posture with a constant feed-forward, for any robot,
    floating bases included: ``tau_j = tau_ff_j + Kp_j (q_d,j - q_j) - Kd_j v_j`` on every
    actuated joint, and zero on the free joint of a floating base (unactuated: a legged
    robot stands through its contacts). The standing and posture controller of legged
    robots; no gravity compensation (on a floating base it needs the contact forces).

    ``q_desired``: a configuration (nq,) or the actuated joints' positions (na,);
    ``kp``, ``kd``: scalars or (na,); ``tau_ff``: None or (na,). Every joint other than a
    root free joint must have one dof."""

    def __init__(self, model, q_desired, kp, kd, tau_ff=None):
        self.model = model
        tree = joint_tree(model)  # with mimic joints: the tree's joints, then the independent ones
        free = [i for i in range(tree.nbodies) if tree.joint_type[i] == J.FREE]
        if any(tree.parent[i] >= 0 for i in free) or any(J.NV[tree.joint_type[i]] != 1 for i in
                                                          range(tree.nbodies) if tree.joint_type[i] != J.FREE):
            raise ValueError("JointPD: every joint but a root free joint must have one dof (revolute, prismatic, "
                             "helical)")
        base = {k for i in free for k in range(tree.idx_v[i], tree.idx_v[i] + 6)}
        dofs = model.independent_v if is_coupled(model) else np.arange(tree.nv)
        coords = model.independent_q if is_coupled(model) else np.arange(tree.nq)
        self.actuated = np.array([c for c, k in enumerate(dofs) if k not in base], dtype=np.int64)
        na = self.actuated.shape[0]
        dof_body = np.empty(tree.nv, dtype=np.int64)
        for i in range(tree.nbodies):
            dof_body[tree.idx_v[i]:tree.idx_v[i] + J.NV[tree.joint_type[i]]] = i
        self.q_index = np.searchsorted(coords, [tree.idx_q[dof_body[dofs[c]]] for c in self.actuated]).astype(np.int64)
        qd = np.array(q_desired, dtype=float)
        if qd.shape == (model.nq,):
            qd = qd[self.q_index]
        if qd.shape != (na,) or not np.all(np.isfinite(qd)):
            raise ValueError(f"q_desired: expected ({model.nq},) or ({na},) finite numbers, got shape {qd.shape}")
        self.q_d = qd
        self.kp, self.kd = gain("kp", kp, na), gain("kd", kd, na)
        ff = np.zeros(na) if tau_ff is None else np.array(tau_ff, dtype=float)
        if ff.shape != (na,) or not np.all(np.isfinite(ff)):
            raise ValueError(f"tau_ff: expected ({na},) finite numbers, got shape {ff.shape}")
        self.tau_ff = ff
        self._table = np.zeros((5, model.nv))
        for row, x in enumerate((self.kp, self.kd, self.q_index, self.q_d, self.tau_ff)):
            self._table[row, self.actuated] = x

    def __call__(self, t, q, v):
        tau = np.zeros(self.model.nv)
        tau[self.actuated] = self.tau_ff + self.kp * (self.q_d - q[self.q_index]) - self.kd * v[self.actuated]
        return tau

    def kernel_law(self):
        if type(self).__call__ is not JointPD.__call__:
            return None
        return laws.JOINT_PD, self._table, np.array([0.0, 1.0]), np.zeros((1, 1, self.model.nv))


class PIDGravity(PDGravity):
    """PID control with gravity compensation to a set point, with the integral of the error
    as internal state ``z`` (``z' = q_d - q``, ``z(0) = 0``)::

        tau = Kp e + Ki z - Kd qd + g(q)

    The integral action removes the steady-state error left by a wrong gravity model or a
    constant disturbance. Its stability needs conditions on the gains (Kelly, "Global
    positioning of robot manipulators via PD control plus a class of nonlinear integral
    actions", IEEE TAC 43(7), 1998); no Lyapunov function is reported. Called as
    ``controller(t, q, v)`` outside a simulation it uses ``z = 0``.
    """

    lyapunov = None
    vectorized = False

    def __init__(self, model, q_desired, kp, ki, kd):
        super().__init__(model, q_desired, kp, kd)
        self.ki = gain("ki", ki, model.nv)
        self.state0 = np.zeros(model.nv)

    def torque(self, t, q, v, z):
        return PDGravity.__call__(self, t, q, v) + self.ki * z

    def state_rate(self, t, q, v, z):
        return self.q_d - q

    def __call__(self, t, q, v):
        return self.torque(t, q, v, self.state0)


class ComputedTorque(Tracking):
    """Inverse-dynamics (computed-torque) control on a reference ``t -> (q_d, qd_d, qdd_d)``:
    ``tau = rnea(q, qd, qdd_d + Kd ed + Kp e)`` (the model's friction and armature
    included). With the exact model the error obeys ``e'' + Kd e' + Kp e = 0``: each joint
    converges exponentially (``Kp = w^2, Kd = 2 w``: critically damped at rate ``w``), and
    ``V = ed^T ed / 2 + e^T Kp e / 2`` has ``dV/dt = -ed^T Kd ed``. Spong et al., section 8.3."""

    def __init__(self, model, reference, kp, kd):
        super().__init__(model, reference)
        self.kp, self.kd = gain("kp", kp, model.nv), gain("kd", kd, model.nv)

    def __call__(self, t, q, v):
        q_d, v_d, a_d = self.reference(t)
        return rnea(self.model, q, v, a_d + self.kd * (v_d - v) + self.kp * (q_d - q))

    def kernel_law(self):
        piecewise = getattr(self.reference, "piecewise_polynomial", None)
        if type(self).__call__ is not ComputedTorque.__call__ or piecewise is None:
            return None
        breaks, coefs = piecewise()
        return laws.COMPUTED_TORQUE, np.stack([self.kp, self.kd]), breaks, coefs

    def lyapunov(self, t, q, v):
        q_d, v_d, _ = self.reference(t)
        e, ed = q_d - q, v_d - v
        return 0.5 * np.sum(ed * ed, -1) + 0.5 * np.sum(self.kp * e * e, -1)


class TaskSpacePD(Controller):
    """PD control of the position of a link or frame ``body`` to ``x_desired`` (world, (3,)),
    with gravity compensation and joint damping ``D`` (for the redundant directions):
    ``tau = J^T (Kp (x_d - x) - Kd J v) - D v + g(q)``, ``J`` the (3, nv) linear Jacobian
    of the body's origin in world axes. ``V = v^T M v / 2 + ex^T Kp ex / 2`` has
    ``dV/dt = -(J v)^T Kd (J v) - v^T D v``. Siciliano et al. (2009), section 8.6.1."""

    frame = renamed_attribute("frame", "body")

    def __init__(self, model, body: str | None = None, x_desired=None, kp=None, kd=None, joint_damping=1.0, *,
                 frame=None):
        if frame is not None:  # the old spelling of ``body`` (``frame`` is the frame vectors are expressed in)
            body = renamed_keyword("frame", frame, "body", body, "TaskSpacePD()", default=None)
        missing = [k for k, x in (("body", body), ("x_desired", x_desired), ("kp", kp), ("kd", kd)) if x is None]
        if missing:
            raise TypeError(f"TaskSpacePD() missing arguments {missing}")
        super().__init__(model)
        b, self._R, self._p = model.frame_index(body)
        if b < 0:
            raise ValueError(f"frame {body!r} is fixed to the world; it cannot be moved")
        self.body, self._body = body, b
        self.x_d = np.array(x_desired, dtype=float)
        if self.x_d.shape != (3,) or not np.all(np.isfinite(self.x_d)):
            raise ValueError(f"x_desired: expected 3 finite numbers, got shape {self.x_d.shape}")
        self.kp, self.kd = gain("kp", kp, 3), gain("kd", kd, 3)
        self.damping = gain("joint_damping", joint_damping, model.nv)

    def position_and_jacobian(self, q):
        """World position (3,) of the body's origin and its linear Jacobian (3, nv) in world
        axes (the rows ``[:3]`` of ``jacobian(model, q, body, "local_world_aligned")``)."""
        k = self.model.kernel
        q = np.ascontiguousarray(q, dtype=float)
        J, R, p = np.empty((6, self.model.nv)), np.empty((3, 3)), np.empty(3)
        status = laws.body_jacobian(k.ints, k.body, k.dofs[False, False], q, self._body, J, R, p)
        raise_for_status(self.model, status, {"q": q}, "TaskSpacePD")
        x = p + R @ self._p
        x_cross = np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])
        return x, J[:3] - x_cross @ J[3:]  # velocity of the point x: v_O + omega x x

    def position(self, q):
        """World position (3,) of the controlled frame."""
        return self.position_and_jacobian(q)[0]

    def __call__(self, t, q, v):
        x, Jl = self.position_and_jacobian(q)
        f = self.kp * (self.x_d - x) - self.kd * (Jl @ v)
        return Jl.T @ f - self.damping * v + gravity(self.model, q)

    def lyapunov(self, t, q, v):
        ex = self.x_d - self.position(q)
        return 0.5 * v @ crba(self.model, q) @ v + 0.5 * ex @ (self.kp * ex)


class SlotineLi(Tracking):
    """Passivity-based tracking control (Slotine and Li, 1987) on a reference.

    With ``q~ = q - q_d``, the reference velocity ``qd_r = qd_d - Lambda q~``, its derivative
    ``qdd_r = qdd_d - Lambda (qd - qd_d)`` and the sliding variable ``s = qd - qd_r``::

        tau = M(q) qdd_r + C(q, qd) qd_r + g(q) (+ friction) - Kd s

    (:meth:`feedforward` computes the model terms as ``rnea(q, qd, qdd_r) - C(q, qd) s``.)
    The closed loop ``M s' + (C + Kd) s = 0`` uses the skew-symmetry of ``Mdot - 2C``:
    ``V = s^T M s / 2 + q~^T Lambda Kd q~`` has ``dV/dt = -q~'^T Kd q~' - q~^T Lambda Kd Lambda q~``.
    The adaptive version, :class:`AdaptiveSlotineLi`, replaces :meth:`feedforward` by
    ``Y(q, qd, qd_r, qdd_r) theta_hat``.
    Spong et al. (2006), section 8.5.
    """

    def __init__(self, model, reference, lam, kd):
        super().__init__(model, reference)
        self.lam, self.kd = gain("lam", lam, model.nv), gain("kd", kd, model.nv)

    def sliding(self, t, q, v):
        """``(q~, qd_r, qdd_r, s)`` at time ``t``."""
        q_d, v_d, a_d = self.reference(t)
        e = q - q_d
        v_r = v_d - self.lam * e
        a_r = a_d - self.lam * (v - v_d)
        return e, v_r, a_r, v - v_r

    def feedforward(self, q, v, v_r, a_r):
        """``M(q) qdd_r + C(q, qd) qd_r + g(q) + friction(qd)`` of the controller's model."""
        return rnea(self.model, q, v, a_r) - coriolis_matrix(self.model, q, v) @ (v - v_r)

    def __call__(self, t, q, v):
        _, v_r, a_r, s = self.sliding(t, q, v)
        return self.feedforward(q, v, v_r, a_r) - self.kd * s

    def lyapunov(self, t, q, v):
        e, _, _, s = self.sliding(t, q, v)
        return 0.5 * np.einsum("...i,...ij,...j->...", s, crba(self.model, q), s) + np.sum(self.lam * self.kd * e * e, -1)


def _gain_matrix(name: str, value, n: int) -> np.ndarray:
    """A symmetric positive-definite (n, n) gain matrix from a scalar, an (n,) diagonal or an
    (n, n) matrix."""
    if np.ndim(value) < 2:
        return np.diag(gain(name, value, n))
    G = np.asarray(value, dtype=float)
    if G.shape != (n, n):
        raise ValueError(f"{name}: expected a positive number, shape ({n},) or ({n}, {n}), got {G.shape}")
    if not np.all(np.isfinite(G)) or not np.allclose(G, G.T, rtol=1e-12, atol=0.0):
        raise ValueError(f"{name}: the matrix must be finite and symmetric")
    try:
        np.linalg.cholesky(G)
    except np.linalg.LinAlgError:
        raise ValueError(f"{name}: the matrix must be positive definite") from None
    return G


class AdaptiveSlotineLi(SlotineLi):
    """Adaptive Slotine-Li control (Slotine and Li, 1987): :class:`SlotineLi` with the model
    terms computed from estimated parameters ``theta_hat``, the controller's internal state::

        tau = Y(q, qd, qd_r, qdd_r) theta_hat - Kd s,      theta_hat' = -Gamma^-1 Y^T s

    with ``Y`` the :func:`robodyn.slotine_li_regressor` of the controller's model (only its
    kinematics is used: joints, placements, gravity) and ``q~``, ``qd_r``, ``qdd_r``, ``s``
    as in :class:`SlotineLi`. ``theta_hat`` (10 per body, order of
    ``Model.inertial_parameters()``, then the optional ``damping``, ``coulomb`` and
    ``armature`` blocks of ``nv`` each, see :func:`robodyn.algorithms.regressor.extended_parameters`)
    starts at ``theta0`` (default: the controller model's own parameters).

    If the plant is exactly ``Y theta`` for some ``theta`` (its friction and armature modelled
    by the chosen columns, torques not saturated), the closed loop is
    ``M s' + (C + Kd) s = Y theta~`` (``theta~ = theta_hat - theta``) and, with the
    skew-symmetry of ``Mdot - 2C``,

        V = s^T M s / 2 + q~^T Lambda Kd q~ + theta~^T Gamma theta~ / 2,
        dV/dt = -q~'^T Kd q~' - q~^T Lambda Kd Lambda q~ <= 0

    so ``q~ -> 0`` and ``q~' -> 0`` (Barbalat's lemma) for any bounded reference with bounded
    derivatives. The estimates stay bounded but converge to ``theta`` only under persistent
    excitation. ``V`` needs the plant's true ``theta``: pass ``theta_true`` (an array, or the
    plant's ``Model``, whose parameters are taken with the same columns) to get
    ``lyapunov(t, q, v, z)`` (sampled by :func:`robodyn.simulate`), or call
    :meth:`lyapunov_with`. Called as ``controller(t, q, v)`` outside a simulation it uses
    ``theta_hat = theta0``.

    Args:
        lam, kd: ``Lambda`` and ``Kd``, scalars or (nv,) (diagonal), > 0.
        gamma: ``Gamma``, a scalar, an (np,) diagonal or an (np, np) symmetric
            positive-definite matrix (np parameters): the larger, the slower the adaptation.
        theta0: (np,) initial estimate.
        damping, coulomb, armature: also estimate viscous friction (column ``v_k``), Coulomb
            friction (``sgn qd_k``, smoothed as in the controller model) and armature
            (``qdd_r,k``) of each joint.

    References: Slotine and Li, IJRR 6(3), 1987; Spong, Hutchinson and Vidyasagar (2006),
    section 8.5.2; Siciliano et al. (2009), section 8.5.4.
    """

    @renamed_keywords(viscous="damping")
    def __init__(self, model, reference, lam, kd, gamma, theta0=None, *, theta_true=None, damping: bool = False,
                 coulomb: bool = False, armature: bool = False):
        super().__init__(model, reference, lam, kd)
        self.columns = dict(damping=bool(damping), coulomb=bool(coulomb), armature=bool(armature))
        self.state0 = self._parameters("theta0", model if theta0 is None else theta0)
        n = self.state0.shape[0]
        self.gamma = _gain_matrix("gamma", gamma, n)
        diagonal = not np.any(self.gamma - np.diag(np.diag(self.gamma)))
        self._gamma_inv = 1.0 / np.diag(self.gamma) if diagonal else np.linalg.inv(self.gamma)
        self.theta_true = None if theta_true is None else self._parameters("theta_true", theta_true)

    def _parameters(self, name, theta):
        """A parameter vector (np,) from an array or a model with the same joints."""
        if hasattr(theta, "inertial_parameters"):
            if (theta.nq, theta.nv, theta.nbodies) != (self.model.nq, self.model.nv, self.model.nbodies):
                raise ValueError(f"{name}: the model has nq={theta.nq}, nv={theta.nv}, {theta.nbodies} bodies; the "
                                 f"controller's has nq={self.model.nq}, nv={self.model.nv}, "
                                 f"{self.model.nbodies} bodies")
            return extended_parameters(theta, **self.columns)
        n = 10 * self.model.nbodies + self.model.nv * sum(self.columns.values())
        x = np.array(theta, dtype=float)
        if x.shape != (n,) or not np.all(np.isfinite(x)):
            raise ValueError(f"{name}: expected ({n},) finite numbers (10 per body, then {self.model.nv} per "
                             f"extra column block), got shape {x.shape}")
        return x

    def regressor(self, t, q, v):
        """``(Y, s)``: the Slotine-Li regressor (nv, np) at ``(q, qd, qd_r, qdd_r)`` and ``s``."""
        _, v_r, a_r, s = self.sliding(t, q, v)
        return slotine_li_regressor(self.model, q, v, v_r, a_r, **self.columns), s

    def torque(self, t, q, v, z):
        Y, s = self.regressor(t, q, v)
        return Y @ z - self.kd * s

    def state_rate(self, t, q, v, z):
        Y, s = self.regressor(t, q, v)
        g = Y.T @ s
        return -(self._gamma_inv * g if self._gamma_inv.ndim == 1 else self._gamma_inv @ g)

    def __call__(self, t, q, v):
        return self.torque(t, q, v, self.state0)

    def lyapunov_with(self, theta, t, q, v, z):
        """``V = s^T M s / 2 + q~^T Lambda Kd q~ + theta~^T Gamma theta~ / 2`` for the plant
        parameters ``theta`` (np,) (or the plant's ``Model``), ``M`` the plant's mass matrix
        (its armature included when estimated). Also for a trajectory: ``t`` (N,), ``q``,
        ``v`` (N, nv), ``z`` (N, np) give (N,)."""
        theta = self._parameters("theta", theta)
        e, _, _, s = self.sliding(t, q, v)
        nb = 10 * self.model.nbodies
        kinetic = kinetic_energy_regressor(self.model, q, s) @ theta[:nb]
        if self.columns["armature"]:
            arm = theta[nb + self.model.nv * (self.columns["damping"] + self.columns["coulomb"]):][:self.model.nv]
            kinetic = kinetic + 0.5 * np.sum(arm * s * s, -1)
        d = np.asarray(z, dtype=float) - theta
        return kinetic + np.sum(self.lam * self.kd * e * e, -1) + 0.5 * np.einsum("...i,ij,...j->...", d, self.gamma, d)

    @property
    def lyapunov(self):
        """``lyapunov(t, q, v, z)`` with ``theta_true`` (None when it was not given)."""
        if self.theta_true is None:
            return None
        return lambda t, q, v, z: self.lyapunov_with(self.theta_true, t, q, v, z)
