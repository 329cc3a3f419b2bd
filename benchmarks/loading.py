"""Model loading: ``rd.load_urdf`` against Pinocchio's ``buildModelFromUrdf`` on large
example-robot-data robots (best of rounds, alternating), ``rd.load_mjcf`` on MuJoCo models
(against ``mujoco.MjModel.from_xml_path``, which also compiles collision data), and robodyn
alone on a generated chain of 5,000 links (Pinocchio's recursive URDF reader overflows the
stack on it).

    python benchmarks/loading.py [--rounds 15]
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
import warnings
from pathlib import Path

import robodyn as rd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare import erd_urdf  # noqa: E402

URDFS = ["icub_description/robots/icub.urdf", "talos_data/robots/talos_reduced.urdf",
         "talos_data/robots/talos_full_v2.urdf"]
MJCFS = ["gymnasium/envs/mujoco/assets/humanoid.xml", "dm_control/suite/humanoid_CMU.xml"]


def best_pair(a, b, rounds: int) -> tuple[float, float]:
    ta, tb = [], []
    for _ in range(rounds):
        for f, t in ((a, ta), (b, tb)):
            t0 = time.perf_counter()
            f()
            t.append(time.perf_counter() - t0)
    return min(ta), min(tb)


def chain(n: int) -> str:
    parts = ['<robot name="chain"><link name="l0"/>']
    for i in range(1, n + 1):
        parts.append(f'<link name="l{i}"><inertial><mass value="1"/><origin xyz="0 0 0.1"/><inertia ixx="0.01" '
                     'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>')
        parts.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
                     '<origin xyz="0 0 0.2" rpy="0 0 0.1"/><axis xyz="0 1 0"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return "".join(parts) + "</robot>"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=15)
    args = ap.parse_args()
    warnings.simplefilter("ignore", rd.RobodynWarning)
    import pinocchio as pin

    print(f"{'model':<48} {'robodyn ms':>11} {'other ms':>9} {'ratio':>6}")
    for rel in URDFS:
        path = erd_urdf(rel)
        t_rd, t_pin = best_pair(lambda: rd.load_urdf(path), lambda: pin.buildModelFromUrdf(path), args.rounds)
        print(f"{rel:<48} {t_rd * 1e3:>11.2f} {t_pin * 1e3:>9.2f} {t_rd / t_pin:>6.2f}")
    import mujoco

    for rel in MJCFS:
        pkg, sub = rel.split("/", 1)
        path = str(Path(next(iter(importlib.util.find_spec(pkg).submodule_search_locations))) / sub)
        t_rd, t_mj = best_pair(lambda: rd.load_mjcf(path), lambda: mujoco.MjModel.from_xml_path(path), args.rounds)
        print(f"{rel:<48} {t_rd * 1e3:>11.2f} {t_mj * 1e3:>9.2f} {t_rd / t_mj:>6.2f}")
    text = chain(5000)
    t = best_pair(lambda: rd.load_urdf(text), lambda: None, 3)[0]
    print(f"{'generated chain of 5,000 links (robodyn alone)':<48} {t * 1e3:>11.1f}")


if __name__ == "__main__":
    main()
