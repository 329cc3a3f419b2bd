"""Load (or compile) every kernel ahead of time, for services that must answer at once.

``robodyn.warmup()`` (and ``robodyn warmup`` on the command line) runs each public function
with compiled code once on a small model, single state and batch, fixed and floating base,
then a short simulation of each kind (uncontrolled, compiled controllers, Python controllers).
Compiled code is cached on disk, so after the first process this only loads it (about a
second); on a fresh install the first process compiles everything (about four minutes on
one core, two on two with ``processes=2``; see ``benchmarks/RESULTS.md``).
"""

from __future__ import annotations

import numpy as np


def _revolute_model():
    """A built-in robot of revolute joints only (inertia_bounds takes no other)."""
    from .models import load

    return load("pendulum")


def _algorithm_steps(rd, model, q, v, a):
    """``(name, call)`` of every public algorithm with compiled kernels, at state ``(q, v, a)``."""
    last = model.nbodies - 1
    known = np.arange(model.nv) == model.nv - 1
    point = rd.PointConstraint(last, np.zeros(3), np.zeros(3))
    return [
        ("rnea", lambda: rd.rnea(model, q, v, a)),
        ("aba", lambda: rd.aba(model, q, v, a)),
        ("crba", lambda: rd.crba(model, q)),
        ("coriolis_matrix", lambda: rd.coriolis_matrix(model, q, v)),
        ("christoffel_symbols", lambda: rd.christoffel_symbols(model, q)),
        ("gravity", lambda: rd.gravity(model, q)),
        ("nonlinear_effects", lambda: rd.nonlinear_effects(model, q, v)),
        ("generalized_momentum", lambda: rd.generalized_momentum(model, q, v)),
        ("kinetic_energy", lambda: rd.kinetic_energy(model, q, v)),
        ("potential_energy", lambda: rd.potential_energy(model, q)),
        ("center_of_mass", lambda: rd.center_of_mass(model, q)),
        ("com_jacobian", lambda: rd.com_jacobian(model, q)),
        ("jacobian", lambda: rd.jacobian(model, q, last)),
        ("jacobian_dot_times_v", lambda: rd.jacobian_dot_times_v(model, q, v, last)),
        ("mass_matrix_from_jacobians", lambda: rd.mass_matrix_from_jacobians(model, q)),
        ("inertia_bounds", lambda: rd.inertia_bounds(_revolute_model(), max_boxes=3)),
        ("frame_velocity_derivatives", lambda: rd.frame_velocity_derivatives(model, q, v, last)),
        ("frame_acceleration_derivatives", lambda: rd.frame_acceleration_derivatives(model, q, v, a, last)),
        ("forward_kinematics", lambda: rd.forward_kinematics(model, q)),
        ("frame_pose", lambda: rd.frame_pose(model, q, model.link_names[last])),
        ("integrate", lambda: rd.integrate(model, q, v)),
        ("difference", lambda: rd.difference(model, q, q)),
        ("integrate_jacobians", lambda: rd.integrate_jacobians(model, q, v)),
        ("difference_jacobians", lambda: rd.difference_jacobians(model, q, q)),
        ("hybrid_dynamics", lambda: rd.hybrid_dynamics(model, q, v, a, a, known)),
        ("inverse_mass_matrix", lambda: rd.inverse_mass_matrix(model, q)),
        ("rnea_derivatives", lambda: rd.rnea_derivatives(model, q, v, a)),
        ("rnea_second_derivatives", lambda: rd.rnea_second_derivatives(model, q, v, a)),
        ("aba_derivatives", lambda: rd.aba_derivatives(model, q, v, a)),
        ("gravity_derivatives", lambda: rd.gravity_derivatives(model, q)),
        ("nonlinear_effects_derivatives", lambda: rd.nonlinear_effects_derivatives(model, q, v)),
        ("generalized_momentum_derivatives", lambda: rd.generalized_momentum_derivatives(model, q, v)),
        ("constrained_dynamics", lambda: rd.constrained_dynamics(model, q, v, a, [point])),
        ("constrained_dynamics_derivatives", lambda: rd.constrained_dynamics_derivatives(model, q, v, a, [point])),
        ("task_space_inertia", lambda: rd.task_space_inertia(model, q, last, rows="linear")),
        ("dynamically_consistent_inverse", lambda: rd.dynamically_consistent_inverse(model, q, last, rows="linear")),
        ("task_space_dynamics", lambda: rd.task_space_dynamics(model, q, v, last, rows="linear")),
        ("regressor", lambda: rd.regressor(model, q, v, a)),
        ("slotine_li_regressor", lambda: rd.slotine_li_regressor(model, q, v, v, a)),
        ("kinetic_energy_regressor", lambda: rd.kinetic_energy_regressor(model, q, v)),
        ("potential_energy_regressor", lambda: rd.potential_energy_regressor(model, q)),
    ]


def _simulation_steps(rd, model):
    """``(name, call)`` of short simulations that compile every simulation kernel: the compiled
    runs (no controller, PD with gravity compensation, computed torque; both fixed-step
    integrators) and the Python-driven stages (a controller in Python, task-space PD), with
    and without contacts."""
    from . import control
    from .contact import Contacts, Plane, Sphere
    from .joints import NV
    from .random import random_configuration

    q0, v0 = random_configuration(model, np.random.default_rng(0)), np.zeros(model.nv)
    pd = control.PDGravity(model, q0, kp=10.0, kd=2.0)
    ct = control.ComputedTorque(model, control.PointToPoint(q0, q0, 0.01), kp=10.0, kd=2.0)
    task = control.TaskSpacePD(model, model.link_names[-1], np.zeros(3), kp=10.0, kd=2.0)

    def python_law(t, q, v):
        return -v

    run = [("simulate", None, "rk4"), ("simulate (semi-implicit Euler)", None, "semi_implicit_euler"),
           ("simulate (PDGravity)", pd, "rk4"), ("simulate (ComputedTorque)", ct, "rk4"),
           ("simulate (Python controller)", python_law, "rk4"), ("simulate (TaskSpacePD)", task, "rk4")]
    out = [(name, lambda c=c, i=i: rd.simulate(model, q0, v0, 0.004, 0.002, c, i, progress=False))
           for name, c, i in run]
    touch = Contacts([Sphere(model.nbodies - 1, 0.05)], surfaces=[Plane(height=10.0)])  # in contact from the start
    one = [name for name, t in zip(model.body_joint_names, model.joint_type) if NV[t] == 1]
    coupled = rd.CoupledModel(model, [(one[-1], one[0], 1.0, 0.0)])
    qc = random_configuration(coupled, np.random.default_rng(0))
    return out + [(name, lambda c=c: rd.simulate(model, q0, v0, 0.004, 0.002, c, contacts=touch, progress=False))
                  for name, c in (("simulate (contacts)", None), ("simulate (contacts, Python controller)",
                                                                   python_law))] + [
        ("simulate (contacts, mimic couplings)",
         lambda: rd.simulate(coupled, qc, np.zeros(coupled.nv), 0.004, 0.002, contacts=touch, progress=False)),
        ("rollout (contacts)", lambda: rd.rollout(model, np.stack([q0, q0]), v0, 0.004, 0.002, pd, contacts=touch)),
        ("rollout (contacts, mimic couplings)",
         lambda: rd.rollout(coupled, np.stack([qc, qc]), np.zeros(coupled.nv), 0.004, 0.002, contacts=touch))]


def _public():
    """The public functions and classes used here, by their names in ``robodyn``."""
    from types import ModuleType, SimpleNamespace

    from . import random
    from .algorithms import (aba, aba_derivatives, com, constrained, constrained_derivatives, coriolis, crba,
                             energy, frame_derivatives, hybrid, inertia_bounds, integrate, jacobian, kinematics,
                             mass_jacobians, minv, regressor, rnea, rnea_derivatives, rnea_second_derivatives,
                             task_space, terms)
    from .coupling import CoupledModel
    from .simulation import rollout, simulate

    names = {}
    for module in (aba, aba_derivatives, com, constrained, constrained_derivatives, coriolis, crba, energy,
                   frame_derivatives, hybrid,
                   inertia_bounds, integrate, jacobian, kinematics, mass_jacobians, minv, regressor, rnea,
                   rnea_derivatives, rnea_second_derivatives, task_space, terms):
        names.update({n: getattr(module, n) for n in dir(module)
                      if not n.startswith("_") and not isinstance(getattr(module, n), ModuleType)})
    return SimpleNamespace(**names, simulate=simulate, rollout=rollout, random=random, CoupledModel=CoupledModel)


def steps():
    """Every warm-up step as ``(name, call)``, in order: the algorithms on a fixed-base and a
    floating-base model, one state and a batch of two, the paths of a model with mimic
    couplings, then the simulations."""
    from .random import random_model, random_state

    rd = _public()

    out = []
    for floating in (False, True):
        model = random_model(6, seed=0, floating_base=floating, branching=0.0)
        for size in ((), (2,)):
            q, v, a = random_state(model, np.random.default_rng(0), size)
            label = f"{'floating' if floating else 'fixed'} base, {'batch' if size else 'one state'}"
            out += [(f"{name} ({label})", call) for name, call in _algorithm_steps(rd, model, q, v, a)]
    out += _coupled_steps(rd, random_model(6, seed=0, floating_base=True, branching=0.0))
    out += _simulation_steps(rd, random_model(6, seed=0, floating_base=False, branching=0.0))
    return out


def _coupled_steps(rd, model):
    """The compiled paths of a model with mimic couplings (``rnea``, ``crba``, ``aba``: one
    state and a batch of two)."""
    from .joints import NV
    from .random import random_state

    one = [name for name, t in zip(model.body_joint_names, model.joint_type) if NV[t] == 1]
    coupled = rd.CoupledModel(model, [(one[-1], one[0], 1.0, 0.0)])
    out = []
    for size in ((), (2,)):
        q, v, a = random_state(coupled, np.random.default_rng(0), size)
        label = f"mimic couplings, {'batch' if size else 'one state'}"
        out += [(f"rnea ({label})", lambda q=q, v=v, a=a: rd.rnea(coupled, q, v, a)),
                (f"crba ({label})", lambda q=q: rd.crba(coupled, q)),
                (f"aba ({label})", lambda q=q, v=v, a=a: rd.aba(coupled, q, v, a))]
    return out


def warmup(progress=None, only=None, processes: int = 1) -> None:
    """Compile or load every kernel: each public algorithm (single and batched calls, fixed and
    floating base) and the simulation kernels.

    ``progress``: None (silent), or a callable ``progress(done, total, name)`` called before
    each step and once at the end (``name`` empty), e.g. to draw a progress bar.
    ``only``: None (everything), or the names of the functions to compile (``["rnea",
    "aba"]``: their steps alone, e.g. on the workers of a cluster that run only those).
    ``processes``: how many processes compile at once (a first run on a machine of several
    cores): the steps run here while the cache has their code; from the first that needed
    compiling (the helpers it shares with the others compiled with it), each process takes
    the next group of the steps after it (a function's, or the simulations with contacts,
    the longest, first) and compiles it into the shared on-disk cache, ``progress`` called as
    groups start; then this process loads them (a few seconds). 1: all here.
    """
    if isinstance(processes, bool) or not isinstance(processes, (int, np.integer)) or processes < 1:
        raise ValueError(f"processes: expected an integer >= 1, got {processes!r}")
    todo = steps()
    if only is not None:
        only = {only} if isinstance(only, str) else set(only)
        unknown = only - {name.split(" ")[0] for name, _ in todo}
        if unknown:
            raise ValueError(f"only: no warm-up step for {sorted(unknown)}")
        todo = [(name, call) for name, call in todo if name.split(" ")[0] in only]
    n, report, watch = len(todo), progress, processes > 1
    for k, (name, call) in enumerate(todo):
        if report is not None:
            report(k, n, name)
        if not watch:
            call()
        elif _compiles(call) and k + 1 < n:  # not in the cache: a first run, the others in processes
            _compile_in_processes([name for name, _ in todo[k + 1:]], int(processes), progress, k + 1, n)
            report = watch = None  # the rest is loaded from the cache
    if progress is not None:
        progress(n, n, "")


def _compiles(call) -> bool:
    """Runs ``call``; whether Numba compiled anything for it (else this process or the cache
    had it all: a filled cache is loaded faster here than by new processes)."""
    from numba.core import event

    with event.install_recorder("numba:compile") as compiled:
        call()
    return bool(compiled.buffer)


def _groups(names: list[str]) -> list[list[str]]:
    """The steps in groups that one process compiles: a function's steps together (they share
    its kernels), the simulations with contacts together and first (the longest compilation;
    the tree's and the coupled model's share the contact solver and the dynamics terms, which
    two processes would compile at once), then the other simulations (the next longest), then
    the algorithms in order: the short groups last, so that the processes finish together."""
    groups: dict[str, list[str]] = {}
    for name in names:
        key = "contacts" if "contacts" in name else name.split(" (")[0]
        groups.setdefault(key, []).append(name)
    return sorted(groups.values(), key=lambda g: ("contacts" not in g[0], g[0].split(" (")[0] != "simulate"))


SERVE = "from robodyn._warmup import _serve; _serve()"


def _serve() -> None:
    """A compiling process of :func:`_compile_in_processes`: runs each group of steps named on
    a line of stdin (JSON), then prints ``done``; stops at the end of stdin."""
    import json
    import sys

    calls = dict(steps())
    for line in sys.stdin:
        for name in json.loads(line):
            calls[name]()
        print("done", flush=True)


def _compile_in_processes(names: list[str], processes: int, progress, done: int = 0, total: int | None = None):
    """Compile the steps ``names`` in ``processes`` child processes (see :func:`warmup`), each
    handed the next group when it has finished one, ``progress(done, total, name)`` as a group
    starts (``done`` counting from the given, of ``total`` steps, default ``len(names)``);
    raises if one of them fails (what the others compiled stays in the cache)."""
    import json
    import queue
    import subprocess
    import sys
    import tempfile
    import threading

    todo, total = _groups(names), len(names) if total is None else total
    events: queue.Queue = queue.Queue()
    children, running, finished = {}, {}, False
    for _ in range(min(processes, len(todo))):
        err = tempfile.TemporaryFile("w+")
        child = subprocess.Popen([sys.executable, "-c", SERVE], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                 stderr=err, text=True)
        children[child] = err
        threading.Thread(target=_relay, args=(child, events), daemon=True).start()

    def hand_out(child):
        if todo:
            running[child] = todo.pop(0)
            if progress is not None:
                progress(done, total, running[child][0])
            child.stdin.write(json.dumps(running[child]) + "\n")
            child.stdin.flush()
        else:
            running.pop(child, None)
            child.stdin.close()  # the child ends

    try:
        for child in children:
            hand_out(child)
        while running:
            child, line = events.get()
            if child not in running or line not in (None, "done\n"):  # a child without work, ending; other output
                continue
            if line is None:  # the child ended before its group was done
                raise RuntimeError(f"warmup: the process compiling {running[child][0]!r} stopped (exit code "
                                   f"{child.wait()}): {_tail(children[child])}")
            done += len(running[child])
            hand_out(child)
        finished = True
    finally:
        for child, err in children.items():
            if not finished:
                child.kill()
            child.wait()
            if not child.stdin.closed:
                child.stdin.close()
            err.close()


def _relay(child, events) -> None:
    """Puts ``(child, line)`` for each line the child prints, then ``(child, None)``."""
    with child.stdout:
        for line in child.stdout:
            events.put((child, line))
    events.put((child, None))


def _tail(err, lines: int = 5) -> str:
    """The last ``lines`` lines a child wrote to its stderr file."""
    err.seek(0)
    return " | ".join(err.read().strip().splitlines()[-lines:]) or "no message"
