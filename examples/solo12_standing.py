"""Solo12 dropped onto the floor, standing under a joint PD: contact forces and friction cones.

    python examples/solo12_standing.py [--plot solo12_standing.png] [--urdf PATH]

The quadruped (example-robot-data's ``solo12.urdf``, floating base; ``pip install
example-robot-data`` or give ``--urdf``) starts with its feet 0.25 m above the ground, its
joints held at a standing posture by ``control.JointPD`` (the base unactuated). Each foot is
a sphere of radius 0.0175 m on the ground plane (Coulomb friction mu = 0.9). It falls, lands,
and settles: at rest the four normal forces carry its weight, every friction force lies
inside its cone, and the feet neither slide nor sink.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn import plots
from robodyn.contact import Contacts, Plane, Sphere
from robodyn.control import JointPD

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
STANCE = np.array([0, 0.8, -1.6] * 2 + [0, -0.8, 1.6] * 2)


def default_urdf() -> Path:
    """``solo12.urdf`` of the installed example-robot-data wheel."""
    for site in map(Path, sys.path):
        path = site / "cmeel.prefix/share/example-robot-data/robots/solo_description/robots/solo12.urdf"
        if path.is_file():
            return path
    raise SystemExit("solo12.urdf not found: pip install example-robot-data, or give --urdf PATH")


def run(urdf=None, duration: float = 2.0, dt: float = 1e-3):
    """``(model, trajectory)`` of the drop."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)  # the file's <contact> elements (PyBullet's)
        model = rd.load_urdf(urdf or default_urdf(), floating_base=True)
    q0 = np.concatenate([[0.0, 0.0, 0.5], [0.0, 0.0, 0.0, 1.0], STANCE])
    contacts = Contacts([Sphere(foot, 0.0175) for foot in FEET], surfaces=[Plane(friction=0.9)])
    controller = JointPD(model, q0, kp=8.0, kd=0.3)
    return model, rd.simulate(model, q0, np.zeros(model.nv), duration, dt, controller, contacts=contacts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", help="save the contact forces and cone usage to this image")
    parser.add_argument("--urdf", help="the Solo12 URDF (default: example-robot-data's)")
    args = parser.parse_args()
    model, traj = run(args.urdf)
    f = traj.normal_force[-1]
    print(f"base height {traj.q[-1, 2]:.4f} m; normal forces {np.round(f, 4).tolist()} N, sum {f.sum():.6f} N "
          f"(weight {model.total_mass * 9.81:.6f} N); friction/normal {np.round(traj.friction_force[-1] / f, 4)}")
    if args.plot:
        plots.plot_contacts(traj, args.plot)


if __name__ == "__main__":
    main()
