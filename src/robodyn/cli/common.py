"""Helpers shared by the command modules: the model argument and loading a model.

Imported by every command module; imports none of them.
"""

from __future__ import annotations

import os
from pathlib import Path

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


def check_output_file(path, option: str) -> None:
    """Refuse, before any work starts, an output file that cannot be written: its directory
    missing or not writable, or the path an existing directory."""
    if path is None:
        return
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise ValueError(f"{option} {path}: is a directory; give a file name")
    if not parent.is_dir():
        raise ValueError(f"{option} {path}: the directory {parent} does not exist; create it first")
    if not os.access(parent, os.W_OK):
        raise ValueError(f"{option} {path}: the directory {parent} is not writable")


def check_output_dir(path, option: str) -> None:
    """Refuse, before any work starts, an output directory that cannot be made or written: its
    parent missing, the path an existing file, or not writable. A missing last directory is
    created by the command."""
    if path is None:
        return
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{option} {path}: is a file; give a directory")
    if path.is_dir():
        if not os.access(path, os.W_OK):
            raise ValueError(f"{option} {path}: the directory is not writable")
        return
    check_output_file(path, option)
