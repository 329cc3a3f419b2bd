"""Conversions to and from other libraries' robot models.

- :func:`to_pinocchio` (robodyn :class:`~robodyn.model.Model` -> ``pinocchio.Model``) and
  :func:`from_pinocchio` (``pinocchio.Model`` -> robodyn ``Model``), with
  :func:`configuration_to_pinocchio` / :func:`configuration_from_pinocchio` for the one place
  where the two configuration vectors differ (Pinocchio's continuous joints store
  ``(cos, sin)``, robodyn one angle). Conventions, frames and units: :mod:`robodyn.interop.pinocchio`.
- :mod:`robodyn.interop.mujoco`: states and forces between MuJoCo and a model read by
  :func:`robodyn.load_mjcf` (free joints differ in quaternion order and velocity frames).

The other libraries are optional dependencies: each is imported inside the function that needs
it, so ``import robodyn.interop`` works without them, and a missing one raises an
``ImportError`` that says what to install.
"""

from . import mujoco
from .pinocchio import (
    configuration_from_pinocchio,
    configuration_to_pinocchio,
    from_pinocchio,
    to_pinocchio,
)

__all__ = ["mujoco", "configuration_from_pinocchio", "configuration_to_pinocchio", "from_pinocchio", "to_pinocchio"]
