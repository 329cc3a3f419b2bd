"""The result of a simulation, :class:`Trajectory`; written and read in robodyn's one
tabular format (:mod:`robodyn.io.log`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..io.log import read_log, write_log

CONTACT_COLUMNS = (("force", ("fx", "fy", "fz")), ("normal", ("nx", "ny", "nz")), ("distance", ("distance",)))


@dataclass(frozen=True)
class Trajectory:
    """Samples of a simulated motion, one row per time ``t[k] = k dt``.

    ``t`` (N,); ``q`` (N, nq); ``v``, ``a`` (N, nv) velocity and acceleration; ``tau`` (N, nv)
    the joint forces applied (the controller's command after clipping to the effort limits);
    ``kinetic``, ``potential``, ``energy`` (N,) with ``energy = kinetic + potential``
    (kinetic energy includes the rotors' ``armature v^2 / 2``, potential energy the joint
    springs' ``stiffness (q - spring_reference)^2 / 2``); ``lyapunov`` (N,) the
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
    :func:`robodyn.constrained_dynamics`). With ``stiction=True``: ``joint_friction`` (N, nv)
    the joints' dry friction torques over the step that starts at the sample.
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
    joint_friction: np.ndarray | None = None

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
        """Write the samples in robodyn's tabular format (:mod:`robodyn.io.log`; Parquet for a
        ``.parquet`` path): ``t, q:, v:, a:, tau:`` then ``kinetic, potential, energy``, and
        what the run has: ``lyapunov``; ``q_desired:<coordinate>``, ``v_desired:<dof>``;
        ``controller_state:<k>``; per contact pair ``contact:<pair>:fx, :fy, :fz`` (its
        force), ``:nx, :ny, :nz`` (the normal), ``:distance`` and ``:mu``, with
        ``solver_iterations, solver_residual``; ``constraint_force:<k>``;
        ``joint_friction:<dof>``.
        :meth:`from_csv` reads it all back."""
        extra = {"kinetic": self.kinetic, "potential": self.potential, "energy": self.energy}
        if self.lyapunov is not None:
            extra["lyapunov"] = self.lyapunov
        for name, x, names in (("q_desired", self.q_desired, self.model.q_names),
                               ("v_desired", self.v_desired, self.model.dof_names),
                               ("joint_friction", self.joint_friction, self.model.dof_names)):
            if x is not None:
                extra.update({f"{name}:{n}": x[:, k] for k, n in enumerate(names)})
        for name, x in (("controller_state", self.controller_state), ("constraint_force", self.constraint_force)):
            if x is not None:
                extra.update({f"{name}:{k}": x[:, k] for k in range(x.shape[1])})
        if self.contact_names is not None:
            for p, pair in enumerate(self.contact_names):
                for field_, parts in CONTACT_COLUMNS:
                    x = getattr(self, f"contact_{field_}")[:, p]
                    extra.update({f"contact:{pair}:{c}": x if x.ndim == 1 else x[:, k] for k, c in enumerate(parts)})
                extra[f"contact:{pair}:mu"] = np.full(self.t.shape, self.contact_friction[p])
            extra.update(solver_iterations=self.solver_iterations, solver_residual=self.solver_residual)
        write_log(path, self.model, self.t, self.q, v=self.v, a=self.a, tau=self.tau, extra=extra)

    @classmethod
    def from_csv(cls, path, model) -> "Trajectory":
        """The trajectory written by :meth:`to_csv` (or any file of robodyn's tabular format
        with ``t``, ``q``, ``v``, ``a`` and ``tau`` columns: the energies are then computed)."""
        log = read_log(path, model)
        missing = [k for k in ("v", "a", "tau") if getattr(log, k) is None]
        if missing:
            raise ValueError(f"{path}: a trajectory needs the {', '.join(missing)} columns as well as t and q")
        x = dict(log.extra)

        def block(prefix, names):
            cols = [f"{prefix}:{n}" for n in names]
            return np.column_stack([x.pop(c) for c in cols]) if cols and all(c in x for c in cols) else None

        def numbered(prefix):
            count = sum(1 for k in x if k.startswith(prefix + ":") and k[len(prefix) + 1:].isdigit())
            return block(prefix, [str(k) for k in range(count)])

        if not all(k in x for k in ("kinetic", "potential")):
            from ..algorithms.energy import kinetic_energy, potential_energy
            x["kinetic"] = kinetic_energy(model, log.q, log.v) + 0.5 * (log.v * log.v) @ model.armature
            x["potential"] = potential_energy(model, log.q)
        kinetic, potential = x.pop("kinetic"), x.pop("potential")
        x.pop("energy", None)
        fields = dict(lyapunov=x.pop("lyapunov", None), q_desired=block("q_desired", model.q_names),
                      v_desired=block("v_desired", model.dof_names), controller_state=numbered("controller_state"),
                      joint_friction=block("joint_friction", model.dof_names),
                      constraint_force=numbered("constraint_force"))
        pairs = list(dict.fromkeys(k[len("contact:"):].rsplit(":", 1)[0] for k in x if k.startswith("contact:")))
        if pairs:
            contact = {f: np.stack([block(f"contact:{p}", parts) for p in pairs], axis=1) for f, parts in CONTACT_COLUMNS}
            fields.update(contact_names=tuple(pairs), contact_force=contact["force"], contact_normal=contact["normal"],
                          contact_distance=contact["distance"][..., 0],
                          contact_friction=np.array([x.pop(f"contact:{p}:mu")[0] for p in pairs]),
                          solver_iterations=x.pop("solver_iterations", None), solver_residual=x.pop("solver_residual", None))
        return cls(model=model, t=log.t, q=log.q, v=log.v, a=log.a, tau=log.tau, kinetic=kinetic, potential=potential,
                   energy=kinetic + potential, **fields)
