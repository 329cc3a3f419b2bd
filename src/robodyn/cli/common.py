"""Helpers shared by the command modules: the model argument and loading a model.

Imported by every command module; imports none of them.
"""

from __future__ import annotations

from .. import models


def load_model(spec: str, floating_base: bool = False, physical: str = "error"):
    """A built-in robot by name, or a URDF file by path."""
    from ..io.urdf import load_urdf

    if spec in models.names():
        if floating_base:
            raise ValueError("--floating-base applies to URDF files; built-in robots have a fixed base")
        return models.load(spec)
    if spec.endswith(".urdf") or "/" in spec:
        return load_urdf(spec, floating_base=floating_base, physical=physical)
    raise ValueError(f"unknown model {spec!r}: give a URDF path or one of {models.names()}")


def add_model_arguments(p, default=None) -> None:
    """The model argument and the loader options of a command."""
    p.add_argument("model", nargs="?", default=default, help="built-in robot name or URDF path")
    p.add_argument("--floating-base", action="store_true", help="URDF: add a free-flying base")
    p.add_argument("--physical", choices=("error", "warn"), default="error",
                   help="URDF: reject (error) or keep with a warning (warn) unphysical inertias")
