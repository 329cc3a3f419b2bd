"""Cold start: how long the first call of each algorithm takes on a fresh install.

Runs a child process with an empty Numba cache directory (``NUMBA_CACHE_DIR`` set to a new
temporary directory, so the caches of this installation are left alone) and times, in order:
``import robodyn``, the first single-state and the first batched call of ``rnea``, ``aba``,
``crba`` and ``coriolis_matrix``, then ``rd.warmup()`` for everything else. A second child
process with the same cache directory then shows the cost of a later start. The simulation
kernels can be timed by name too: ``simulate`` (with contacts), ``rollout`` (with contacts,
under ``JointPD``) and ``coupled_rollout`` (the same with a mimic coupling), in the order given.

    python benchmarks/cold_start.py            # all of it (a few minutes)
    python benchmarks/cold_start.py rnea aba   # only these algorithms, no warmup
    python benchmarks/cold_start.py rollout    # the first contact rollout alone
    python benchmarks/cold_start.py warmup-processes   # everything, one compiling process per core
"""

import os
import subprocess
import sys
import tempfile

CHILD = r"""
import sys, time
t0 = time.perf_counter()
import numpy as np
import robodyn as rd
from robodyn.random import random_model, random_state
total = time.perf_counter() - t0
print(f"  {'import robodyn':<34} {total:8.2f} s  (total {total:7.2f} s)", flush=True)
which = sys.argv[1:]
model = random_model(3, seed=0, floating_base=True)
q, v, a = random_state(model, np.random.default_rng(0), ())
Q, V, A = random_state(model, np.random.default_rng(0), (4,))
args = {"rnea": (q, v, a), "aba": (q, v, a), "crba": (q,), "coriolis_matrix": (q, v)}
batch = {"rnea": (Q, V, A), "aba": (Q, V, A), "crba": (Q,), "coriolis_matrix": (Q, V)}

def timed(label, f):
    global total
    t = time.perf_counter()
    f()
    dt = time.perf_counter() - t
    total += dt
    print(f"  {label:<34} {dt:8.2f} s  (total {total:7.2f} s)", flush=True)

def touching():  # every body's sphere below the plane: in contact from the start
    from robodyn.contact import Contacts, Plane, Sphere
    return Contacts([Sphere(i, 0.05) for i in range(model.nbodies)], surfaces=[Plane(height=10.0)])

def coupled_rollout():
    from robodyn.control import JointPD
    coupled = rd.CoupledModel(model, [(model.body_joint_names[-1], model.body_joint_names[-2], 1.0, 0.0)])
    qc = q[coupled.independent_q]
    rd.rollout(coupled, np.stack([qc, qc]), np.zeros(coupled.nv), 0.004, 0.002, JointPD(coupled, qc, 10.0, 2.0),
               contacts=touching())

def rollout():
    from robodyn.control import JointPD
    rd.rollout(model, np.stack([q, q]), v, 0.004, 0.002, JointPD(model, q, 10.0, 2.0), contacts=touching())

sims = {"simulate": lambda: rd.simulate(model, q, v, 0.004, 0.002, contacts=touching(), progress=False),
        "rollout": rollout, "coupled_rollout": coupled_rollout}

for name in which:
    if name in sims:
        timed(name + " (contacts)", sims[name])
        continue
    if name == "warmup":
        timed("rd.warmup() (everything else)", rd.warmup)
        continue
    if name == "warmup-processes":  # one compiling process per core
        import os
        timed(f"rd.warmup(processes={os.cpu_count()})", lambda: rd.warmup(processes=os.cpu_count()))
        continue
    timed(name + ", one state", lambda: getattr(rd, name)(model, *args[name]))
    timed(name + ", batch of 4", lambda: getattr(rd, name)(model, *batch[name]))
"""


def run(names, cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    subprocess.run([sys.executable, "-c", CHILD, *names], env=env, check=True)


def main():
    names = sys.argv[1:] or ["rnea", "aba", "crba", "coriolis_matrix", "warmup"]
    with tempfile.TemporaryDirectory() as cache:
        print("first start (empty cache):", flush=True)
        run(names, cache)
        print("second start (cache filled):", flush=True)
        run(names, cache)


if __name__ == "__main__":
    main()
