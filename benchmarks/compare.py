"""Side-by-side timings: robodyn against Pinocchio and roboticstoolbox-python, same process.

    python benchmarks/compare.py [--batch 100000] [--write]

Robots: Panda and Talos (reduced, floating base) from example-robot-data, both loaded by
robodyn and by Pinocchio from the same URDF; PUMA 560 and Panda as DH models in robodyn
(built-in) and in roboticstoolbox-python. Prints per-call / per-state times and the ratio
robodyn / other (below 1: robodyn is faster). ``--write`` appends the tables to
``benchmarks/RESULTS.md`` with the machine, the versions and this command line.

Needs the test extras (``pip install ".[test]"``) and ``pip install roboticstoolbox-python``.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numba
import numpy as np

import robodyn as rd
from robodyn.bench import Timing, agreement, batch_timings, format_table, paired_us, per_call_us, single_call_timings

TOL = 1e-9  # the core dynamics' tolerance against Pinocchio

HERE = Path(__file__).resolve().parent


def erd_urdf(relpath: str) -> str:
    import sysconfig

    base = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
    return str(base / relpath)


def pinocchio_section(name: str, relpath: str, floating: bool, batch: int) -> str:
    import pinocchio as pin

    f = erd_urdf(relpath)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rd.load_urdf(f, floating_base=floating)
    pm = pin.buildModelFromUrdf(f, pin.JointModelFreeFlyer()) if floating else pin.buildModelFromUrdf(f)
    if pm.nq != model.nq:
        raise SystemExit(f"{name}: continuous joints make the q layouts differ; pick another robot")
    single = single_call_timings(model, pm)
    batched = batch_timings(model, batch, pm)
    errors = agreement(model, pm, batch)
    bad = {k: e for k, e in errors.items() if not e <= TOL}
    if bad:
        raise SystemExit(f"{name}: robodyn and Pinocchio differ beyond {TOL:g} on benchmarked states: {bad}")
    head = f"### {name} ({'floating' if floating else 'fixed'} base, nv = {model.nv}) vs Pinocchio {pin.__version__}\n"
    agree = ", ".join(f"{k} {e:.1e}" for k, e in errors.items())
    return (head + "\n```\n" + format_table(single + batched) + "\n```\n\n"
            + f"Largest relative error against Pinocchio over the benchmarked states: {agree}.\n")


def rtb_section(batch: int) -> str:
    import roboticstoolbox as rtb

    rows = []
    for name, rtb_cls in (("puma560", rtb.models.DH.Puma560), ("panda", rtb.models.DH.Panda)):
        robot = rtb_cls()
        model = rd.models.load(name)
        rng = np.random.default_rng(0)
        q, v, a = rng.uniform(-1, 1, (3, model.nv))
        rows += [
            Timing(f"{name} rne / rnea", *paired_us(lambda: rd.rnea(model, q, v, a), lambda: robot.rne(q, v, a))),
            Timing(f"{name} inertia / crba", *paired_us(lambda: rd.crba(model, q), lambda: robot.inertia(q))),
            Timing(f"{name} coriolis", per_call_us(lambda: rd.coriolis_matrix(model, q, v)),
                   per_call_us(lambda: robot.coriolis(q, v), min_time=0.5, repeat=2)),
        ]
    import roboticstoolbox

    return (f"### DH models vs roboticstoolbox-python {roboticstoolbox.__version__} (single calls)\n"
            "\n```\n" + format_table(rows, other="rtb") + "\n```\n")


def import_time() -> str:
    """Wall time of ``import robodyn`` in a fresh process (kernels are compiled lazily)."""
    code = "import time; t = time.perf_counter(); import robodyn; print(time.perf_counter() - t)"
    times = [float(subprocess.check_output([sys.executable, "-c", code], text=True)) for _ in range(3)]
    return f"`import robodyn`: {min(times):.3f} s (best of 3 fresh processes)\n"


def first_call_time() -> str:
    """Time of the first rnea call in a fresh process: the compile cache is loaded from disk."""
    code = ("import time, numpy as np, robodyn as rd; m = rd.models.load('panda'); q = np.zeros(7);"
            "t = time.perf_counter(); rd.rnea(m, q, q, q); print(time.perf_counter() - t)")
    t = float(subprocess.check_output([sys.executable, "-c", code], text=True))
    return f"first `rnea` call in a new process (compiled code loaded from the cache): {t:.3f} s\n"


def machine() -> str:
    import pinocchio

    versions = f"robodyn {rd.__version__}, numba {numba.__version__}, numpy {np.__version__}, pinocchio {pinocchio.__version__}"
    return (f"{datetime.date.today()}, {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"{numba.get_num_threads()} threads, Python {platform.python_version()}; {versions}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--batch", type=int, default=100_000)
    p.add_argument("--write", action="store_true", help="append the results to benchmarks/RESULTS.md")
    p.add_argument("--no-rtb", action="store_true", help="skip roboticstoolbox-python")
    args = p.parse_args()
    t0 = time.time()
    parts = [f"## {machine()}\n", f"Command: `python benchmarks/compare.py {' '.join(sys.argv[1:])}`\n",
             import_time(), first_call_time(),
             pinocchio_section("Panda", "panda_description/urdf/panda.urdf", False, args.batch),
             pinocchio_section("Talos reduced", "talos_data/robots/talos_reduced.urdf", True, args.batch)]
    if not args.no_rtb:
        parts.append(rtb_section(args.batch))
    text = "\n".join(parts)
    print(text)
    print(f"(ran in {time.time() - t0:.0f} s)")
    if args.write:
        with open(HERE / "RESULTS.md", "a") as fh:
            fh.write("\n" + text)


if __name__ == "__main__":
    main()
