"""Side-by-side timings: robodyn against Pinocchio, roboticstoolbox-python and MuJoCo, same process.

    python benchmarks/compare.py [--batch 100000] [--write] [--no-rtb] [--no-mujoco]

Robots: Panda and Talos (reduced, floating base) from example-robot-data, both loaded by
robodyn and by Pinocchio from the same URDF; PUMA 560 and Panda as DH models in robodyn
(built-in) and in roboticstoolbox-python; Panda and Talos (fixed base) converted by MuJoCo
from the same URDFs, for ``rnea`` against ``mj_inverse``. Prints per-call / per-state times
and the ratio robodyn / other (below 1: robodyn is faster), after checking that the results
agree on the timed states. ``--write`` appends the tables to ``benchmarks/RESULTS.md`` with
the machine, the versions and this command line.

Needs the test extras (``pip install ".[test]"``) and ``pip install roboticstoolbox-python mujoco``.
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
from robodyn.bench import (Timing, agreement, batch_timings, format_table, paired_us, per_call_us, rel_error,
                           single_call_timings, states)

TOL = 1e-9  # the core dynamics' tolerance against Pinocchio

HERE = Path(__file__).resolve().parent


def erd_urdf(relpath: str) -> str:
    import sysconfig

    base = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
    return str(base / relpath)


def load_pair(name: str, relpath: str, floating: bool):
    """robodyn's and Pinocchio's models of one example-robot-data URDF, ``(model, pin_model)``,
    with the same configuration layout (a continuous joint would differ: refused; mimic joints
    as independent joints on both sides, Pinocchio's default)."""
    import pinocchio as pin

    f = erd_urdf(relpath)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rd.load_urdf(f, floating_base=floating, mimic="independent")
    pm = pin.buildModelFromUrdf(f, pin.JointModelFreeFlyer()) if floating else pin.buildModelFromUrdf(f)
    if pm.nq != model.nq:
        raise SystemExit(f"{name}: continuous joints make the q layouts differ; pick another robot")
    return model, pm


def pinocchio_section(name: str, relpath: str, floating: bool, batch: int) -> str:
    import pinocchio as pin

    model, pm = load_pair(name, relpath, floating)
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


def mujoco_model(urdf: str):
    """MuJoCo's model of a URDF, for ``mj_inverse`` to compute what ``rnea`` does: the
    geometry is left out (MuJoCo would need the mesh files; the dynamics do not use it), and
    so are the constraint forces (joint limits), the passive forces (damping, springs) and
    the armature, which robodyn's ``rnea(..., friction=False, armature=False)`` leaves out."""
    import re

    import mujoco

    text = Path(urdf).read_text()
    for tag in ("visual", "collision"):
        text = re.sub(rf"<{tag}\b.*?</{tag}>", "", text, flags=re.S)
    m = mujoco.MjModel.from_xml_string(text)
    m.opt.disableflags |= (mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_DAMPER
                           | mujoco.mjtDisableBit.mjDSBL_SPRING)
    m.dof_armature[:] = 0.0
    return m


def mujoco_section() -> str:
    """Single calls of ``rnea`` against MuJoCo's ``mj_inverse`` (which has no batched call) on
    the fixed-base models that convert: Panda and Talos reduced (MuJoCo reads no floating
    base from a URDF). MuJoCo numbers its dofs in its own order: the states are permuted once,
    before the timing, by joint name."""
    import mujoco

    rows, errors = [], {}
    for name, relpath in (("panda", "panda_description/urdf/panda.urdf"),
                          ("talos", "talos_data/robots/talos_reduced.urdf")):
        f = erd_urdf(relpath)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = rd.load_urdf(f, mimic="independent")  # MuJoCo's <mimic>-free reading
        m = mujoco_model(f)
        d = mujoco.MjData(m)
        if m.nv != model.nv or m.nq != model.nq:
            raise SystemExit(f"{name}: MuJoCo's model has nq, nv = {m.nq}, {m.nv}, robodyn's {model.nq}, {model.nv}")
        # order[k]: robodyn's dof of MuJoCo's dof k (every joint has one dof, q and v alike)
        dof_of = {jn: int(model.idx_v[i]) for i, jn in enumerate(model.body_joint_names)}
        order = np.array([dof_of[mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in range(m.njnt)])
        order = order[np.argsort(m.jnt_dofadr)]
        _, (Q, V, A) = states(model, 200)
        err = 0.0
        tau = rd.rnea(model, Q, V, A, friction=False, armature=False)
        for s in range(Q.shape[0]):
            d.qpos[:], d.qvel[:], d.qacc[:] = Q[s, order], V[s, order], A[s, order]
            mujoco.mj_inverse(m, d)
            err = max(err, rel_error(d.qfrc_inverse, tau[s, order]))
        if not err <= TOL:
            raise SystemExit(f"{name}: robodyn's rnea and MuJoCo's mj_inverse differ by {err:.3g} > {TOL:g}")
        errors[name] = err
        q, v, a = Q[0], V[0], A[0]
        qm, vm, am = q[order], v[order], a[order]

        def mj_call():
            d.qpos[:], d.qvel[:], d.qacc[:] = qm, vm, am
            mujoco.mj_inverse(m, d)
            return d.qfrc_inverse

        rows.append(Timing(f"{name} rnea / mj_inverse", *paired_us(
            lambda: rd.rnea(model, q, v, a, friction=False, armature=False), mj_call)))
    agree = ", ".join(f"{k} {e:.1e}" for k, e in errors.items())
    return (f"### Fixed-base URDF models vs MuJoCo {mujoco.__version__} (single calls)\n"
            "\n```\n" + format_table(rows, other="mujoco") + "\n```\n\n"
            + f"Largest relative error of `rnea` against `mj_inverse` over 200 states: {agree}.\n")


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
    p.add_argument("--no-mujoco", action="store_true", help="skip MuJoCo")
    args = p.parse_args()
    t0 = time.time()
    parts = [f"## {machine()}\n", f"Command: `python benchmarks/compare.py {' '.join(sys.argv[1:])}`\n",
             import_time(), first_call_time(),
             pinocchio_section("Panda", "panda_description/urdf/panda.urdf", False, args.batch),
             pinocchio_section("Talos reduced", "talos_data/robots/talos_reduced.urdf", True, args.batch)]
    if not args.no_rtb:
        parts.append(rtb_section(args.batch))
    if not args.no_mujoco:
        parts.append(mujoco_section())
    text = "\n".join(parts)
    print(text)
    print(f"(ran in {time.time() - t0:.0f} s)")
    if args.write:
        with open(HERE / "RESULTS.md", "a") as fh:
            fh.write("\n" + text)


if __name__ == "__main__":
    main()
