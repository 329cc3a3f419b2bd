"""Helpers shared by the command modules: the model argument and loading a model.

Imported by every command module; imports none of them.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .. import models


def load_model(spec: str, floating_base: bool = False, physical: str = "error", mimic: str = "couple"):
    """A built-in robot by name, a MuJoCo model (``.xml``, ``.mjcf``) or a URDF file by path, or
    a URDF of example-robot-data by its name (``solo12``) when that package is installed
    (``mimic``: see :func:`robodyn.load_urdf` and :func:`robodyn.load_mjcf`)."""
    from ..io.mjcf import load_mjcf
    from ..io.urdf import load_urdf

    if spec in models.names():
        if floating_base:
            raise ValueError("--floating-base applies to URDF files; built-in robots have a fixed base")
        return models.load(spec)
    if spec.lower().endswith((".xml", ".mjcf")):
        if floating_base:
            raise ValueError("--floating-base applies to URDF files; a MuJoCo model declares its free joints")
        return load_mjcf(spec, physical=physical, mimic=mimic)
    if spec.endswith(".urdf") or "/" in spec:
        return load_urdf(spec, floating_base=floating_base, physical=physical, mimic=mimic)
    found = models.example_robot_urdf(spec)
    if found is not None:
        return load_urdf(found, floating_base=floating_base, physical=physical, mimic=mimic)
    raise ValueError(f"unknown model {spec!r}: give a URDF or MJCF path, one of {models.names()}, or the name of "
                     f"a URDF of example-robot-data (pip install example-robot-data), e.g. solo12")


def add_model_arguments(p, default=None) -> None:
    """The model argument and the loader options of a command."""
    p.add_argument("model", nargs="?", default=default, help="built-in robot name, URDF path or MJCF path (.xml)")
    p.add_argument("--floating-base", action="store_true", help="URDF: add a free-flying base")
    p.add_argument("--physical", choices=("error", "warn", "repair"), default="error",
                   help="reject (error), keep with a warning (warn) or repair with a warning (repair: negative "
                        "principal moments to 0, then MuJoCo's balanceinertia) unphysical inertias")
    p.add_argument("--mimic", choices=("couple", "independent"), default="couple",
                   help="URDF <mimic> joints and MJCF joint equalities: follow their source joint (couple) "
                   "or move as independent joints")


def loaded(args):
    """The model of a command's arguments (:func:`add_model_arguments`)."""
    if args.model is None:
        raise ValueError(f"robodyn {args.command}: give a MODEL (built-in name, URDF or MJCF path)")
    return load_model(args.model, args.floating_base, args.physical, args.mimic)


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


# Outputs that could not be written where asked and were saved elsewhere (see :func:`save`);
# ``main`` reports them and exits 2 once the command has finished.
RESCUED: list[str] = []


def save(write, path, option: str):
    """``write(path)``, so that finished work is never lost: when it fails with an ``OSError``
    (a full disk, the directory removed meanwhile), the result goes into a new directory of the
    system's temporary directory instead, and the failure and the new place are recorded for
    ``main`` to report. Returns what ``write`` returns (nothing is written for ``path=None``)."""
    if path is None:
        return write(None)
    try:
        return write(path)
    except OSError as e:
        rescue = Path(tempfile.mkdtemp(prefix="robodyn-")) / Path(path).name
        result = write(rescue)
        RESCUED.append(f"{option} {path}: {e.strerror or e}; saved to {rescue} instead")
        _WHERE[str(path)] = rescue
        return result


_WHERE: dict[str, Path] = {}


def written(path):
    """Where :func:`save` put ``path``'s result: ``path``, or the place it was saved instead."""
    return _WHERE.get(str(path), path)


def reset() -> None:
    """Forget the rescued outputs of a previous command (``main`` runs one per call)."""
    RESCUED.clear()
    _WHERE.clear()
