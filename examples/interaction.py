"""Interaction control on the Panda against a wall: impedance and hybrid force/position.

    python examples/interaction.py [--plot examples/interaction.png]

1. Impedance: the hand (a 2 cm sphere on link7) is held by a Cartesian spring about a point
   2 cm behind a wall (friction 0.2). It presses on the wall with the spring's force,
   ``K * 2 cm`` minus nothing else at rest: 16 N for K = 800 N/m.
2. Hybrid force/position: the hand pushes 10 N into the wall and slides 5 cm along it.
3. The constrained-manipulator formulation (MLS ch. 4, 5.3): a planar arm whose tool a rod
   holds on a circle follows a path along it while the rod force tracks a varying command.

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


L1, L2, ANCHOR, RADIUS = 0.8, 0.6, np.array([1.0, 0.0, 0.0]), 0.4


def planar_arm():
    b = rd.ModelBuilder("planar-2r", gravity=(0.0, -9.81, 0.0))
    b.add_link("base")
    for name, m, L in (("rod1", 3.0, L1), ("rod2", 2.0, L2)):
        b.add_link(name, mass=m, com=(L / 2, 0, 0), inertia=np.diag([0.0, m * L * L / 12, m * L * L / 12]))
    b.add_joint("shoulder", "revolute", "base", "rod1", axis=(0, 0, 1))
    b.add_joint("elbow", "revolute", "rod1", "rod2", xyz=(L1, 0, 0), axis=(0, 0, 1))
    return b.build()


def on_circle(s, sd=0.0, sdd=0.0):
    """Joint position, velocity and acceleration putting the tool at angle ``s`` on the circle
    (elbow-down inverse kinematics, rates through the Jacobian)."""
    u, du = np.array([np.cos(s), np.sin(s)]), np.array([-np.sin(s), np.cos(s)])
    p = ANCHOR[:2] + RADIUS * u
    c2 = (p @ p - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    q2 = -np.arccos(np.clip(c2, -1, 1))
    q = np.array([np.arctan2(p[1], p[0]) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2)), q2])

    def jac(q):
        s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q.sum()), np.cos(q.sum())
        return np.array([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])

    qd = np.linalg.solve(jac(q), RADIUS * du * sd)
    Jdot = (jac(q + 1e-6 * qd) - jac(q - 1e-6 * qd)) / 2e-6
    return q, qd, np.linalg.solve(jac(q), RADIUS * (du * sdd - u * sd * sd) - Jdot @ qd)


def constrained(duration: float = 3.0):
    """The tool held on a circle by a rod, moving along it, the rod force commanded."""
    model = planar_arm()
    rod = rd.DistanceConstraint("rod2", (L2, 0.0, 0.0), None, ANCHOR, RADIUS)

    def reference(t):
        return on_circle(2.4 + 0.4 * np.sin(t), 0.4 * np.cos(t), -0.4 * np.sin(t))

    def force(t):
        return np.array([-8.0 + 3.0 * np.sin(2 * t)])  # tension in the rod

    ctrl = control.ConstrainedForcePosition(model, rod, reference, force, kp=100.0, kd=20.0)
    traj = rd.simulate(model, on_circle(2.3)[0], np.zeros(2), duration, 2e-3, controller=ctrl, constraints=[rod])
    return traj, force


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
    held, force = constrained()
    wanted = np.array([force(t)[0] for t in held.t])
    print(f"constrained: rod force within {np.abs(held.constraint_force[:, 0] - wanted).max():.1e} N of the command")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        y = np.array([rd.frame_pose(model, q, "link7")[1, 3] for q in slide.q]) - x0[1]
        fig, ax = plt.subplots(1, 4, figsize=(17, 3.4))
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
        ax[3].plot(held.t, held.constraint_force[:, 0], label="rod force")
        ax[3].plot(held.t, wanted, ls="--", c="k", label="commanded")
        ax[3].set(title="constrained arm: force along the rod", xlabel="t [s]", ylabel="N")
        for a in ax:
            a.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=90)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
