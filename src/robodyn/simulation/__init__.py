"""Simulation: forward dynamics integrated in time, free or under a controller.

``simulate(model, q0, v0, duration, dt, controller=None, integrator="rk4")`` returns a
:class:`Trajectory`; ``linearize`` gives the ``(A, B)`` of one of its steps;
``Trajectory.to_csv``/``from_csv`` and ``read_trajectory`` write and read trajectories in
robodyn's one tabular format (:mod:`robodyn.io.log`).
"""

from .simulate import INTEGRATORS, SCIPY_INTEGRATORS, SYMPLECTIC, simulate
from ..io.log import coordinate_names, read_csv, read_log, read_trajectory, write_log
from .trajectory import Trajectory
from .linearize import linearize
from .rollout import Rollouts, rollout

__all__ = ["simulate", "rollout", "Rollouts", "linearize", "Trajectory", "read_trajectory", "read_log", "write_log",
           "read_csv", "coordinate_names", "INTEGRATORS", "SCIPY_INTEGRATORS", "SYMPLECTIC"]
