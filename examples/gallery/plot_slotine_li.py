r"""
Adaptive control: Slotine and Li with an unknown payload
========================================================

The planar 2R arm (``rd.models.load("planar_2r")``) carries a payload of 3 kg at the end of
its second link that its controller does not know. The adaptive law of Slotine and Li
(*Applied Nonlinear Control*, 1991, section 9.2; Spong, Hutchinson and Vidyasagar, 2006,
section 8.5) computes its feed-forward from estimated inertial parameters
:math:`\hat\theta` and corrects them along the motion:

.. math::

   s = \dot{\tilde q} + \Lambda \tilde q, \quad
   \tau = Y(q, \dot q, \dot q_r, \ddot q_r)\,\hat\theta - K_D s, \quad
   \dot{\hat\theta} = -\Gamma\, Y^T s,

with :math:`\tilde q = q - q_d`, :math:`\dot q_r = \dot q_d - \Lambda \tilde q` and
:math:`Y \theta = M(q) \ddot q_r + C(q, \dot q) \dot q_r + g(q)`. The book's Lyapunov function

.. math::

   V = \tfrac12 s^T M(q) s + \tfrac12 \tilde\theta^T \Gamma^{-1} \tilde\theta, \qquad
   \dot V = -s^T K_D s \le 0

(the skew symmetry of :math:`\dot M - 2C` cancels the Coriolis terms) shows that
:math:`s`, hence the tracking error, goes to zero; the estimates stay bounded but need not
converge to the true values. ``control.AdaptiveSlotineLi`` writes the adaptation as
``theta_hat' = -gamma^-1 Y^T s``: its ``gamma`` is the book's :math:`\Gamma^{-1}`. Given the
plant's true parameters (``theta_true``) it samples into ``traj.lyapunov`` the same function
plus :math:`\tilde q^T \Lambda K_D \tilde q` (Spong's form, whose derivative
:math:`-\dot{\tilde q}^T K_D \dot{\tilde q} - \tilde q^T \Lambda K_D \Lambda \tilde q` is
also never positive).
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import cumulative_simpson

import robodyn as rd
from robodyn import control

arm = rd.models.load("planar_2r")
payload = 3.0
theta = arm.theta.copy()  # 10 parameters per body: m, m c, inertia about the body origin
theta[1] += payload * np.array([1, 1, 0, 0, 0, 0, 1, 0, 0, 1])  # a point mass 1 m along link 2
plant = arm.replace(theta=theta)

amplitude, frequency = np.array([[0.6, 0.3], [0.8, 0.4]]), np.array([[1.5, 4.5], [3.0, 6.0]])  # rad, rad/s
period = 2 * np.pi / 1.5


def reference(t):
    """A periodic motion (period 4.2 s) of both joints, ``(q_d, v_d, a_d)``, also for arrays of times."""
    t = np.asarray(t, dtype=float)[..., None, None]
    s, c = np.sin(frequency * t), np.cos(frequency * t)
    return ((amplitude * s).sum(-1) + np.array([-np.pi / 2, 0.3]), (amplitude * frequency * c).sum(-1),
            -(amplitude * frequency ** 2 * s).sum(-1))


lam, kd, gamma = 5.0, 50.0, 0.1
adaptive = control.AdaptiveSlotineLi(arm, reference, lam=lam, kd=kd, gamma=gamma, theta_true=plant)
q0, v0 = reference(0.0)[0] + np.array([0.2, -0.2]), reference(0.0)[1]
traj = rd.simulate(plant, q0, v0, 3 * period, 2e-3, controller=adaptive)  # RK4, 2 ms
fixed = rd.simulate(plant, q0, v0, 3 * period, 2e-3, controller=control.SlotineLi(arm, reference, lam=lam, kd=kd))
error = np.abs(traj.q - traj.q_desired).max(axis=1)
error_fixed = np.abs(fixed.q - fixed.q_desired).max(axis=1)

# %%
# The Lyapunov function of the book, computed from the trajectory (the plant's mass matrix,
# ``s`` from the controller, the estimates ``traj.controller_state``), never increases, and
# its decrease is exactly the dissipated :math:`\int s^T K_D s\,dt` (Simpson's rule on the
# 2 ms samples, compared at every other sample, where it spans whole pairs of steps).
t = traj.t
_, _, _, s = adaptive.sliding(t, traj.q, traj.v)
theta_error = traj.controller_state - plant.inertial_parameters()
V = 0.5 * np.einsum("ki,kij,kj->k", s, rd.crba(plant, traj.q), s) + 0.5 * gamma * np.sum(theta_error ** 2, axis=1)
dissipated = cumulative_simpson(kd * np.sum(s * s, axis=1), x=t, initial=0.0)
print(f"V: {V[0]:.4f} -> {V[-1]:.4f}; largest step up {np.diff(V).max():.1e}; "
      f"|V(t) - V(0) + int s^T Kd s| <= {np.abs(V - V[0] + dissipated)[::2].max():.1e}")
assert np.all(np.diff(V) <= 1e-12 * V[0])
assert np.allclose((V - V[0])[::2], -dissipated[::2], rtol=0, atol=1e-5 * V[0])
assert np.all(np.diff(traj.lyapunov) <= 1e-12 * traj.lyapunov[0])  # robodyn's, with the q~ term
assert np.allclose(traj.lyapunov, V + np.sum(lam * kd * (traj.q - traj.q_desired) ** 2, axis=1), rtol=1e-12)

# %%
# The tracking error, period after period: it keeps falling, to a small fraction of
# the 0.2 rad it started from and far below the error of the same law with the nominal
# parameters and no adaptation (``control.SlotineLi``), which the payload drags off the path.
periods = [(t >= k * period) & (t < (k + 1) * period) for k in range(3)]
worst = np.array([error[p].max() for p in periods])
worst_fixed = np.array([error_fixed[p].max() for p in periods])
print("largest error per period, adaptive:", worst.round(5), "rad; without adaptation:", worst_fixed.round(4), "rad")
assert np.all(np.diff(worst) < 0)
assert worst[-1] < 0.01 * error[0] and worst[-1] < 0.05 * worst_fixed[-1]

fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
ax1.semilogy(t, error_fixed, color="0.6", label="Slotine-Li, nominal parameters")
ax1.semilogy(t, error, color="C0", label="adaptive Slotine-Li")
ax1.set_ylabel("max |q - q_d| (rad)")
ax1.set_title("Tracking error")
ax1.legend(fontsize=8)
ax2.semilogy(t, traj.lyapunov, color="C2", label=r"traj.lyapunov, $V + \tilde q^T \Lambda K_D \tilde q$")
ax2.semilogy(t, V, color="C1", label=r"$V = \frac{1}{2} s^T M s + \frac{1}{2} \tilde\theta^T \Gamma^{-1} \tilde\theta$")
ax2.semilogy(t, V[0] - dissipated, "k:", label=r"$V(0) - \int_0^t s^T K_D s\,dt$")
ax2.set_ylabel("Lyapunov function")
ax2.set_xlabel("t (s)")
ax2.legend(fontsize=8)
fig.tight_layout()
