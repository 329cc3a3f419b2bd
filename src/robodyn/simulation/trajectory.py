"""The result of a simulation, :class:`Trajectory`; its CSV format is that of
:mod:`robodyn.io.trajectory_csv`.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field

import numpy as np

from ..files import atomic_path
from ..io.trajectory_csv import coordinate_names


@dataclass(frozen=True)
class Trajectory:
    """Samples of a simulated motion, one row per time ``t[k] = k dt``.

    ``t`` (N,); ``q`` (N, nq); ``v``, ``a`` (N, nv) velocity and acceleration; ``tau`` (N, nv)
    the joint forces applied (the controller's command after clipping to the effort limits);
    ``kinetic``, ``potential``, ``energy`` (N,) with ``energy = kinetic + potential``
    (kinetic energy includes the rotors' ``armature v^2 / 2``); ``lyapunov`` (N,) the
    controller's Lyapunov function or None; ``q_desired``, ``v_desired`` (N, nq) / (N, nv)
    the controller's reference or None; ``controller_state`` (N, nz) the internal state of a
    controller that has one (see :func:`robodyn.simulate`), else None.

    With contacts: ``contact_names`` the pairs ``"<shape>@<surface>"``, ``contact_normal``
    (N, npairs, 3) the surface's outward normal at each pair's nearest point and
    ``contact_friction`` (npairs,) its ``mu``; ``contact_force``
    (N, npairs, 3) the force each pair's surface applies to the robot (world axes, N; zero
    when apart), over the step that starts at the sample; ``contact_distance`` (N, npairs)
    the signed distance (m, negative: penetration); ``solver_iterations`` (N,) and
    ``solver_residual`` (N,) (m/s) of the contact solve. With bilateral constraints:
    ``constraint_force`` (N, m) their forces stacked in the order given (see
    :func:`robodyn.constrained_dynamics`).
    """

    model: object = field(repr=False)
    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    energy: np.ndarray
    lyapunov: np.ndarray | None = None
    q_desired: np.ndarray | None = None
    v_desired: np.ndarray | None = None
    controller_state: np.ndarray | None = None
    integrator: str = "rk4"
    contact_names: tuple | None = None
    contact_normal: np.ndarray | None = None
    contact_friction: np.ndarray | None = None
    contact_force: np.ndarray | None = None
    contact_distance: np.ndarray | None = None
    solver_iterations: np.ndarray | None = None
    solver_residual: np.ndarray | None = None
    constraint_force: np.ndarray | None = None

    @property
    def normal_force(self) -> np.ndarray | None:
        """``(N, npairs)`` the normal component of each pair's contact force (N), or None."""
        return None if self.contact_force is None else np.einsum("kpi,kpi->kp", self.contact_force,
                                                                     self.contact_normal)

    @property
    def friction_force(self) -> np.ndarray | None:
        """``(N, npairs)`` the magnitude of each pair's tangential (friction) force (N), or None."""
        if self.contact_force is None:
            return None
        tangential = self.contact_force - self.normal_force[..., None] * self.contact_normal
        return np.linalg.norm(tangential, axis=-1)

    @property
    def tracking_error(self) -> np.ndarray | None:
        """``q - q_desired`` (N, nq) (1-dof joints), or None without a reference."""
        return None if self.q_desired is None else self.q - self.q_desired

    def to_csv(self, path) -> None:
        """Write the samples in the CSV format of the module docstring."""
        qn, vn = coordinate_names(self.model)
        header = (["t"] + [f"q:{n}" for n in qn] + [f"v:{n}" for n in vn] + [f"a:{n}" for n in vn]
                  + [f"tau:{n}" for n in vn] + ["energy"] + (["lyapunov"] if self.lyapunov is not None else []))
        cols = [self.t[:, None], self.q, self.v, self.a, self.tau, self.energy[:, None]]
        if self.lyapunov is not None:
            cols.append(self.lyapunov[:, None])
        with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(np.hstack(cols).tolist())
