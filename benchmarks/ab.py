"""A/B timing of the working tree's robodyn against a git revision, in one process.

    python benchmarks/ab.py [REV] [--calls aba,rnea] [--robots panda,talos] [--batch 20000]
                            [--threads 1] [--rounds 25] [--single]

``REV`` (default ``HEAD``) is exported with ``git archive`` into a directory of the system's
temporary directory named after its commit, and imported as ``robodyn_old``; its compiled
kernels are cached there, so a second run against the same commit compiles nothing. Both
versions are timed on the same states in alternating rounds (best of ``--rounds``), so that
both see the same machine load. Prints, per robot and call, the time per state (or per call
with ``--single``) of ``REV`` and of the working tree in microseconds, their ratio (below 1:
the working tree is faster) and the largest relative difference of their results.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import warnings
from inspect import signature
from pathlib import Path

import numba
import numpy as np

ROBOTS = {"panda": ("panda_description/urdf/panda.urdf", False),
          "talos": ("talos_data/robots/talos_reduced.urdf", True)}
ARGS = {"rnea": "QVA", "aba": "QVA", "crba": "Q", "coriolis_matrix": "QV", "inverse_mass_matrix": "Q",
        "rnea_derivatives": "QVA", "aba_derivatives": "QVA", "rnea_second_derivatives": "QVA"}


def import_revision(rev: str):
    """``robodyn`` as of ``rev``, imported under the name ``robodyn_old``."""
    repo = Path(__file__).resolve().parent.parent
    sha = subprocess.run(["git", "rev-parse", rev], cwd=repo, check=True, capture_output=True,
                         text=True).stdout.strip()
    root = Path(tempfile.gettempdir()) / "robodyn-ab" / sha
    if not (root / "robodyn_old").exists():
        root.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "archive", sha, "src/robodyn"], cwd=repo, check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(root)], input=archive, check=True)
        (root / "src" / "robodyn").rename(root / "robodyn_old")
    sys.path.insert(0, str(root))
    import robodyn_old

    return robodyn_old


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("rev", nargs="?", default="HEAD")
    p.add_argument("--calls", default="aba,rnea,crba,coriolis_matrix")
    p.add_argument("--robots", default="panda,talos")
    p.add_argument("--batch", type=int, default=20000)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--rounds", type=int, default=25)
    p.add_argument("--single", action="store_true", help="single calls instead of a batch")
    args = p.parse_args()

    import robodyn as rd
    from robodyn.bench import paired_us, rel_error, states

    ro = import_revision(args.rev)
    numba.set_num_threads(args.threads)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from compare import erd_urdf

    print(f"{args.rev} -> working tree, {args.threads} thread(s), "
          + ("single calls, us per call" if args.single else f"batches of {args.batch}, us per state"))
    for name in args.robots.split(","):
        relpath, floating = ROBOTS[name]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            new, old = (lib.load_urdf(erd_urdf(relpath), floating_base=floating,  # mimic joints independent
                                      **({"mimic": "independent"} if "mimic" in signature(lib.load_urdf).parameters
                                         else {})) for lib in (rd, ro))
        single, batch = states(new, args.batch)
        x = dict(zip("QVA", single if args.single else batch))
        per = 1 if args.single else args.batch
        cells = []
        for call in args.calls.split(","):
            inputs = [x[k] for k in ARGS[call]]
            f_new, f_old = getattr(rd, call), getattr(ro, call)
            err = rel_error(np.asarray(f_new(new, *inputs)), np.asarray(f_old(old, *inputs)))  # tuples: stacked
            t_new, t_old = paired_us(lambda: f_new(new, *inputs), lambda: f_old(old, *inputs), rounds=args.rounds)
            cells.append(f"{call} {t_old / per:.3f} -> {t_new / per:.3f} ({t_new / t_old:.2f}), diff {err:.0e}")
        print(f"{name}: " + " | ".join(cells))


if __name__ == "__main__":
    main()
