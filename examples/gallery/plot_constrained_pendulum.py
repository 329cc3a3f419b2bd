r"""
A point mass on a rod: the Lagrange multiplier is the rod's tension
===================================================================

A bob of mass ``m = 2`` kg moves in the vertical x-z plane on two prismatic joints, a free
point of two coordinates. A massless rigid rod of length ``l = 0.8`` m to the origin,
``rd.DistanceConstraint``, turns it into a pendulum. robodyn solves the constrained
equations of motion (Featherstone, *Rigid Body Dynamics Algorithms*, 2008, chapter 8;
Murray, Li and Sastry, 1994, section 6.1, Lagrange's equations with constraints)

.. math::

   M \ddot q = \tau - h(q, \dot q) + J_c^T \lambda, \qquad J_c \ddot q + \dot J_c \dot q = 0,

where ``lambda`` is the rod force along ``d / l``, ``d`` the bob's position relative to
the anchor: positive pushes the bob away from the anchor, negative pulls it in (tension). Along the swing the
rod's tension has the closed form (the radial part of Newton's law, centripetal acceleration
:math:`l\dot\varphi^2` towards the pivot)

.. math::

   T = -\lambda = m (g \cos\varphi + l \dot\varphi^2) = m g (3 \cos\varphi - 2 \cos\varphi_0),

with :math:`\varphi` the angle from the downward vertical and the second form from the
energy, :math:`l \dot\varphi^2 = 2 g (\cos\varphi - \cos\varphi_0)`, for a release at rest
from :math:`\varphi_0`. Released above the horizontal, the bob first falls inside the
circle: a rigid rod then pushes it (``lambda > 0``), where a string would go slack.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.special import ellipk

import robodyn as rd

m, l, g = 2.0, 0.8, 9.81
builder = rd.ModelBuilder("point_mass")
builder.add_link("slider")
builder.add_link("bob", mass=m)
builder.add_joint("x", "prismatic", "world", "slider", axis=(1, 0, 0))
builder.add_joint("z", "prismatic", "slider", "bob", axis=(0, 0, 1))
point = builder.build()
rod = rd.DistanceConstraint("bob", (0, 0, 0), None, (0, 0, 0), length=l)  # bob's origin to the world origin

# %%
# One state first: hanging at 30 degrees and swinging at 2 rad/s, with no joint forces.
phi, omega = np.radians(30.0), 2.0
q = l * np.array([np.sin(phi), -np.cos(phi)])
v = l * omega * np.array([np.cos(phi), np.sin(phi)])
res = rd.constrained_dynamics(point, q, v, np.zeros(2), [rod])
tension = m * (g * np.cos(phi) + l * omega ** 2)
print(f"lambda = {res.forces[0][0]:.12f} N, closed form -T = {-tension:.12f} N; rank {res.rank}")
assert np.isclose(res.forces[0][0], -tension, rtol=1e-13, atol=0)
# and the acceleration is the pendulum's: tangential -g sin(phi), centripetal l omega^2
tangent, inward = np.array([np.cos(phi), np.sin(phi)]), -q / l
assert np.allclose(res.a, -g * np.sin(phi) * tangent + l * omega ** 2 * inward, rtol=1e-13, atol=1e-13)

# %%
# Swings released at rest from 45, 90 and 150 degrees, simulated for half a period of the
# pendulum (``2 sqrt(l/g) K(sin(phi0 / 2))``, from one side to the other) with RK4 steps of 2 ms, the constraint held by
# ``rd.simulate(..., constraints=[rod])`` with a light Baumgarte stabilisation (RK4 keeps the
# rod's length to 1e-9 m by itself). ``traj.constraint_force`` is the rod force at each sample.
swings = {}
for phi0 in np.radians([45.0, 90.0, 150.0]):
    period = 4 * np.sqrt(l / g) * ellipk(np.sin(phi0 / 2) ** 2)
    q0 = l * np.array([np.sin(phi0), -np.cos(phi0)])
    traj = rd.simulate(point, q0, [0.0, 0.0], period / 2, 2e-3, constraints=[rod], baumgarte=(2.0, 2.0))
    x, z = traj.q.T
    vx, vz = traj.v.T
    phi = np.arctan2(x, -z)
    phid = (x * vz - z * vx) / l ** 2
    lam = traj.constraint_force[:, 0]
    newton = m * (g * np.cos(phi) + l * phid ** 2)
    energy = m * g * (3 * np.cos(phi) - 2 * np.cos(phi0))
    print(f"phi0 = {np.degrees(phi0):5.1f} deg: tension from {-lam.max():8.3f} to {-lam.min():7.3f} N, "
          f"largest differences from the closed forms {np.abs(-lam - newton).max():.1e} N and "
          f"{np.abs(-lam - energy).max():.1e} N; |rod length - l| <= {np.abs(np.hypot(x, z) - l).max():.1e} m")
    assert np.allclose(-lam, newton, rtol=0, atol=1e-8 * m * g)
    assert np.allclose(-lam, energy, rtol=0, atol=1e-7 * m * g)
    assert np.abs(np.hypot(x, z) - l).max() < 1e-8
    swings[phi0] = traj.t, phi, lam

# the lowest point of the 90-degree swing: three times the weight
_, phi, lam = swings[np.pi / 2]
assert np.isclose(-lam[np.argmin(np.abs(phi))], 3 * m * g, rtol=1e-5)

# %%
# The tension over the angle: dots from robodyn's multiplier, lines the closed form
# :math:`m g (3\cos\varphi - 2\cos\varphi_0)`; below zero the rod pushes.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
angles = np.linspace(-np.pi, np.pi, 361)
for (phi0, (t, phi, lam)), color in zip(swings.items(), ("C0", "C1", "C2")):
    inside = np.abs(angles) <= phi0
    ax1.plot(np.degrees(angles[inside]), m * g * (3 * np.cos(angles[inside]) - 2 * np.cos(phi0)), color=color,
             label=f"phi0 = {np.degrees(phi0):.0f} deg")
    ax1.plot(np.degrees(phi[::15]), -lam[::15], "o", color=color, markersize=3)
    ax2.plot(t, -lam, color=color)
ax1.axhline(0.0, color="k", lw=0.5)
ax1.set_xlabel("angle from the downward vertical (deg)")
ax1.set_ylabel("rod tension -lambda (N)")
ax1.set_title("Tension over the angle")
ax1.legend(fontsize=8)
ax2.axhline(0.0, color="k", lw=0.5)
ax2.set_xlabel("t (s)")
ax2.set_title("Tension over half a period")
fig.tight_layout()
