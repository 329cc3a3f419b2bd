"""Interaction control on the Panda against a wall: impedance and hybrid force/position.

    python examples/interaction.py [--plot examples/interaction.png]

1. Impedance: the hand (a 2 cm sphere on link7) is held by a Cartesian spring about a point
   2 cm behind a wall (friction 0.2). It presses on the wall with the spring's force,
   ``K * 2 cm`` minus nothing else at rest: 16 N for K = 800 N/m.
2. Hybrid force/position: the hand pushes 10 N into the wall and slides 5 cm along it.

Prints and plots the normal contact force against its target and the hand's path; the
figure is in the README.
"""

from __future__ import annotations

import argparse

import numpy as np

import robodyn as rd
from robodyn import control
from robodyn.contact import Contacts, Plane, Sphere

Q0 = np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.1, 0.8])
RADIUS, NORMAL = 0.02, np.array([-1.0, 0.0, 0.0])


def scene(model):
    x0 = rd.frame_pose(model, Q0, "link7")[:3, 3]
    wall = Plane(normal=NORMAL, height=-(x0[0] + RADIUS + 0.002), friction=0.2)  # 2 mm in front of the hand
    return x0, Contacts([Sphere("link7", RADIUS)], surfaces=[wall])


def run(duration: float = 3.0):
    model = rd.models.load("panda").rigid()
    x0, contacts = scene(model)
    K = 800.0
    target = x0 + [0.02 + 0.002, 0.0, 0.0]  # 2 cm into the wall
    impedance = control.CartesianImpedance(model, "link7", target, stiffness=K, damping=80.0, joint_damping=2.0)
    soft = rd.simulate(model, Q0, np.zeros(7), duration, 1e-3, controller=impedance, contacts=contacts)

    def path(t):
        return x0 + [0.0, 0.05 * np.clip((t - 0.5) / 2.0, 0.0, 1.0), 0.0]

    hybrid = control.HybridForcePosition(model, "link7", NORMAL, 10.0, path, stiffness=800.0, damping=80.0,
                                         normal_damping=40.0, joint_damping=2.0)
    slide = rd.simulate(model, Q0, np.zeros(7), duration, 1e-3, controller=hybrid, contacts=contacts)
    return model, x0, K, soft, slide, path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", help="PNG of the contact forces and the hand's path")
    args = parser.parse_args()
    model, x0, K, soft, slide, path = run()
    expected = K * 0.02
    print(f"impedance: normal force at rest {soft.normal_force[-1, 0]:.3f} N (spring K * 2 cm = {expected:.3f} N)")
    sliding = slide.t > 0.7
    print(f"hybrid: normal force while sliding {slide.normal_force[sliding, 0].min():.3f}-"
          f"{slide.normal_force[sliding, 0].max():.3f} N (target 10 N)")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        y = np.array([rd.frame_pose(model, q, "link7")[1, 3] for q in slide.q]) - x0[1]
        fig, ax = plt.subplots(1, 3, figsize=(13, 3.4))
        ax[0].plot(soft.t, soft.normal_force[:, 0], label="normal force")
        ax[0].axhline(expected, ls="--", c="k", label="K * 2 cm")
        ax[0].set(title="impedance against the wall (impact clipped)", xlabel="t [s]", ylabel="N",
                  ylim=(0, 2.5 * expected))
        ax[1].plot(slide.t, slide.normal_force[:, 0], label="normal force")
        ax[1].axhline(10.0, ls="--", c="k", label="commanded")
        ax[1].set(title="hybrid: force while sliding", xlabel="t [s]", ylabel="N", ylim=(0, 15))
        ax[2].plot(slide.t, 100 * y, label="hand")
        ax[2].plot(slide.t, [100 * (path(t)[1] - x0[1]) for t in slide.t], ls="--", c="k", label="path")
        ax[2].set(title="hybrid: position along the wall", xlabel="t [s]", ylabel="cm")
        for a in ax:
            a.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=90)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
