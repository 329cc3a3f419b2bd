"""Timings of hybrid dynamics, the inverse mass matrix, constrained and task-space dynamics.

    python benchmarks/dynamics_extras.py

Robots: Panda (fixed base) and Talos reduced (floating base) from example-robot-data.
Single calls from Python, per-state time of a batch of 10,000 states, and the reference each
is compared with: ``aba`` for ``hybrid_dynamics`` (half the joints with known acceleration),
Pinocchio's ``computeMinverse`` for ``inverse_mass_matrix`` (and ``numpy.linalg.inv`` of
``crba``); ``constrained_dynamics`` with one point constraint on the last body and
``task_space_dynamics`` of the last body have no equivalent call elsewhere. Prints
microseconds per call; the ratio is robodyn / other (below 1: robodyn is faster).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.bench import Timing, format_table, per_call_us

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare import load_pair  # noqa: E402


def section(name: str, relpath: str, floating: bool, batch: int = 10000) -> str:
    import pinocchio as pin

    model, pm = load_pair(name, relpath, floating)
    data = pm.createData()
    rng = np.random.default_rng(0)
    q, v, a = rd.random.random_state(model, rng)
    Q, V, A = rd.random.random_state(model, rng, batch)
    mask = np.arange(model.nv) >= model.nv - (model.nv - (6 if floating else 0)) // 2
    last = model.link_names[-1]
    hold = rd.PointConstraint(last, (0, 0, 0), rd.frame_pose(model, q, last)[:3, 3])
    rows = [
        Timing("hybrid_dynamics / aba", per_call_us(lambda: rd.hybrid_dynamics(model, q, v, a, a, mask)),
               per_call_us(lambda: rd.aba(model, q, v, a))),
        Timing("hybrid (batch) / aba", per_call_us(lambda: rd.hybrid_dynamics(model, Q, V, A, A, mask)) / batch,
               per_call_us(lambda: rd.aba(model, Q, V, A)) / batch),
        Timing("inverse_mass_matrix / pin", per_call_us(lambda: rd.inverse_mass_matrix(model, q)),
               per_call_us(lambda: pin.computeMinverse(pm, data, q))),
        Timing("inverse_mass_matrix / inv", per_call_us(lambda: rd.inverse_mass_matrix(model, q)),
               per_call_us(lambda: np.linalg.inv(rd.crba(model, q)))),
        Timing("Minv (batch) / pin loop", per_call_us(lambda: rd.inverse_mass_matrix(model, Q[:1000])) / 1000,
               per_call_us(lambda: [pin.computeMinverse(pm, data, x) for x in Q[:1000]]) / 1000),
        Timing("constrained_dynamics", per_call_us(lambda: rd.constrained_dynamics(model, q, v, a, [hold]))),
        Timing("task_space_dynamics", per_call_us(lambda: rd.task_space_dynamics(model, q, v, last))),
    ]
    head = f"### {name} ({'floating' if floating else 'fixed'} base, nv = {model.nv}), Pinocchio {pin.__version__}\n"
    return head + "\n```\n" + format_table(rows, "other") + "\n```\n"


def main() -> None:
    print(section("Panda", "panda_description/urdf/panda.urdf", False))
    print(section("Talos reduced", "talos_data/robots/talos_reduced.urdf", True))


if __name__ == "__main__":
    main()
