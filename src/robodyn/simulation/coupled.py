"""Simulation of a model with mimic couplings (``robodyn.coupling.CoupledModel``).

The full tree (every joint free) is integrated under one ``CouplingConstraint`` per mimic joint,
``q_m = r q_s + o``, from a state on the coupling (``q = E(q_r)``, ``v = G v_r``), with the
controller's torques on the independent joints and none on the mimic joints. The constrained
accelerations are exactly ``G a_r`` with ``a_r`` the coupled model's forward dynamics, and a
Runge-Kutta method (the fixed-step and SciPy integrators alike) keeps linear invariants such as
``q_m - r q_s - o`` exactly (Hairer, Lubich, Wanner, *Geometric Numerical Integration*, IV.1,
Theorem 1.5): the samples, read in the independent coordinates, are the coupled model's own
integration. The couplings' forces are internal and are not reported.

With contacts the coupled model is stepped itself (:mod:`._coupled_contact_step`: the full
tree's ``h``, ``M`` and contact rows reduced by ``G``), its state kept on the coupling.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..algorithms.constrained import CouplingConstraint
from ..coupling import expand_q, expand_v


class ReducedLaw:
    """A controller of the coupled model seen by the full tree: ``(t, q, v) -> tau`` with ``q``,
    ``v`` of the full tree, the command on the independent dofs and zero on the mimic dofs; its
    state, Lyapunov function and reference mapped the same way."""

    def __init__(self, controller, model):
        self.controller, self.coupled = controller, model  # not ``model``: simulate() checks a controller's model
        self.state0 = getattr(controller, "state0", None)
        for name in ("lyapunov", "desired"):
            if callable(getattr(controller, name, None)):
                setattr(self, name, getattr(self, "_" + name))

    def _pad(self, tau) -> np.ndarray:
        tau = np.asarray(tau, dtype=float)
        if tau.shape != (self.coupled.nv,):
            raise ValueError(f"controller: returned shape {tau.shape}, expected ({self.coupled.nv},)")
        out = np.zeros(self.coupled.full.nv)
        out[self.coupled.independent_v] = tau
        return out

    def _reduced(self, q, v):
        return np.asarray(q)[..., self.coupled.independent_q], np.asarray(v)[..., self.coupled.independent_v]

    def __call__(self, t, q, v):
        return self._pad(self.controller(t, *self._reduced(q, v)))

    def torque(self, t, q, v, z):
        return self._pad(self.controller.torque(t, *self._reduced(q, v), z))

    def state_rate(self, t, q, v, z):
        return self.controller.state_rate(t, *self._reduced(q, v), z)

    def _lyapunov(self, t, q, v, *z):
        return self.controller.lyapunov(t, *self._reduced(q, v), *z)

    def _desired(self, t):
        q_d, v_d, a_d = self.controller.desired(t)
        return expand_q(self.coupled, q_d), expand_v(self.coupled, v_d), expand_v(self.coupled, a_d)


def full_tree_problem(model, q0, v0, controller, constraints: tuple):
    """``(q0, v0, controller, constraints)`` of the full tree: the initial state on the
    coupling, the controller as a :class:`ReducedLaw`, the caller's constraints then one
    ``CouplingConstraint`` per mimic joint."""
    couplings = tuple(CouplingConstraint(source, joint, r, o) for joint, source, r, o in model.mimic)
    law = None if controller is None else ReducedLaw(controller, model)
    return expand_q(model, q0), expand_v(model, v0), law, tuple(constraints) + couplings


def reduced_trajectory(model, traj, user_constraints: bool):
    """The full tree's trajectory read in the coupled model's independent coordinates (the
    forces of the caller's constraints kept; the couplings' columns come last and are dropped)."""
    iq, iv = model.independent_q, model.independent_v
    cf = traj.constraint_force
    return replace(traj, model=model, q=traj.q[:, iq], v=traj.v[:, iv], a=traj.a[:, iv], tau=traj.tau[:, iv],
                   q_desired=None if traj.q_desired is None else traj.q_desired[:, iq],
                   v_desired=None if traj.v_desired is None else traj.v_desired[:, iv],
                   constraint_force=cf[:, :cf.shape[1] - len(model.mimic)] if user_constraints else None,
                   joint_friction=None if traj.joint_friction is None else traj.joint_friction[:, iv])


def run_coupling(model) -> tuple:
    """``(cmap, cscale, independent, independent_q)``: the coupling arguments of the compiled
    runs (``_contact_runs``): :func:`contact_coupling` and the independent coordinates."""
    return (*contact_coupling(model), np.ascontiguousarray(model.independent_q, dtype=np.int64))


def contact_coupling(model) -> tuple:
    """``(cmap, cscale, independent)`` of :mod:`._coupled_contact_step`: ``G[k, cmap[k]] =
    cscale[k]``, the only entry of row ``k`` of ``G`` (the model's ``CouplingTables``), and the
    full dofs of the independent ones."""
    nvf, tables = model.full.nv, model.tables
    return (np.ascontiguousarray(tables.ints[2:2 + nvf]), np.ascontiguousarray(tables.floats[:nvf]),
            np.ascontiguousarray(model.independent_v, dtype=np.int64))
