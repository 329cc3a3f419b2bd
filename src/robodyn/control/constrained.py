"""Hybrid force/position control of a constrained manipulator: the robot moves on the
manifold its environment allows (``phi(q) = 0``, e.g. a tool on a surface or a crank) and
presses on it with a commanded constraint force.

The constrained dynamics (Murray, Li & Sastry, *A Mathematical Introduction to Robotic
Manipulation* (1994), ch. 4, section 5.3; McClamroch & Wang, "Feedback stabilization and
tracking of constrained robots", IEEE TAC 33(5), 1988):

    M(q) a + h(q, v) = tau + J^T lambda,        J a = -Jdot v           (J = dphi/dq (m, nv))

with ``lambda`` the constraint forces (:func:`robodyn.constrained_dynamics`' sign: the force
the environment applies). The control law

    a_r = q_d'' + Kd (q_d' - v) + Kp (q_d - q)                    (joint reference on the manifold)
    a_c = a_r - M^-1 J^T S^-1 (J a_r + Jdot v),   S = J M^-1 J^T  (the consistent part of a_r)
    tau = M a_c + h - J^T lambda_d                 (= rnea(q, v, a_c) - J^T lambda_d)

makes the closed loop ``a = a_c`` and ``lambda = lambda_d`` with an exact model: the
commanded acceleration already satisfies the constraint, so the environment's force is
exactly the one asked for, and the position error obeys ``e'' + Kd e' + Kp e = 0`` along
the manifold (the reference ``q_d`` must lie on it). With a model error the force is off by
the error's share across the constraint (add a force loop on a sensor for that).
"""

from __future__ import annotations

import numpy as np

from ..algorithms.constrained import constraint_jacobian
from ..algorithms.crba import crba
from ..algorithms.rnea import rnea
from .controllers import Tracking, gain


class ConstrainedForcePosition(Tracking):
    """Position along the constraint manifold and force across it (module docstring).

    Args:
        constraints: the environment as robodyn constraints (:class:`robodyn.PointConstraint`,
            :class:`robodyn.DistanceConstraint`, ... or one of them), ``m`` rows in all.
        reference: ``t -> (q_d, q_d', q_d'')`` on the manifold (e.g. from inverse kinematics).
        force: ``lambda_d``: (m,) numbers or a callable ``t -> (m,)``, in the constraints'
            force conventions and order.
        kp, kd: joint gains (numbers or (nv,)).
    """

    def __init__(self, model, constraints, reference, force, kp, kd):
        super().__init__(model, reference)
        self.constraints = tuple(constraints) if isinstance(constraints, (list, tuple)) else (constraints,)
        if not self.constraints:
            raise ValueError("constraints: expected at least one constraint")
        J, _, _ = constraint_jacobian(model, np.zeros(model.nq), np.zeros(model.nv), self.constraints)
        self.m = J.shape[1]
        if not callable(force):
            fixed = np.array(force, dtype=float)
            if fixed.shape not in ((), (self.m,)) or not np.all(np.isfinite(fixed)):
                raise ValueError(f"force: expected {self.m} finite numbers or a callable t -> ({self.m},), "
                                 f"got {force!r}")
            fixed = np.broadcast_to(fixed, (self.m,)).copy()
            force = lambda t: fixed  # noqa: E731
        self.force = force
        self.kp, self.kd = gain("kp", kp, model.nv), gain("kd", kd, model.nv)

    def desired_force(self, t) -> np.ndarray:
        """``lambda_d(t)`` (m,)."""
        f = np.asarray(self.force(t), dtype=float)
        if f.shape != (self.m,):
            raise ValueError(f"force: expected shape ({self.m},) at t = {t}, got {f.shape}")
        return f

    def __call__(self, t, q, v):
        q_d, v_d, a_d = (np.asarray(x, dtype=float) for x in self.reference(t))
        a_r = a_d + self.kd * (v_d - v) + self.kp * (q_d - q)
        J, Jdv, _ = (x[0] for x in constraint_jacobian(self.model, q, v, self.constraints))
        MinvJT = np.linalg.solve(crba(self.model, q), J.T)
        a_c = a_r - MinvJT @ np.linalg.lstsq(J @ MinvJT, J @ a_r + Jdv, rcond=1e-12)[0]
        return rnea(self.model, q, v, a_c) - J.T @ self.desired_force(t)
