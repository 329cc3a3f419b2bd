r"""
A bouncing ball: Newton's restitution and the apex heights
==========================================================

A ball of radius 10 cm and mass 0.5 kg (a free body with a ``Sphere`` contact shape) is
dropped from ``h = 1`` m onto the ground, a ``Plane`` with restitution ``e = 0.8``.
robodyn's contact model (velocity-level time stepping with Newton's impact law, the scheme
of Moreau and Jean; see ``robodyn.contact.solver``) reverses the approach speed times
``e`` at each impact, so in closed form the ball reaches the apex heights

.. math::

   h_k = e^{2k} h,

hits the ground at the times :math:`t_k = t_0 \left(1 + 2 \sum_{j=1}^{k} e^j\right)`,
:math:`t_0 = \sqrt{2h/g}`, and would bounce infinitely often before
:math:`t_\infty = t_0 (1 + e) / (1 - e)` (Zeno). Impacts slower than ``bounce_speed``
(5 cm/s by default) are inelastic, so the simulated ball comes to rest at the first impact
slower than that, and then lies on the ground carrying its weight.
"""

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd
from robodyn.contact import Contacts, Plane, Sphere

radius, mass, g = 0.1, 0.5, 9.81
h, e = 1.0, 0.8
builder = rd.ModelBuilder("ball")
builder.add_link("ball", mass=mass, inertia=rd.inertia.sphere(mass, radius))
ball = builder.build(floating_base=True)  # q = [x, y, z, qx, qy, qz, qw]
contacts = Contacts([Sphere("ball", radius)], surfaces=[Plane(restitution=e)])


def drop(dt):
    """The ball's height above the ground, its vertical velocity and the trajectory."""
    traj = rd.simulate(ball, [0, 0, h + radius, 0, 0, 0, 1], np.zeros(6), 4.5, dt, contacts=contacts)
    return traj.q[:, 2] - radius, traj.v[:, 2], traj


def bounces(z, vz):
    """Sample indices just after each impact faster than the bounce speed, and the apexes between them."""
    hits = np.flatnonzero((vz[:-1] < -contacts.bounce_speed) & (vz[1:] > 0)) + 1
    return hits, np.array([z[a:b].max() for a, b in zip(hits[:-1], hits[1:])])


z, vz, traj = drop(1e-5)
hits, apex = bounces(z, vz)
k = np.arange(1, len(apex) + 1)
print("apex heights (m):", apex[:6].round(5), "closed form:", (e ** (2 * k[:6]) * h).round(5))

# %%
# Newton's law of impact holds exactly at every impact (it is the solver's velocity
# constraint): the speed after is ``e`` times the speed before.
ratio = -vz[hits] / vz[hits - 1]
print(f"{len(hits)} bounces; largest |v_after / v_before - e| = {np.abs(ratio - e).max():.1e}")
assert np.allclose(ratio, e, rtol=0, atol=1e-9)

# %%
# The apex heights and impact times follow the closed form to the accuracy of the time
# stepping (semi-implicit Euler, first order: 10 microsecond steps here).
t0 = np.sqrt(2 * h / g)
n = np.arange(len(hits))
t_hits = t0 * (1 + 2 * e * (1 - e ** n) / (1 - e))
print(f"apex errors <= {np.abs(apex - e ** (2 * k) * h).max():.1e} m, impact times within "
      f"{np.abs(traj.t[hits] - t_hits).max() * 1e3:.2f} ms")
assert np.allclose(apex, e ** (2 * k) * h, rtol=0, atol=5e-5)
assert np.allclose(traj.t[hits], t_hits, rtol=0, atol=1e-3)
assert np.all(np.diff(traj.energy) <= 1e-12)  # impacts only take energy away

# %%
# The rest: the first impact slower than the bounce speed is the 21st (approach speed
# ``e^21 sqrt(2 g h)``), at :math:`t_{21}`, a little before :math:`t_\infty`; from then on the
# ball lies on the ground (no sinking), and the ground carries its weight.
k_rest = int(np.ceil(np.log(contacts.bounce_speed / np.sqrt(2 * g * h)) / np.log(e)))
t_rest = t0 * (1 + 2 * e * (1 - e ** k_rest) / (1 - e))
resting = np.flatnonzero(np.abs(z) + np.abs(vz) > 1e-9)[-1] + 1
print(f"at rest from t = {traj.t[resting]:.4f} s; closed form t_{k_rest} = {t_rest:.4f} s "
      f"(t_inf = {t0 * (1 + e) / (1 - e):.4f} s); normal force {traj.normal_force[-1, 0]:.6f} N, weight {mass * g} N")
assert k_rest == 21 and len(hits) == k_rest
assert abs(traj.t[resting] - t_rest) < 2e-3
assert np.all(np.abs(z[resting:]) < 1e-9)
# (the solver stops at a velocity residual of 1e-10 m/s: 5e-6 N over a 10 microsecond step)
assert np.allclose(traj.normal_force[resting + 1:, 0], mass * g, rtol=0, atol=1e-5)

# %%
# First order in the step: the largest apex error of the first eight bounces shrinks about
# tenfold with the step.
errors = {}
for dt in (1e-3, 1e-4, 1e-5):
    zz, vv = (z, vz) if dt == 1e-5 else drop(dt)[:2]
    errors[dt] = np.abs(bounces(zz, vv)[1][:8] / (e ** (2 * k[:8]) * h) - 1)
    print(f"dt = {dt:.0e} s: largest relative apex error {errors[dt].max():.1e}")
assert errors[1e-4].max() < errors[1e-3].max() / 5 and errors[1e-5].max() < errors[1e-4].max() / 5

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [1.7, 1]})
ax1.plot(traj.t[::10], z[::10], lw=1, label="rd.simulate, 10 us steps")
apex_times = t_hits[:-1] + t0 * e ** k
ax1.plot(apex_times, e ** (2 * k) * h, "k_", markersize=12, mew=1.5, label="e^(2k) h")
ax1.plot(t_hits, np.zeros_like(t_hits), "k|", markersize=8, label="t_k (closed form)")
ax1.axvline(t0 * (1 + e) / (1 - e), color="0.6", ls="--", lw=1, label="t_inf")
ax1.set_xlabel("t (s)")
ax1.set_ylabel("height of the ball's bottom (m)")
ax1.set_title("Ball dropped from 1 m, restitution 0.8")
ax1.legend(fontsize=8)
for dt, marker in zip(errors, ("o", "s", "^")):
    ax2.semilogy(k[:8], errors[dt], marker + "-", label=f"dt = {dt:.0e} s")
ax2.set_xlabel("bounce k")
ax2.set_ylabel("|h_k / (e^2k h) - 1|")
ax2.set_title("Apex error against the step")
ax2.legend(fontsize=8)
fig.tight_layout()
