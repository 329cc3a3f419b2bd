"""Three contact scenes with their closed forms: a bouncing ball, a box on an incline, a
planar hopper.

    python examples/contact_scenes.py [--gif DIR]

- **Bouncing ball** (restitution e = 0.8, dropped from h = 1 m): rebounds to e^2 h, e^4 h, ...
  and comes to rest once its impacts are slower than ``bounce_speed``.
- **Box on an incline** (mu = 0.5): sticks below atan(mu) = 26.57 degrees, slides above with
  the acceleration g (sin a - mu cos a).
- **Hopper** (a body on a springy prismatic leg, moving in the vertical x-z plane through a
  planar joint): dropped with a forward speed, it touches down, compresses its leg spring and
  takes off again, losing the foot's impact energy at each touchdown.

Reference: the rigid contact model of :mod:`robodyn.contact.solver`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn import plots
from robodyn.contact import Box, Contacts, Plane, Sphere

G = 9.81


def free_body(name, mass, inertia):
    b = rd.ModelBuilder(name)
    b.add_link("body", mass=mass, inertia=inertia)
    return b.build(floating_base=True)


def bouncing_ball(height=1.0, restitution=0.8, radius=0.1, duration=3.0):
    """``(model, contacts, trajectory)`` of the ball; prints its apexes against ``e^2k h``."""
    model = free_body("ball", 1.0, 0.4 * radius ** 2 * np.eye(3))
    contacts = Contacts([Sphere("body", radius)], surfaces=[Plane(restitution=restitution)])
    traj = rd.simulate(model, [0, 0, height + radius, 0, 0, 0, 1], np.zeros(6), duration, 1e-3, contacts=contacts)
    z = traj.q[:, 2] - radius
    apex = [z[k] for k in range(1, len(z) - 1) if z[k - 1] < z[k] >= z[k + 1] and z[k] > 1e-6]
    print("bouncing ball: apex / (e^2k h) =", [round(a / (restitution ** (2 * k + 2) * height), 4)
                                              for k, a in enumerate(apex[:4])])
    return model, contacts, traj


def box_on_incline(degrees, mu=0.5, size=(0.2, 0.1, 0.05), duration=1.0):
    """``(model, contacts, trajectory)`` of a box released on a plane tilted by ``degrees``;
    prints its acceleration along the slope against ``g (sin a - mu cos a)`` (0 when it sticks)."""
    size = np.asarray(size)
    m = 2.0
    model = free_body("box", m, m / 12 * np.diag([size[1] ** 2 + size[2] ** 2, size[0] ** 2 + size[2] ** 2,
                                                 size[0] ** 2 + size[1] ** 2]))
    a = np.radians(degrees)
    n = np.array([-np.sin(a), 0.0, np.cos(a)])
    quat = np.array([0.0, -np.sin(a / 2), 0.0, np.cos(a / 2)])  # about y by -a: the box's z along n
    contacts = Contacts([Box("body", size)], surfaces=[Plane(normal=n, friction=mu)])
    traj = rd.simulate(model, np.concatenate([n * size[2] / 2, quat]), np.zeros(6), duration, 1e-3,
                       contacts=contacts)
    down = -np.array([np.cos(a), 0.0, np.sin(a)])
    s = (traj.q[:, :3] - traj.q[0, :3]) @ down
    accel = 2 * np.polyfit(traj.t, s, 2)[0]
    expected = max(G * (np.sin(a) - mu * np.cos(a)), 0.0)
    print(f"box on a {degrees:g} degree incline (mu = {mu}): acceleration {accel:.5f} m/s^2, "
          f"g (sin a - mu cos a) = {expected:.5f} m/s^2")
    return model, contacts, traj


def hopper(duration=2.0, stiffness=2000.0, damping=5.0, rest_length=0.5):
    """``(model, contacts, trajectory)`` of the planar hopper (its leg a spring-damper)."""
    b = rd.ModelBuilder("hopper")
    b.add_link("world")
    b.add_link("body", mass=5.0, inertia=np.diag([0.05, 0.05, 0.05]))
    b.add_link("leg", mass=0.3, com=(0, 0, -0.25), inertia=np.diag([0.006, 0.006, 1e-4]))
    b.add_joint("base", "planar", "world", "body", rpy=(np.pi / 2, 0, 0))  # the x-y plane of the joint: world x-z
    b.add_joint("knee", "prismatic", "body", "leg", rpy=(-np.pi / 2, 0, 0), axis=(0, 0, 1))  # q: compression
    b.add_link("foot")
    b.add_joint("ankle", "fixed", "leg", "foot", xyz=(0, 0, -rest_length))  # a frame at the leg's end
    model = b.build()
    contacts = Contacts([Sphere("foot", 0.03)], surfaces=[Plane(friction=1.0)])
    q0 = np.array([0.0, 1.0, 1.0, 0.0, 0.0])  # x, height, cos, sin of the pitch, leg compression
    v0 = np.array([0.5, 0.0, 0.0, 0.0])

    def spring(t, q, v):  # the leg pushes back on its compression; the pitch is held upright
        pitch = np.arctan2(q[3], q[2])
        return np.array([0.0, 0.0, -200.0 * pitch - 20.0 * v[2], -stiffness * q[4] - damping * v[3]])

    traj = rd.simulate(model, q0, v0, duration, 5e-4, spring, contacts=contacts)
    touching = traj.normal_force[:, 0] > 0
    starts = np.flatnonzero(np.diff(touching.astype(int)) == 1)
    print(f"hopper: {len(starts)} touchdowns at t = {np.round(traj.t[starts + 1], 3).tolist()} s, "
          f"largest leg compression {traj.q[:, 4].max() * 1000:.0f} mm")
    return model, contacts, traj


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--gif", help="write ball.gif, incline.gif and hopper.gif into this directory")
    args = parser.parse_args()
    scenes = {"ball": bouncing_ball(), "incline": box_on_incline(35.0), "hopper": hopper()}
    box_on_incline(20.0)
    if args.gif:
        for name, (model, contacts, traj) in scenes.items():
            plots.animate(model, traj.t, traj.q, Path(args.gif) / f"{name}.gif", fps=20, contacts=contacts)


if __name__ == "__main__":
    main()
