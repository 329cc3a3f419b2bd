r"""
Pendulums: the exact period, and a spherical pendulum's conserved quantities
============================================================================

**The simple pendulum** (a point mass on a massless rod, ``rd.models.load("pendulum")``:
``m = 1`` kg, ``l = 1`` m, ``q = 0`` upright) released at rest from the angle
:math:`\theta_0` away from the bottom swings with the period

.. math::

   T(\theta_0) = 4 \sqrt{l / g}\; K\!\left(\sin\frac{\theta_0}{2}\right),

:math:`K(k) = \int_0^{\pi/2} d\phi / \sqrt{1 - k^2 \sin^2\phi}` the complete elliptic integral
of the first kind (Spong, Hutchinson and Vidyasagar, *Robot Modeling and Control*, 2006, and
any mechanics text; SciPy's ``ellipk`` takes the parameter :math:`m = k^2`). Small swings
give :math:`2\pi\sqrt{l/g}`; swings close to the top take arbitrarily long.

**The spherical pendulum** (a ball joint, built with ``rd.ModelBuilder``) keeps its energy
and the vertical component of its angular momentum about the pivot (gravity has no moment
about the vertical through the pivot); started at the right speed it circles as a conical
pendulum, :math:`\Omega^2 = g / (l \cos\alpha)` at the cone angle :math:`\alpha`.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.special import ellipk
from scipy.spatial.transform import Rotation

import robodyn as rd

g, l = 9.81, 1.0
pendulum = rd.models.load("pendulum")


def half_period(traj):
    """The first time after the release at which the velocity is zero again (linear
    interpolation between samples: at a turning point the velocity is locally linear)."""
    v = traj.v[:, 0]
    k = np.flatnonzero((traj.t[:-1] > 0.01) & (np.sign(v[:-1]) != np.sign(v[1:])))[0]
    return traj.t[k] - v[k] * (traj.t[k + 1] - traj.t[k]) / (v[k + 1] - v[k])


amplitudes = np.radians([5, 30, 60, 90, 120, 150, 170, 179])
simulated, exact = [], []
for theta0 in amplitudes:
    T = 4 * np.sqrt(l / g) * ellipk(np.sin(theta0 / 2) ** 2)
    traj = rd.simulate(pendulum, [np.pi - theta0], [0.0], 0.5 * T + 0.05, 1e-3)  # RK4, 1 ms
    simulated.append(2 * half_period(traj))
    exact.append(T)
    print(f"theta0 = {np.degrees(theta0):5.1f} deg: T = {simulated[-1]:.10f} s, closed form {T:.10f} s")
simulated, exact = np.array(simulated), np.array(exact)
assert np.allclose(simulated, exact, rtol=1e-9, atol=0)

# %%
# The period relative to the small-swing period :math:`2\pi\sqrt{l/g}`: lines are the
# closed form, dots the simulations.
T0 = 2 * np.pi * np.sqrt(l / g)
curve = np.radians(np.linspace(0.5, 179.5, 300))
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(np.degrees(curve), 4 * np.sqrt(l / g) * ellipk(np.sin(curve / 2) ** 2) / T0,
        label=r"$4\sqrt{l/g}\,K(\sin(\theta_0/2)) / T_0$")
ax.plot(np.degrees(amplitudes), simulated / T0, "o", label="rd.simulate (RK4, 1 ms)")
ax.set_xlabel("amplitude theta0 (deg)")
ax.set_ylabel("T / T0")
ax.set_title("Period of the simple pendulum")
ax.legend()
fig.tight_layout()

# %%
# The spherical pendulum
# ----------------------
# A ball of mass 1 kg and radius 5 cm on a massless rod of 1 m, hanging from a ball joint at
# the origin. The joint's configuration is a unit quaternion ``(qx, qy, qz, qw)`` and its
# velocity the angular velocity in the body frame (Pinocchio's convention). The angular
# momentum about the pivot is ``R M(q) w`` in world axes (``M`` is the inertia about the
# pivot in the body frame).
m, radius = 1.0, 0.05
builder = rd.ModelBuilder("spherical_pendulum")
builder.add_link("bob", mass=m, com=(0, 0, -l), inertia=rd.inertia.sphere(m, radius))
builder.add_joint("ball", "spherical", "world", "bob")
spherical = builder.build()


def world_momentum(traj):
    R = Rotation.from_quat(traj.q).as_matrix()
    return np.einsum("kij,kj->ki", R, np.einsum("kij,kj->ki", rd.crba(spherical, traj.q), traj.v))


def bob_position(traj):
    return Rotation.from_quat(traj.q).apply([0.0, 0.0, -l])


q0 = Rotation.from_rotvec([0.9, 0.3, 0.0]).as_quat()
free = rd.simulate(spherical, q0, [0.5, -1.0, 2.0], 10.0, 1e-3)
Lz = world_momentum(free)[:, 2]
print(f"10 s: energy varies by {np.ptp(free.energy):.1e} J, vertical angular momentum by {np.ptp(Lz):.1e} N m s "
      f"(Lz = {Lz[0]:.4f})")
assert np.ptp(free.energy) < 1e-10 * np.abs(free.kinetic).max()
assert np.ptp(Lz) < 1e-10 * abs(Lz[0])
assert np.allclose(np.linalg.norm(free.q, axis=1), 1.0, rtol=0, atol=1e-14)

# %%
# The conical pendulum: tilted by :math:`\alpha = 40^\circ` about the y axis and turning about
# the vertical at :math:`\Omega = \sqrt{g / (l \cos\alpha)}` (for a ball, whose inertia about
# its centre is isotropic, the same condition as for a point mass), the bob runs around the
# circle of radius :math:`l \sin\alpha` at constant height.
cone = np.radians(40.0)
Omega = np.sqrt(g / (l * np.cos(cone)))
q0 = Rotation.from_rotvec([0.0, cone, 0.0]).as_quat()
w0 = Rotation.from_quat(q0).inv().apply([0.0, 0.0, Omega])  # the body-frame angular velocity
conical = rd.simulate(spherical, q0, w0, 2 * 2 * np.pi / Omega, 1e-3)
p = bob_position(conical)
phase = Omega * conical.t
circle = l * np.stack([-np.sin(cone) * np.cos(phase), -np.sin(cone) * np.sin(phase),
                       np.full_like(phase, -np.cos(cone))], axis=-1)
print(f"conical pendulum: Omega = {Omega:.6f} rad/s, largest distance from the closed-form circle "
      f"{np.abs(p - circle).max():.1e} m")
assert np.allclose(p, circle, rtol=0, atol=1e-9)

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 4))
top = bob_position(free)
ax1.plot(top[:, 0], top[:, 1], lw=0.8, label="free motion, 10 s")
ax1.plot(p[:, 0], p[:, 1], "k--", lw=1.5, label="conical, Omega^2 = g / (l cos 40 deg)")
ax1.set_aspect("equal")
ax1.set_xlabel("x (m)")
ax1.set_ylabel("y (m)")
ax1.set_title("The bob seen from above")
ax1.legend(fontsize=7, loc="lower left")
ax2.semilogy(free.t, np.abs(free.energy - free.energy[0]) + 1e-17, label="|E - E(0)| (J)")
ax2.semilogy(free.t, np.abs(Lz - Lz[0]) + 1e-17, label="|Lz - Lz(0)| (N m s)")
ax2.set_xlabel("t (s)")
ax2.set_title("Conserved quantities (RK4, 1 ms)")
ax2.legend(fontsize=8)
fig.tight_layout()
