"""The ``robodyn`` command line.

    robodyn info MODEL          joint table, masses and inertias of a built-in robot or URDF
    robodyn demo [MODEL]        inverse and forward dynamics and the mass matrix at a sample state
    robodyn bench [MODEL]       per-call timings (and the comparison with Pinocchio if installed)
    robodyn warmup              compile (or load from the cache) every kernel, with a progress bar
    robodyn simulate MODEL      simulation, free or controlled (plots, GIF, CSV; cli/simulation.py)
    robodyn torques MODEL CSV   joint forces of a trajectory: inertial, Coriolis, gravity
    robodyn excite MODEL ...    excitation trajectory for identification (cli/identification.py)
    robodyn identify MODEL CSV  identified parameters, URDF and report (cli/identification.py)
    robodyn derive MODEL        closed-form M, C, g (sympy), as LaTeX and C code

MODEL is a built-in name (``robodyn info --list``) or the path of a URDF file.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from ..errors import ModelError
from . import identification, model, simulation, symbolic


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="robodyn", description="Rigid-body robot dynamics.")
    sub = parser.add_subparsers(dest="command", required=True)

    for commands in (model, simulation, identification, symbolic):
        commands.add_commands(sub)

    args = parser.parse_args(argv)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            status = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the try
        return status
    except (ModelError, ValueError) as e:
        print(f"robodyn: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader stopped early (``robodyn demo | head``): exit quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
