"""Actuators and joint non-linearities: a DC motor's step response, an elastic joint under
Tomei's regulator, gear backlash, and stiction against the smooth friction law.

    python examples/actuators.py [--plot examples/actuators.png]

1. A geared DC motor on a rotor, 12 V applied: the current jumps with the electrical time
   constant ``L / R`` and decays as the rotor reaches its no-load speed ``V / (k_e N)``.
2. The double pendulum with elastic joints, regulated by Tomei's motor PD with gravity
   compensation: link and motor angles (the springs' twist holds the links up).
3. The same with gear backlash: the plain regulator leaves the link off by the gap, the one
   that crosses the gap on the loaded side brings it to the set point.
4. A pendulum whose joint has static friction just above the gravity torque: the exact
   (set-valued) law holds it, the smooth ``tanh`` law lets it creep.

Prints the figures the tests check and writes the figure of the README.
"""

from __future__ import annotations

import argparse

import numpy as np

import robodyn as rd
from robodyn import actuators


def rotor():
    b = rd.ModelBuilder("rotor")
    b.add_link("disk", mass=1.0, inertia=np.diag([0.01, 0.01, 0.02]))
    b.add_joint("shaft", "revolute", "world", "disk", axis=(0, 0, 1))
    return b.build()


def pendulum(m=2.0, L=0.7):
    b = rd.ModelBuilder("pendulum")
    b.add_link("base")
    b.add_link("bob", mass=m, com=(0.0, 0.0, L))
    b.add_joint("hinge", "revolute", "base", "bob", axis=(0, 1, 0))
    return b.build()


def run():
    out = {}
    motor = actuators.DCMotor(torque_constant=0.05, back_emf=0.05, resistance=2.0, inductance=2e-3, gear_ratio=10.0)
    plant = motor.plant(rotor())
    drive = actuators.VoltageDrive(plant, motor, lambda t, q, v: np.array([12.0]))
    out["motor"] = rd.simulate(plant, [0.0], [0.0], 0.6, 1e-4, controller=drive, integrator="Radau")

    model = rd.models.load("double_pendulum")
    K, B, gap = 300.0, np.array([0.05, 0.05]), np.array([0.05, 0.02])
    q0, q_d = np.array([0.6, -0.3]), np.array([0.3, 0.2])
    tomei = actuators.motor_pd_gravity(model, q_d, K, 500.0, 20.0)
    elastic = actuators.FlexibleJoints(model, K, B, tomei, damping=10.0, theta0=q0)
    out["elastic"] = rd.simulate(model, q0, np.zeros(2), 6.0, 2e-3, controller=elastic, integrator="rk4")
    for name, law in (("plain", tomei), ("crossed", actuators.motor_pd_gravity(model, q_d, K, 500.0, 20.0, gap))):
        joints = actuators.FlexibleJoints(model, K, B, law, damping=10.0, backlash=gap, theta0=q0)
        out[name] = rd.simulate(model, q0, np.zeros(2), 6.0, 2e-3, controller=joints, integrator="rk4")

    m, L, q_start = 2.0, 0.7, 0.3
    hold = 1.1 * m * 9.81 * L * np.sin(q_start)
    sticky = pendulum(m, L).replace(coulomb=[hold])
    out["exact"] = rd.simulate(sticky, [q_start], [0.0], 3.0, 1e-3, stiction=True)
    out["smooth"] = rd.simulate(sticky.replace(coulomb_smoothing=0.01), [q_start], [0.0], 3.0, 1e-3)
    return out, q_d, gap


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", help="PNG of the four runs")
    args = parser.parse_args()
    out, q_d, gap = run()
    speed = out["motor"].v[-1, 0]
    print(f"DC motor: speed {speed:.3f} rad/s after 0.6 s (no-load V / (k_e N) = {12.0 / (0.05 * 10):.3f})")
    print(f"elastic joints: link error {np.abs(out['elastic'].q[-1] - q_d).max():.2e} rad after 6 s")
    print(f"backlash: link error {np.abs(out['plain'].q[-1] - q_d).max():.4f} rad with the plain set point, "
          f"{np.abs(out['crossed'].q[-1] - q_d).max():.2e} rad with the gap crossed (gap {gap.tolist()} rad)")
    print(f"stiction: exact law moved {abs(out['exact'].q[-1, 0] - 0.3):.1e} rad, smooth law "
          f"{abs(out['smooth'].q[-1, 0] - 0.3):.3f} rad in 3 s")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(1, 4, figsize=(16, 3.4))
        run_ = out["motor"]
        ax[0].plot(run_.t, run_.controller_state[:, 0], label="current [A]")
        ax[0].plot(run_.t, run_.v[:, 0], label="speed [rad/s]")
        ax[0].set(title="DC motor, 12 V step", xlabel="t [s]")
        e = out["elastic"]
        for k in range(2):
            ax[1].plot(e.t, e.q[:, k], label=f"link {k + 1}")
            ax[1].plot(e.t, e.controller_state[:, k], ls="--", label=f"motor {k + 1}")
        ax[1].set(title="elastic joints, Tomei's PD", xlabel="t [s]", ylabel="rad")
        for name, style in (("plain", ":"), ("crossed", "-")):
            ax[2].plot(out[name].t, 1e3 * (out[name].q[:, 0] - q_d[0]), ls=style, label=f"set point {name}")
        ax[2].set(title="backlash: link 1 error", xlabel="t [s]", ylabel="mrad", ylim=(-80, 80))
        for name in ("exact", "smooth"):
            ax[3].plot(out[name].t, out[name].q[:, 0], label=f"{name} friction")
        ax[3].set(title="pendulum held by static friction", xlabel="t [s]", ylabel="rad")
        for a in ax:
            a.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=90)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
