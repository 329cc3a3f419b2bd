"""robodyn: rigid-body robot dynamics for Python.

    import robodyn as rd
    model = rd.models.load("panda")
    tau = rd.rnea(model, q, v, a)        # inverse dynamics
    a = rd.aba(model, q, v, tau)         # forward dynamics
    M = rd.crba(model, q)                # mass matrix
"""

from .builder import ModelBuilder
from .io import DHLink, dh_transform, from_dh, from_poe, load_mjcf, load_urdf, write_mjcf, write_urdf
from .errors import ModelError, RobodynWarning
from .model import Model
from .coupling import CoupledModel
from . import models, random

# The algorithms are imported on first use (PEP 562), so that `import robodyn` stays fast.
_LAZY = {
    "aba": "aba", "center_of_mass": "com", "com_jacobian": "com", "christoffel_symbols": "coriolis",
    "coriolis_matrix": "coriolis", "crba": "crba", "kinetic_energy": "energy", "potential_energy": "energy",
    "jacobian": "jacobian", "jacobian_dot_times_v": "jacobian", "forward_kinematics": "kinematics",
    "frame_pose": "kinematics", "rnea": "rnea", "generalized_momentum": "terms", "gravity": "terms",
    "nonlinear_effects": "terms", "gravity_derivatives": "terms", "nonlinear_effects_derivatives": "terms",
    "generalized_momentum_derivatives": "terms", "frame_velocity_derivatives": "frame_derivatives",
    "frame_acceleration_derivatives": "frame_derivatives", "integrate": "integrate", "difference": "integrate",
    "integrate_jacobians": "integrate", "difference_jacobians": "integrate",
    "hybrid_dynamics": "hybrid", "inverse_mass_matrix": "minv", "constrained_dynamics": "constrained",
    "ConstrainedDynamics": "constrained", "PointConstraint": "constrained", "WeldConstraint": "constrained",
    "LoopConstraint": "constrained", "DistanceConstraint": "constrained", "CouplingConstraint": "constrained",
    "constrained_dynamics_derivatives": "constrained_derivatives",
    "ConstrainedDynamicsDerivatives": "constrained_derivatives",
    "task_space_inertia": "task_space", "dynamically_consistent_inverse": "task_space",
    "task_space_dynamics": "task_space", "TaskSpaceDynamics": "task_space",
    "regressor": "regressor", "kinetic_energy_regressor": "regressor", "potential_energy_regressor": "regressor",
    "slotine_li_regressor": "regressor", "rnea_derivatives": "rnea_derivatives",
    "rnea_second_derivatives": "rnea_second_derivatives", "RNEASecondDerivatives": "rnea_second_derivatives",
    "aba_derivatives": "aba_derivatives", "mass_matrix_from_jacobians": "mass_jacobians",
    "inertia_bounds": "inertia_bounds",
}
# Applications, also imported on first use: name -> module.
_LAZY_APPS = {"simulate": "simulation", "Trajectory": "simulation", "linearize": "simulation",
              "rollout": "simulation", "Rollouts": "simulation", "simulation": None,
              "control": None, "plots": None, "identification": None, "symbolic": None, "interop": None,
              "contact": None, "Contacts": "contact", "inertia": None, "actuators": None,
              "distributed": None, "simulate_many": "distributed", "viewer": None}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".algorithms.{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in _LAZY_APPS:
        import importlib

        module = importlib.import_module(f".{_LAZY_APPS[name] or name}", __name__)
        value = module if _LAZY_APPS[name] is None else getattr(module, name)
        globals()[name] = value
        return value
    if name == "warmup":
        from ._warmup import warmup

        return warmup
    raise AttributeError(f"module 'robodyn' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | set(_LAZY_APPS) | {"warmup"})


__version__ = "0.1.0"

__all__ = [
    "Model", "CoupledModel", "ModelError", "ModelBuilder", "RobodynWarning", "DHLink", "dh_transform", "from_dh",
    "from_poe", "load_urdf", "load_mjcf", "models", "rnea", "aba", "crba", "gravity", "nonlinear_effects",
    "generalized_momentum",
    "coriolis_matrix", "christoffel_symbols", "kinetic_energy", "potential_energy", "center_of_mass",
    "com_jacobian", "jacobian", "jacobian_dot_times_v", "forward_kinematics", "frame_pose", "warmup",
    "hybrid_dynamics", "inverse_mass_matrix", "constrained_dynamics", "ConstrainedDynamics", "PointConstraint",
    "WeldConstraint", "LoopConstraint", "DistanceConstraint", "CouplingConstraint", "task_space_inertia",
    "constrained_dynamics_derivatives", "ConstrainedDynamicsDerivatives",
    "mass_matrix_from_jacobians", "inertia_bounds",
    "dynamically_consistent_inverse", "task_space_dynamics", "TaskSpaceDynamics",
    "integrate", "difference", "simulate", "Trajectory", "simulation", "control", "plots",
    "regressor", "kinetic_energy_regressor", "potential_energy_regressor", "write_urdf", "write_mjcf",
    "slotine_li_regressor", "interop", "rnea_derivatives", "rnea_second_derivatives", "RNEASecondDerivatives",
    "aba_derivatives", "linearize",
    "integrate_jacobians", "difference_jacobians", "gravity_derivatives", "nonlinear_effects_derivatives",
    "generalized_momentum_derivatives", "frame_velocity_derivatives", "frame_acceleration_derivatives",
    "contact", "Contacts", "rollout", "Rollouts", "distributed", "simulate_many",
]
# ``rd.symbolic`` (closed-form models, imports sympy) is loaded on first use and left out of
# ``__all__`` so that ``from robodyn import *`` stays light.
