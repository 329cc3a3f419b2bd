"""Contact simulation against MuJoCo: Solo12 on the ground at 1 kHz, one process.

    python benchmarks/contacts.py [--seconds 2] [--rollouts 1000]

The same robot (the MJCF that ``rd.write_mjcf`` writes from example-robot-data's URDF, with a
sphere of radius 0.0175 m at each foot and a floor, MuJoCo's elliptic cones and Euler
integrator), the same joint PD about a standing posture (MuJoCo: position actuators with
``kp`` and ``kv``; robodyn: ``control.JointPD``, compiled), the same time step. Two phases:
the drop from 0.25 m (feet above the floor) and standing after settling. robodyn: one
``rd.simulate`` call per phase; MuJoCo: ``mujoco.rollout`` (its C loop, no Python per step).
Per-step times are the best of interleaved rounds. Then batched rollouts: ``--rollouts`` drops of 1 s
from random heights and yaw rates, ``rd.rollout`` (keeping the first and last samples) against
``mujoco.rollout`` with one ``MjData`` per thread (which keeps every state), throughput in
steps per second. Ratio: robodyn / MuJoCo time, below 1 robodyn is faster.

The two contact models differ (robodyn: rigid contacts, exact Coulomb cones; MuJoCo: soft
convex contacts), so the trajectories differ by the contact compliance; printed: the
settled base height and total normal force of each.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numba
import numpy as np

import robodyn as rd
from robodyn.contact import Contacts, Plane, Sphere
from robodyn.control import JointPD

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from conftest import example_robot_data_dir  # noqa: E402

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
RADIUS, MU, KP, KD, DT = 0.0175, 0.9, 8.0, 0.3, 1e-3
STANCE = np.array([0, 0.8, -1.6] * 2 + [0, -0.8, 1.6] * 2)


def solo():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_urdf(example_robot_data_dir() / "solo_description/robots/solo12.urdf", floating_base=True)


def mujoco_solo(model):
    """MuJoCo's model of the same robot: feet spheres, a floor, PD position actuators."""
    import mujoco

    with tempfile.TemporaryDirectory() as d:
        rd.write_mjcf(model, Path(d) / "solo.xml")
        xml = (Path(d) / "solo.xml").read_text()
    for foot in FEET:
        xml = re.sub(rf'<site name="{foot}" pos="([^"]*)"([^/]*)/>',
                     rf'<site name="{foot}" pos="\1"\2/><geom type="sphere" size="{RADIUS}" pos="\1" '
                     rf'friction="{MU} 0 0"/>', xml)
    xml = xml.replace("<worldbody>", f'<worldbody><geom type="plane" size="0 0 1" friction="{MU} 0 0"/>')
    xml = xml.replace('<option gravity="0.0 0.0 -9.81"/>',
                      f'<option gravity="0 0 -9.81" timestep="{DT}" cone="elliptic" integrator="Euler"/>')
    actuators = "".join(f'<position joint="{j}" kp="{KP}" kv="{KD}"/>' for j in model.joint_names)
    xml = xml.replace("</mujoco>", f"<actuator>{actuators}</actuator></mujoco>")
    return mujoco.MjModel.from_xml_string(xml)


def main() -> None:
    import mujoco
    from mujoco import rollout

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=2.0, help="simulated time per phase")
    p.add_argument("--rollouts", type=int, default=1000, help="batched rollouts (drops)")
    args = p.parse_args()
    n = int(round(args.seconds / DT))

    model = solo()
    contacts = Contacts([Sphere(f, RADIUS) for f in FEET], surfaces=[Plane(friction=MU)])
    q0 = np.concatenate([[0, 0, 0.5], [0, 0, 0, 1], STANCE])
    ctrl = JointPD(model, q0, KP, KD)
    mj = mujoco_solo(model)
    data = mujoco.MjData(mj)
    assert mj.nq == model.nq and mj.nu == 12 and mj.ngeom == 5

    def mj_state(q, v):
        mujoco.mj_resetData(mj, data)
        data.qpos[:] = rd.interop.mujoco.q_to_qpos(model, q)
        data.qvel[:] = rd.interop.mujoco.v_to_qvel(model, q, v)
        s = np.empty(mujoco.mj_stateSize(mj, mujoco.mjtState.mjSTATE_FULLPHYSICS))
        mujoco.mj_getState(mj, data, s, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        return s

    control = np.tile(STANCE, (1, n, 1))
    settled = rd.simulate(model, q0, np.zeros(model.nv), 1.5, DT, ctrl, contacts=contacts).q[-1]
    print(f"Solo12 ({model.nv} dofs, 4 foot contacts), dt = {DT:g} s, {n} steps per run; best of interleaved rounds")
    print(f"  {'phase':<10} {'robodyn us/step':>16} {'MuJoCo us/step':>15} {'ratio':>7}")
    for phase, q in (("drop", q0), ("standing", settled)):
        v = np.zeros(model.nv)
        s0 = mj_state(q, v)
        best = [np.inf, np.inf]
        for _ in range(7):
            t0 = time.perf_counter()
            traj = rd.simulate(model, q, v, args.seconds, DT, ctrl, contacts=contacts, progress=False)
            best[0] = min(best[0], (time.perf_counter() - t0) / n)
            t0 = time.perf_counter()
            state, _ = rollout.rollout(mj, data, s0, control)
            best[1] = min(best[1], (time.perf_counter() - t0) / n)
        print(f"  {phase:<10} {best[0] * 1e6:16.2f} {best[1] * 1e6:15.2f} {best[0] / best[1]:7.3g}")
    z_mj = state[0, -1, 1 + 2]  # mjSTATE_FULLPHYSICS: time, then qpos
    print(f"  settled base height: robodyn {traj.q[-1, 2]:.5f} m, MuJoCo {z_mj:.5f} m; robodyn's normal forces "
          f"sum to {traj.contact_force[-1, :, 2].sum():.6f} N (weight {model.total_mass * 9.81:.6f} N)")

    # Batched rollouts: drops from random heights and yaw rates, every state kept by neither
    rng = np.random.default_rng(0)
    B = args.rollouts
    Q0 = np.tile(q0, (B, 1))
    Q0[:, 2] += rng.uniform(-0.05, 0.05, B)
    V0 = np.zeros((B, model.nv))
    V0[:, 5] = rng.uniform(-1.0, 1.0, B)
    S0 = np.stack([mj_state(q, v) for q, v in zip(Q0, V0)])
    threads = numba.get_num_threads()
    datas = [mujoco.MjData(mj) for _ in range(threads)]
    best, m = [np.inf, np.inf], int(round(1.0 / DT))  # drops of 1 s
    for _ in range(3):
        t0 = time.perf_counter()
        rd.rollout(model, Q0, V0, m * DT, DT, ctrl, contacts=contacts, every=m)
        best[0] = min(best[0], time.perf_counter() - t0)
        t0 = time.perf_counter()
        for k in range(0, B, 100):  # in pieces: MuJoCo keeps every state (0.5 GB for all at once)
            rollout.rollout(mj, datas, S0[k:k + 100], np.tile(STANCE, (min(100, B - k), m, 1)))
        best[1] = min(best[1], time.perf_counter() - t0)
    steps = B * m
    print(f"\n{B} rollouts of {m} steps on {threads} threads (rd.rollout, mujoco.rollout with {threads} MjData)")
    print(f"  {'':<10} {'robodyn steps/s':>16} {'MuJoCo steps/s':>15} {'ratio':>7}")
    print(f"  {'rollouts':<10} {steps / best[0]:16.0f} {steps / best[1]:15.0f} {best[0] / best[1]:7.3g}")



if __name__ == "__main__":
    main()
