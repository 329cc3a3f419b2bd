"""robodyn: rigid-body robot dynamics for Python.

    import robodyn as rd
    model = rd.models.load("panda")
    tau = rd.rnea(model, q, v, a)        # inverse dynamics
    a = rd.aba(model, q, v, tau)         # forward dynamics
    M = rd.crba(model, q)                # mass matrix
"""

from .builder import ModelBuilder
from .io import DHLink, dh_transform, from_dh, load_urdf
from .errors import ModelError, RobodynWarning
from .model import Model
from . import models, random
from .algorithms.aba import aba
from .algorithms.com import center_of_mass, com_jacobian
from .algorithms.coriolis import christoffel_symbols, coriolis_matrix
from .algorithms.crba import crba
from .algorithms.energy import kinetic_energy, potential_energy
from .algorithms.jacobian import jacobian, jacobian_dot_times_v
from .algorithms.kinematics import forward_kinematics, frame_pose
from .algorithms.rnea import rnea
from .algorithms.terms import generalized_momentum, gravity, nonlinear_effects
from .warmup import warmup

__version__ = "0.1.0"

__all__ = [
    "Model", "ModelError", "ModelBuilder", "RobodynWarning", "DHLink", "dh_transform", "from_dh",
    "load_urdf", "models", "rnea", "aba", "crba", "gravity", "nonlinear_effects", "generalized_momentum",
    "coriolis_matrix", "christoffel_symbols", "kinetic_energy", "potential_energy", "center_of_mass",
    "com_jacobian", "jacobian", "jacobian_dot_times_v", "forward_kinematics", "frame_pose", "warmup",
]
