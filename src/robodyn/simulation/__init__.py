"""Simulation: forward dynamics integrated in time, free or under a controller.

``simulate(model, q0, v0, duration, dt, controller=None, integrator="rk4")`` returns a
:class:`Trajectory`; ``linearize`` gives the ``(A, B)`` of one of its steps;
``read_csv`` reads trajectories back (format in ``trajectory``).
"""

from .simulate import INTEGRATORS, SCIPY_INTEGRATORS, simulate
from ..io.trajectory_csv import coordinate_names, read_csv
from .trajectory import Trajectory
from .linearize import linearize
from .rollout import Rollouts, rollout

__all__ = ["simulate", "rollout", "Rollouts", "linearize", "Trajectory", "read_csv", "coordinate_names", "INTEGRATORS",
           "SCIPY_INTEGRATORS"]
