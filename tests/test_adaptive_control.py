"""Adaptive Slotine-Li control (robodyn.control.AdaptiveSlotineLi): with a controller model
whose masses and inertias are 30 % wrong, the tracking error converges, the Lyapunov function
s^T M s / 2 + q~^T Lambda Kd q~ + theta~^T Gamma theta~ / 2 (plant's true theta) decreases at
the rate theory gives, and the non-adaptive Slotine-Li law with the same wrong model tracks
worse (planar_2r; puma560 with viscous friction and armature estimated); the law and the
adaptation rate against their definitions; bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn import control
from helpers import rng_for
from test_control import assert_lyapunov_rate


def mismatched(model):
    """The model with each body's inertial parameters scaled by 1.3 or 0.7 (alternately)."""
    scale = np.where(np.arange(model.nbodies) % 2 == 0, 1.3, 0.7)
    return model.replace(theta=model.theta * scale[:, None])


def sinusoid(q_mid, amplitude, w):
    """The reference ``q_mid + amplitude sin(w t)`` and its derivatives (t scalar or (N,))."""
    amplitude = np.full(np.shape(q_mid), amplitude)

    def reference(t):
        wt = w * np.asarray(t, dtype=float)[..., None] if np.ndim(t) else w * t  # (N, 1) or scalar
        st, ct = np.sin(wt), np.cos(wt)
        return q_mid + amplitude * st, amplitude * w * ct, -amplitude * w * w * st
    return reference


def lyapunov_rate(traj, lam, kd):
    """``dV/dt = -q~'^T Kd q~' - q~^T Lambda Kd Lambda q~`` along the trajectory."""
    e, ed = traj.q - traj.q_desired, traj.v - traj.v_desired
    return -np.sum(kd * ed ** 2 + lam * kd * lam * e ** 2, axis=1)


def tracking(plant, reference, controller, e0, duration, dt):
    q0 = reference(0.0)[0] + e0
    return rd.simulate(plant, q0, reference(0.0)[1], duration, dt, controller=controller)


# The tolerance of V(t) - V(0) == integral of dV/dt is the trapezoidal rule's error at
# dt = 2 ms (it shrinks as dt^2: 1.4e-2, 3.3e-3, 8.4e-4 absolute on puma560's first 0.2 s
# for dt = 2, 1, 0.5 ms; its wrist's fast transient makes it the larger one).
@pytest.mark.parametrize("name, duration, columns, tol", [
    ("planar_2r", 3.0, {}, 5e-5),
    ("puma560", 1.5, dict(damping=True, armature=True), 1e-3),
], ids=["planar_2r", "puma560"])
def test_adaptive_tracking_with_wrong_model(name, duration, columns, tol):
    """Wrong masses and inertias: the error converges, V never increases and V(t) - V(0) is
    the integral of its theoretical rate; the non-adaptive law tracks worse. (puma560: its
    viscous friction and armature estimated too, Coulomb friction off.)"""
    plant = rd.models.load(name)
    plant = plant.replace(coulomb=np.zeros(plant.nv))
    rng = rng_for(name, "adaptive")
    reference = sinusoid(rng.uniform(-0.5, 0.5, plant.nv), 0.5, 2.0)
    lam, kd, dt = 5.0, 10.0, 2e-3
    ctrl = control.AdaptiveSlotineLi(mismatched(plant), reference, lam, kd, gamma=0.1, theta_true=plant, **columns)
    e0 = np.full(plant.nv, 0.2)
    traj = tracking(plant, reference, ctrl, e0, duration, dt)
    err = np.abs(traj.q - traj.q_desired).max(axis=1)
    last = traj.t >= duration - 0.5
    assert err[last].max() < 0.1 * err[0]
    V = traj.lyapunov
    assert np.all(np.diff(V) <= 1e-9 * V[0])
    assert_lyapunov_rate(traj, lyapunov_rate(traj, lam, kd), tol)
    assert traj.controller_state.shape == (traj.t.shape[0], ctrl.state0.shape[0])
    assert np.abs(traj.controller_state[-1] - ctrl.state0).max() > 1e-3  # the estimates moved
    fixed = control.SlotineLi(mismatched(plant).replace(damping=np.zeros(plant.nv), armature=np.zeros(plant.nv)),
                              reference, lam, kd)
    traj_fixed = tracking(plant, reference, fixed, e0, duration, dt)
    err_fixed = np.abs(traj_fixed.q - traj_fixed.q_desired).max(axis=1)
    assert err[last].max() < 0.25 * err_fixed[last].max()


def test_exact_estimates_give_slotine_li():
    """theta_hat = the plant's parameters (friction and armature columns on): the torque is
    SlotineLi's with the plant model, V is SlotineLi's V, and the rate is -Gamma^-1 Y^T s."""
    plant = rd.models.load("puma560")
    rng = rng_for("exact")
    reference = sinusoid(rng.uniform(-1, 1, plant.nv), 0.3, 1.5)
    columns = dict(damping=True, coulomb=True, armature=True)
    G = rng.standard_normal((plant.nv * 3 + 10 * plant.nbodies,) * 2)
    gamma = G @ G.T + np.eye(G.shape[0])
    ad = control.AdaptiveSlotineLi(mismatched(plant), reference, 2.0, 3.0, gamma, theta_true=plant, **columns)
    sl = control.SlotineLi(plant, reference, 2.0, 3.0)
    theta = rd.algorithms.regressor.extended_parameters(plant, **columns)
    for t in (0.0, 0.7):
        q, v = rng.uniform(-1, 1, (2, plant.nv))
        np.testing.assert_allclose(ad.torque(t, q, v, theta), sl(t, q, v), rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(ad.lyapunov(t, q, v, theta), sl.lyapunov(t, q, v), rtol=1e-12)
        Y, s = ad.regressor(t, q, v)
        np.testing.assert_allclose(ad.state_rate(t, q, v, theta), -np.linalg.solve(gamma, Y.T @ s), rtol=1e-9,
                                   atol=1e-12)
        d = rng.standard_normal(theta.shape[0])
        np.testing.assert_allclose(ad.lyapunov(t, q, v, theta + d) - ad.lyapunov(t, q, v, theta),
                                   0.5 * d @ gamma @ d, rtol=1e-10)
    assert np.array_equal(ad.state0, rd.algorithms.regressor.extended_parameters(mismatched(plant), **columns))


def test_gains_as_scalar_vector_or_matrix():
    """gamma as a scalar, an (np,) diagonal and the same diagonal matrix: the same rate; the
    trajectory's Lyapunov function (vectorized call) equals the per-sample values."""
    plant = rd.models.load("planar_2r")
    reference = sinusoid(np.zeros(2), 0.4, 1.0)
    d = np.linspace(0.5, 2.0, 20)
    rates = [control.AdaptiveSlotineLi(plant, reference, 3.0, 4.0, g).state_rate(0.3, np.ones(2), -np.ones(2),
                                                                                  np.zeros(20))
             for g in (d, np.diag(d))]
    np.testing.assert_allclose(rates[0], rates[1], rtol=1e-14)
    np.testing.assert_allclose(control.AdaptiveSlotineLi(plant, reference, 3.0, 4.0, 2.0).state_rate(
        0.3, np.ones(2), -np.ones(2), np.zeros(20)), rates[0] * d / 2.0, rtol=1e-14)
    ctrl = control.AdaptiveSlotineLi(mismatched(plant), reference, 3.0, 4.0, d, theta_true=plant)
    traj = rd.simulate(plant, np.full(2, 0.1), np.zeros(2), 0.05, 1e-2, controller=ctrl,
                       integrator="semi_implicit_euler")
    np.testing.assert_allclose(ctrl.lyapunov_with(plant, traj.t, traj.q, traj.v, traj.controller_state),
                               traj.lyapunov, rtol=1e-12)


def test_without_true_parameters_no_lyapunov_function():
    """Without theta_true the controller reports no Lyapunov function, and still simulates;
    called as controller(t, q, v) it uses theta0."""
    plant = rd.models.load("planar_2r")
    reference = sinusoid(np.zeros(2), 0.4, 1.0)
    ctrl = control.AdaptiveSlotineLi(plant, reference, 3.0, 4.0, 1.0)
    assert ctrl.lyapunov is None
    traj = rd.simulate(plant, np.zeros(2), np.zeros(2), 0.02, 1e-2, controller=ctrl)
    assert traj.lyapunov is None and traj.controller_state.shape == (3, 20)
    q, v = np.array([0.1, 0.2]), np.array([0.3, -0.1])
    np.testing.assert_allclose(ctrl(0.1, q, v), control.SlotineLi(plant, reference, 3.0, 4.0)(0.1, q, v),
                               rtol=1e-12, atol=1e-12)


def test_bad_input():
    plant = rd.models.load("planar_2r")
    reference = sinusoid(np.zeros(2), 0.4, 1.0)

    def make(**kw):
        args = dict(lam=1.0, kd=1.0, gamma=1.0) | kw
        return control.AdaptiveSlotineLi(plant, reference, **args)

    with pytest.raises(ValueError, match=r"gamma: gains must be finite and > 0"):
        make(gamma=-1.0)
    with pytest.raises(ValueError, match=r"gamma: expected a positive number or shape \(20,\)"):
        make(gamma=np.ones(3))
    with pytest.raises(ValueError, match=r"gamma: expected .* \(20, 20\), got \(3, 3\)"):
        make(gamma=np.eye(3))
    with pytest.raises(ValueError, match="gamma: the matrix must be finite and symmetric"):
        make(gamma=np.eye(20) + np.triu(np.ones((20, 20)), 1))
    with pytest.raises(ValueError, match="gamma: the matrix must be positive definite"):
        make(gamma=-np.eye(20))
    with pytest.raises(ValueError, match=r"theta0: expected \(22,\) finite numbers .* got shape \(20,\)"):
        make(theta0=np.ones(20), damping=True)
    with pytest.raises(ValueError, match=r"theta0: expected \(20,\) finite numbers"):
        make(theta0=np.full(20, np.nan))
    with pytest.raises(ValueError, match=r"theta_true: the model has nq=6, nv=6, 6 bodies"):
        make(theta_true=rd.models.load("puma560"))
    with pytest.raises(ValueError, match="lam: gains must be finite and > 0"):
        make(lam=0.0)
    with pytest.raises(ValueError, match="fixed-base model"):
        control.AdaptiveSlotineLi(rd.random.random_model(2, seed=1, floating_base=True), reference, 1.0, 1.0, 1.0)
