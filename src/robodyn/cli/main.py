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
    robodyn view MODEL          3-D view in the browser, or a PNG/GIF render (cli/view.py)

MODEL is a built-in name (``robodyn info --list``) or the path of a URDF file.

Exit status: 0 success; 2 bad input or output (the message names the file or option: missing,
unreadable, malformed or unphysical input, an output whose directory is missing or not
writable, checked before the work starts); 130 interrupted (Ctrl-C); 1 an unexpected error
(one line; ``robodyn --debug ...`` shows the traceback). A closed pipe exits quietly with 0.
Outputs are written atomically (``robodyn.files``); one whose write fails after the work is
saved in a new temporary directory instead (``common.save``), and the error line says where.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from ..errors import ModelError
from . import common, identification, model, simulation, symbolic, view


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="robodyn", description="Rigid-body robot dynamics.")
    sub = parser.add_subparsers(dest="command", required=True)

    parser.add_argument("--debug", action="store_true", help="show the Python traceback of an unexpected error")
    for commands in (model, simulation, identification, symbolic, view):
        commands.add_commands(sub)

    args = parser.parse_args(argv)
    common.reset()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            status = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the try
        if common.RESCUED:  # finished work saved elsewhere: say where, and fail
            print(f"robodyn: error: {'; '.join(common.RESCUED)}", file=sys.stderr)
            return 2
        return status
    except (ModelError, ValueError) as e:
        print(f"robodyn: error: {e}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader stopped early (``robodyn demo | head``): exit quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as e:  # a missing or unreadable input, a directory given for a file, ...
        where = f"{e.filename}: " if e.filename is not None else ""
        print(f"robodyn: error: {where}{e.strerror or e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("robodyn: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # noqa: BLE001 - a defect: one line, the traceback on request
        if args.debug:
            raise
        print(f"robodyn: internal error: {type(e).__name__}: {e} (rerun with --debug for the traceback)",
              file=sys.stderr)
        return 1
