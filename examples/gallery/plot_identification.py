r"""
Identifying the inertial parameters of the 2R arm from a noisy log
==================================================================

The joint torques are linear in the inertial parameters, :math:`\tau = Y(q, \dot q, \ddot q)
\theta` (Khalil and Dombre, *Modeling, Identification and Control of Robots*, 2002, chapter
12). Only some combinations of :math:`\theta`, the *base parameters*
:math:`\beta = K\theta`, change the torques; for a planar arm of two revolute joints in a
vertical plane there are six (e.g. ``mx1 + l1 m2``: the mass of link 2 seen by joint 1 is
indistinguishable from a shift of link 1's centre of mass), plus viscous and Coulomb friction
per joint. Here:

1. an **excitation** trajectory (a periodic Fourier series per joint, optimised for the
   condition number of the base regressor: Swevers et al. 1997) is sampled at 200 Hz for 20 s;
2. the torques of the "real" arm (``planar_2r`` with friction the model does not have) along
   it come from inverse dynamics, plus Gaussian **noise** of 0.3 N m (the states are taken
   as exact, as from a well-filtered encoder: all the noise is on the torques);
3. ``identify`` estimates :math:`\beta` by ordinary least squares, with standard deviations
   :math:`\sigma_k` from the residuals, and by physically consistent least squares (every
   body's pseudo-inertia positive definite: Wensing, Kim and Slotine, 2017), starting from a
   nominal model 30 % too heavy.

With the noise on the torques only, least squares is unbiased and its reported standard
deviations are right: the errors :math:`(\hat\beta_k - \beta_k) / \sigma_k` look like draws of
a standard normal variable.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd
from robodyn import identification as ident

arm = rd.models.load("planar_2r")
truth = arm.replace(damping=[0.8, 0.5], coulomb=[1.5, 0.7])  # N m s/rad, N m
nominal = arm.replace(theta=1.3 * arm.theta)  # what we believe before identifying
base = ident.base_parameters(nominal, damping=True, coulomb=True)
print(base.count, "base parameters:", ", ".join(base.names))
beta_true = base.project(np.concatenate([truth.inertial_parameters(), truth.damping, truth.coulomb]))

excitation = ident.optimize_excitation(nominal, base, period=10.0, harmonics=4, samples=100, maxiter=10, seed=1)
print(f"condition number of the base regressor: {excitation.initial_condition_number:.1f} (random start) -> "
      f"{excitation.condition_number:.1f} (optimised)")
t, q, v, a = excitation.trajectory.sample(20.0, 200.0)  # two periods at 200 Hz

rng = np.random.default_rng(0)
noise = 0.3  # N m
log = ident.Log(t, q, v, a, rd.rnea(truth, q, v, a) + noise * rng.standard_normal(q.shape))

# %%
# Ordinary least squares: every base parameter within three standard deviations of the
# truth, and the normalised errors with a root mean square close to 1; the residuals'
# standard deviation is the noise level.
ols = ident.identify(nominal, log, method="ols", base=base)
z = (ols.estimate.beta - beta_true) / ols.estimate.std
print(ols.summary())
print("normalised errors (beta_hat - beta) / std:", z.round(2), f"rms {np.sqrt(np.mean(z ** 2)):.2f}")
assert np.all(np.abs(z) < 3.0)
assert 0.6 < np.sqrt(np.mean(z ** 2)) < 1.4
assert np.allclose(ols.estimate.sigma, noise, rtol=0.05)

# %%
# The physically consistent estimate: the same torques (to a fraction of the noise), and
# full parameters whose every body has a positive-definite pseudo-inertia
# :math:`\begin{bmatrix} \frac12 \mathrm{tr}(I) 1 - I & h \\ h^T & m \end{bmatrix}`
# (:math:`I` the inertia about the body origin, :math:`h = m c`), so the identified model is
# a real rigid body and ``result.identified_model()`` builds with robodyn's checks on.
physical = ident.identify(nominal, log, method="physical", base=base)
z_physical = (physical.estimate.beta - beta_true) / ols.estimate.std
print("physically consistent, normalised errors:", z_physical.round(2))
assert np.all(np.abs(z_physical) < 3.0)
theta = physical.estimate.theta[:10 * arm.nbodies].reshape(arm.nbodies, 10)
for m, mx, my, mz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz in theta:
    inertia = np.array([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
    h = np.array([mx, my, mz])
    pseudo = np.block([[0.5 * np.trace(inertia) * np.eye(3) - inertia, h[:, None]], [h[None, :], np.array([[m]])]])
    assert np.linalg.eigvalsh(pseudo).min() > 0
identified = physical.identified_model()
print("identified friction:", physical.extra())

# %%
# Validation on another motion (a random Fourier trajectory within the same limits): the
# identified model predicts the measured torques to the noise level.
other = ident.feasible_trajectory(nominal, period=8.0, harmonics=3, samples=100, seed=7)
tv, qv, vv, av = other.sample(8.0, 200.0)
validation = ident.Log(tv, qv, vv, av, rd.rnea(truth, qv, vv, av) + noise * rng.standard_normal(qv.shape))
predicted = rd.rnea(identified, qv, vv, av)
rms = np.sqrt(np.mean((predicted - validation.tau) ** 2, axis=0))
print("validation: rms error of the predicted torques", rms.round(3), "N m (noise 0.3 N m)")
assert np.allclose(predicted, physical.predict(validation), rtol=1e-9, atol=1e-9)
assert np.all(rms < 1.1 * noise)
assert np.allclose(predicted, rd.rnea(truth, qv, vv, av), rtol=0, atol=0.1)

# %%
# ``write_report`` writes the text summary and its figures (measured against predicted
# torques, residuals, singular values); here into a temporary directory.
with tempfile.TemporaryDirectory() as folder:
    paths = ident.write_report(physical, log, Path(folder) / "report", validation=validation)
    print("report files:", sorted(p.name for p in paths))
    print("\n".join(paths[0].read_text().splitlines()[:6]))

# %%
# Left: measured (noisy) and predicted torques on the validation motion, and their
# difference, which is the noise (the band: one standard deviation); right: the normalised
# errors of the base parameters.
fig = plt.figure(figsize=(11, 5))
grid = fig.add_gridspec(2, 2, width_ratios=[1.6, 1])
ax1 = fig.add_subplot(grid[0, 0])
ax3 = fig.add_subplot(grid[1, 0], sharex=ax1)
ax2 = fig.add_subplot(grid[:, 1])
for j, color in enumerate(("C0", "C1")):
    ax1.plot(tv, validation.tau[:, j], ".", color=color, markersize=1.5, label=f"joint {j + 1}, measured")
    ax1.plot(tv, predicted[:, j], color="k", lw=0.8)
    ax3.plot(tv, validation.tau[:, j] - predicted[:, j], ".", color=color, markersize=1.5)
ax1.plot([], [], "k", lw=0.8, label="identified model")
ax1.set_ylabel("tau (N m)")
ax1.set_title("Validation motion")
ax1.legend(fontsize=7, markerscale=4)
ax3.axhspan(-noise, noise, color="0.85", zorder=0)
ax3.set_ylabel("measured - predicted")
ax3.set_xlabel("t (s)")
k = np.arange(base.count)
ax2.axhspan(-1, 1, color="0.9", zorder=0)
ax2.bar(k - 0.2, z, width=0.4, label="OLS")
ax2.bar(k + 0.2, z_physical, width=0.4, label="physically consistent")
ax2.set_xticks(k, base.names, rotation=60, ha="right", fontsize=7)
ax2.set_ylabel("(estimate - truth) / std")
ax2.set_title("Base parameters")
ax2.legend(fontsize=8)
fig.tight_layout()
