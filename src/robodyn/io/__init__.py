"""Loaders that build a :class:`~robodyn.model.Model` from robot descriptions."""

from .dh import DHLink, dh_transform, from_dh
from .mjcf import load_mjcf
from .mjcf_writer import write_mjcf
from .poe import from_poe
from .urdf import load_urdf
from .urdf_writer import write_urdf
from ..errors import RobodynWarning

__all__ = ["DHLink", "dh_transform", "from_dh", "from_poe", "load_mjcf", "load_urdf", "write_mjcf", "write_urdf", "RobodynWarning"]
