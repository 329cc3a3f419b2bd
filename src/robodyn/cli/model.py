"""``robodyn info``, ``robodyn demo``, ``robodyn bench`` and ``robodyn warmup``: a model's tables,
its dynamics at a sample state, timings, and compiling every kernel ahead of time."""

from __future__ import annotations

import os
import sys

import numpy as np

from .. import models
from ..coupling import independent_q, joint_tree
from .common import add_model_arguments, loaded


def _fmt(x, width=9, prec=4) -> str:
    return " ".join(f"{v:{width}.{prec}f}" for v in np.atleast_1d(x))


def cmd_info(args) -> int:
    if args.list:
        for name in models.names():
            m = models.load(name)
            print(f"{name:<16} nv={m.nv:<3} mass={m.total_mass:8.3f} kg")
        return 0
    if not args.model:
        print("robodyn info: give a MODEL (or --list)", file=sys.stderr)
        return 2
    model = loaded(args)
    print(model)
    print("\nInertial parameters per body (about the body origin, body frame):")
    print(f"  {'body':<24} {'m':>9} {'mcx':>9} {'mcy':>9} {'mcz':>9} {'Ixx':>9} {'Ixy':>9} {'Iyy':>9} {'Ixz':>9} {'Iyz':>9} {'Izz':>9}")
    for i, name in enumerate(model.link_names):
        print(f"  {name:<24} {_fmt(model.theta[i])}")
    tree = joint_tree(model)  # with mimic joints: every joint of the tree, the mimic joints marked
    follows = {joint: f"= {r:g} {source}" + (f" {o:+g}" if o else "") for joint, source, r, o in getattr(model, "mimic", ())}
    if tree.nv:
        print("\nJoint data (per velocity entry):")
        print(f"  {'#':>3} {'lower':>9} {'upper':>9} {'vel.max':>9} {'effort':>9} {'damping':>9} {'coulomb':>9} "
              f"{'armature':>9}  dof")
        for k, name in enumerate(tree.dof_names):
            vals = [tree.lower[k], tree.upper[k], tree.velocity_limit[k], tree.effort_limit[k],
                    tree.damping[k], tree.coulomb[k], tree.armature[k]]
            print(f"  {k:>3} {_fmt(vals)}  {name} {follows.get(name, '')}".rstrip())
    return 0


def sample_state(model, seed: int = 0):
    """A reproducible sample state: mid-range joint angles, moderate speeds and accelerations."""
    from ..joints import NQ
    from ..random import random_configuration

    rng = np.random.default_rng(seed)
    tree = joint_tree(model)  # a model with mimic joints: its independent coordinates of the tree's
    q = random_configuration(tree, rng)
    for i in range(tree.nbodies):  # joint angles in [-pi/2, pi/2]; free and spherical joints as drawn
        if NQ[tree.joint_type[i]] == 1:
            q[tree.idx_q[i]] *= 0.5
    q = independent_q(model, q)
    v = rng.uniform(-1.0, 1.0, model.nv)
    a = rng.uniform(-2.0, 2.0, model.nv)
    return q, v, a


def cmd_demo(args) -> int:
    import robodyn as rd

    model = loaded(args)
    q, v, a = sample_state(model, args.seed)
    np.set_printoptions(precision=4, suppress=True, linewidth=120)
    print(f"robodyn demo on {model.name!r}: nq={model.nq}, nv={model.nv}, {model.nbodies} bodies, "
          f"mass {model.total_mass:.3f} kg")
    print(f"  q   = {q}\n  v   = {v}\n  a   = {a}")

    M = rd.crba(model, q, armature=False)
    inertial = M @ a
    coriolis = rd.coriolis_matrix(model, q, v) @ v
    grav = rd.gravity(model, q)
    tau = rd.rnea(model, q, v, a, friction=False, armature=False)
    print("\nInverse dynamics (RNEA): tau = M(q) a + C(q, v) v + g(q)   [N m or N]")
    print(f"  {'joint':<22} {'inertial':>10} {'coriolis':>10} {'gravity':>10} {'total':>10}")
    names = model.dof_names
    for k in range(model.nv):
        print(f"  {names[k]:<22} {inertial[k]:10.4f} {coriolis[k]:10.4f} {grav[k]:10.4f} {tau[k]:10.4f}")
    residual = np.abs(inertial + coriolis + grav - tau).max()
    print(f"  max |M a + C v + g - rnea| = {residual:.2e}")
    extra = rd.rnea(model, q, v, a) - tau
    tree = joint_tree(model)
    if np.any(tree.damping) or np.any(tree.coulomb) or np.any(tree.armature):
        print("  NOTE rnea(model, q, v, a) with its defaults also adds the joints' friction and rotor inertia\n"
              f"  (armature), up to {np.abs(extra).max():.4g} N m more: {rd.rnea(model, q, v, a)};\n"
              "  friction=False, armature=False (or model.rigid()) give the rigid-body terms above")
    else:
        print("  (no joint friction or armature in this model; rnea, aba and crba add them by default\n"
              "  when a model has them: friction=False, armature=False or model.rigid() leave them out)")

    acc = rd.aba(model, q, v, tau, friction=False, armature=False)
    print("\nForward dynamics (ABA) of those torques recovers a:")
    print(f"  a = {acc}\n  max |aba(rnea(a)) - a| = {np.abs(acc - a).max():.2e}")
    acc0 = rd.aba(model, q, v, np.zeros(model.nv), friction=False, armature=False)
    print(f"  with tau = 0 (falling under gravity): a = {acc0}")

    print("\nMass matrix M(q) (CRBA):")
    print(M)
    print(f"  eigenvalues: {np.linalg.eigvalsh(M)}")
    print(f"\nKinetic energy {rd.kinetic_energy(model, q, v):.6f} J, "
          f"potential energy {rd.potential_energy(model, q):.6f} J")
    return 0


def cmd_bench(args) -> int:
    from ..bench import run_bench

    model = loaded(args)
    return run_bench(model, args.model, batch=args.batch, compare=not args.no_compare)


def cmd_warmup(args) -> int:
    """Compile (first run) or load every kernel, with a progress bar on a terminal."""
    import time

    from .._warmup import warmup
    from ..simulation.simulate import Progress

    bar, start, count = None, time.perf_counter(), [0]

    def progress(done, total, name):
        nonlocal bar
        if bar is None:
            bar = Progress(total)
        bar.update(done)
        count[0] = total

    processes = (os.cpu_count() or 1) if args.processes is None else args.processes
    if processes < 1:
        raise ValueError(f"--processes {processes}: expected a number of processes >= 1")
    warmup(progress, processes=processes)
    bar.close()
    print(f"robodyn warmup: {count[0]} steps compiled or loaded from the cache in "
          f"{time.perf_counter() - start:.1f} s")
    return 0


def add_commands(sub) -> None:
    """Register ``info``, ``demo``, ``bench`` and ``warmup`` on the ``robodyn`` subcommand parser."""
    p = sub.add_parser("info", help="print the joint table, masses and inertias")
    add_model_arguments(p)
    p.add_argument("--list", action="store_true", help="list the built-in robots")
    p.set_defaults(func=cmd_info)
    p = sub.add_parser("demo", help="inverse/forward dynamics and mass matrix at a sample state")
    add_model_arguments(p, default="panda")
    p.add_argument("--seed", type=int, default=0)
    p.set_defaults(func=cmd_demo)
    p = sub.add_parser("bench", help="per-call timings (and the comparison with Pinocchio)")
    add_model_arguments(p, default="panda")
    p.add_argument("--batch", type=int, default=10000, help="batch size for the batched timings")
    p.add_argument("--no-compare", action="store_true", help="do not run Pinocchio even if installed")
    p.set_defaults(func=cmd_bench)
    p = sub.add_parser("warmup", help="compile (or load from the cache) every kernel now, with a progress bar")
    p.add_argument("--processes", type=int, default=None,
                   help="processes compiling at once on a first run (default: one per core)")
    p.set_defaults(func=cmd_warmup)
