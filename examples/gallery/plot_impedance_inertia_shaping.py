r"""
Cartesian impedance with and without inertia shaping
====================================================

The Panda's hand (``rd.models.load("panda")``, 7 joints) is held about its start by a
Cartesian spring and damper (Hogan 1985; Siciliano et al., *Robotics*, 2009, section 9.3),
and pushed from :math:`t = 0` by a constant force :math:`f` along :math:`x` (an external
force on the hand in the simulation, read by an ideal force sensor).

* **Without inertia shaping**, ``control.CartesianImpedance(..., stiffness=K, damping=D)``:
  :math:`\tau = J^T (K e - D J \dot q) - D_q \dot q + g(q)`. The hand settles at
  :math:`f / K`, but on the way it moves with the arm's own apparent mass
  :math:`\Lambda(q) = (J M^{-1} J^T)^{-1}` and its Coriolis forces: no closed form.
* **With inertia shaping**, ``inertia=M_d, force=sensor``: the force measurement and the
  task-space dynamics :math:`\Lambda \ddot x + \mu + p = F + h_e` make the hand the
  mass-spring-damper :math:`M_d \ddot x + D \dot x + K x = f` exactly, whose step response
  from rest is

  .. math:: x(t) = \frac{f}{K}\left(1 - e^{-\zeta\omega_n t}\left(\cos\omega_d t +
     \frac{\zeta\omega_n}{\omega_d}\sin\omega_d t\right)\right),\quad
     \omega_n = \sqrt{K / M_d},\ \zeta = \frac{D}{2\sqrt{K M_d}},\ \omega_d = \omega_n\sqrt{1 - \zeta^2}.

  Two desired masses, 1 kg and 6 kg, give two different responses, each its closed form.
"""

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd
from robodyn import control

model = rd.models.load("panda").rigid()
q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8])
x0 = rd.frame_pose(model, q0, "link7")[:3, 3]
K, D, f = 400.0, 30.0, 6.0  # N/m, N s/m, N
push = np.array([f, 0.0, 0.0])
wrench = np.zeros((model.nbodies, 6))
wrench[model.frame_index("link7")[0], :3] = push  # world axes, on the hand's origin


def sensor(t, q, v):
    return push


def step_response(m, t):
    wn, z = np.sqrt(K / m), D / (2 * np.sqrt(K * m))
    wd = wn * np.sqrt(1 - z * z)
    return f / K * (1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z * wn / wd * np.sin(wd * t)))


runs = {}
for label, options in (("no shaping", {}), ("M_d = 1 kg", {"inertia": 1.0, "force": sensor}),
                       ("M_d = 6 kg", {"inertia": 6.0, "force": sensor})):
    ctrl = control.CartesianImpedance(model, "link7", x0, stiffness=K, damping=D, joint_damping=2.0, **options)
    traj = rd.simulate(model, q0, np.zeros(7), 1.5, 1e-3, controller=ctrl, f_ext=wrench, frame="local_world_aligned")
    runs[label] = traj.t, np.array([rd.frame_pose(model, q, "link7")[:3, 3] for q in traj.q]) - x0

# %%
# With shaping, the hand's displacement along the push is the closed form, to the accuracy
# of the integration (RK4, 1 ms); across the push it does not move at all. Without shaping it
# reaches the same rest, f / K = 1.5 cm, along another path.
t = runs["no shaping"][0]
for label, m in (("M_d = 1 kg", 1.0), ("M_d = 6 kg", 6.0)):
    x = runs[label][1]
    gap = np.abs(x[:, 0] - step_response(m, t)).max()
    across = np.abs(x[:, 1:]).max()
    print(f"{label}: largest difference from the closed form {gap:.1e} m; across the push {across:.1e} m")
    assert gap < 1e-6 * f / K and across < 1e-6 * f / K
x_plain = runs["no shaping"][1]
print(f"no shaping: at 1.5 s x = {1e3 * x_plain[-1, 0]:.3f} mm (f / K = {1e3 * f / K:.3f} mm), "
      f"moving {1e3 * np.abs(x_plain[:, 1:]).max():.2f} mm across the push on the way")
assert abs(x_plain[-1, 0] - f / K) < 0.02 * f / K

# %%
# The displacement along the push; the closed forms dotted.
fig, ax = plt.subplots(figsize=(7, 4))
for label, (t, x) in runs.items():
    ax.plot(t, 100 * x[:, 0], label=label)
for m in (1.0, 6.0):
    ax.plot(t, 100 * step_response(m, t), "k:", lw=1)
ax.plot([], [], "k:", lw=1, label="closed form")
ax.axhline(100 * f / K, color="0.6", lw=0.8)
ax.set(xlabel="t (s)", ylabel="x - x_d (cm)", title="Step push of 6 N on the Panda's hand, K = 400 N/m, D = 30 N s/m")
ax.legend()
fig.tight_layout()
