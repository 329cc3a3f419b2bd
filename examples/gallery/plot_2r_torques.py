"""
The 2R arm: torque contributions along a motion
===============================================

The planar two-link arm of Murray, Li and Sastry (1994, section 4.2) and Spong et al.
(2006, section 7.3): thin rods of mass ``m1 = 10`` kg and ``m2 = 5`` kg, length 1 m, moving
in a vertical plane. Along a smooth motion of both joints, the joint torques
``tau = M(q) qdd + C(q, v) v + g(q)`` split into the inertial, Coriolis/centrifugal and
gravity parts, each computed by robodyn and checked against the closed form of the book
(centres of mass at the middle of each rod, ``I = m l^2 / 12``).
"""

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd

model = rd.models.load("planar_2r")
t = np.linspace(0.0, 2.0, 201)
q = np.stack([np.pi / 4 * np.sin(np.pi * t), np.pi / 3 * (1 - np.cos(np.pi * t))], axis=-1)
v = np.stack([np.pi ** 2 / 4 * np.cos(np.pi * t), np.pi ** 2 / 3 * np.sin(np.pi * t)], axis=-1)
a = np.stack([-np.pi ** 3 / 4 * np.sin(np.pi * t), np.pi ** 3 / 3 * np.cos(np.pi * t)], axis=-1)

inertial = np.einsum("kij,kj->ki", rd.crba(model, q, armature=False), a)
coriolis = np.einsum("kij,kj->ki", rd.coriolis_matrix(model, q, v), v)
gravity = rd.gravity(model, q)
tau = rd.rnea(model, q, v, a, friction=False, armature=False)
assert np.allclose(inertial + coriolis + gravity, tau, rtol=1e-12, atol=1e-9)

# %%
# The closed form: with ``lc = l / 2``, ``I = m l^2 / 12`` and ``q2`` the elbow angle,
# ``M11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos q2)``, ``M12 = I2 + m2 (lc2^2 +
# l1 lc2 cos q2)``, ``M22 = I2 + m2 lc2^2``, ``h = -m2 l1 lc2 sin q2`` and the Coriolis
# torques ``(h (2 v1 v2 + v2^2), -h v1^2)``.
m1, m2, l1, l2 = 10.0, 5.0, 1.0, 1.0
I1, I2, c1, c2 = m1 * l1 ** 2 / 12, m2 * l2 ** 2 / 12, l1 / 2, l2 / 2
cos2, sin2 = np.cos(q[:, 1]), np.sin(q[:, 1])
M11 = I1 + I2 + m1 * c1 ** 2 + m2 * (l1 ** 2 + c2 ** 2 + 2 * l1 * c2 * cos2)
M12 = I2 + m2 * (c2 ** 2 + l1 * c2 * cos2)
M22 = np.full_like(M11, I2 + m2 * c2 ** 2)
h = -m2 * l1 * c2 * sin2
book_inertial = np.stack([M11 * a[:, 0] + M12 * a[:, 1], M12 * a[:, 0] + M22 * a[:, 1]], axis=-1)
book_coriolis = np.stack([h * (2 * v[:, 0] * v[:, 1] + v[:, 1] ** 2), -h * v[:, 0] ** 2], axis=-1)
print("largest difference from the book, inertial:", np.abs(inertial - book_inertial).max(),
      "Coriolis:", np.abs(coriolis - book_coriolis).max())
assert np.allclose(inertial, book_inertial, rtol=1e-12, atol=1e-9)
assert np.allclose(coriolis, book_coriolis, rtol=1e-12, atol=1e-9)

fig, axes = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
for j, ax in enumerate(axes):
    ax.plot(t, inertial[:, j], label="inertial M(q) qdd")
    ax.plot(t, coriolis[:, j], label="Coriolis C(q, v) v")
    ax.plot(t, gravity[:, j], label="gravity g(q)")
    ax.plot(t, tau[:, j], "k--", label="total (RNEA)")
    ax.set_ylabel(f"tau{j + 1} (N m)")
axes[0].legend(loc="upper right", fontsize=8)
axes[1].set_xlabel("t (s)")
fig.tight_layout()
