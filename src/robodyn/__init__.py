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
from . import models

__version__ = "0.1.0"

__all__ = [
    "Model", "ModelError", "ModelBuilder", "RobodynWarning", "DHLink", "dh_transform", "from_dh",
    "load_urdf", "models",
]
