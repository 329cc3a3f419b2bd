"""Load (or compile) every kernel ahead of time, for services that must answer at once.

``robodyn.warmup()`` runs each algorithm once on a small model, single state and batch,
fixed and floating base. Compiled code is cached on disk, so after the first process this
only loads it (about a second); the first process ever compiles everything (about a minute).
"""

from __future__ import annotations

import numpy as np


def warmup() -> None:
    """Compile or load every public algorithm's kernels (single and batched calls)."""
    import robodyn as rd
    from robodyn.random import random_model, random_state

    for floating in (False, True):
        model = random_model(3, seed=0, floating_base=floating)
        for size in ((), (2,)):
            q, v, a = random_state(model, np.random.default_rng(0), size)
            rd.rnea(model, q, v, a)
            rd.aba(model, q, v, a)
            rd.crba(model, q)
            rd.coriolis_matrix(model, q, v)
            rd.gravity(model, q)
            rd.nonlinear_effects(model, q, v)
            rd.kinetic_energy(model, q, v)
            rd.potential_energy(model, q)
            rd.center_of_mass(model, q)
            rd.com_jacobian(model, q)
            rd.jacobian(model, q, model.nbodies - 1)
            rd.jacobian_dot_times_v(model, q, v, model.nbodies - 1)
            rd.forward_kinematics(model, q)
            rd.hybrid_dynamics(model, q, v, a, a, np.arange(model.nv) == model.nv - 1)
            rd.inverse_mass_matrix(model, q)
