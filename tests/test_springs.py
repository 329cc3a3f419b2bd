"""Joint springs ``tau = stiffness (q - spring_reference)`` in every algorithm.

Oracles: the closed form of the added torque, a mass on a spring (harmonic motion at
``sqrt(k / m)``), conservation of energy with the springs' potential, central differences for
the derivatives, and MuJoCo's springs (``tests/test_mjcf.py``: ``stiffness``/``springref``
against ``mj_inverse``).
"""

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn import joints as J
from robodyn.random import random_model, random_state

from helpers import assert_rel, rng_for


def sprung(model, seed=0):
    """``model`` with random springs on its joints of one dof."""
    rng = rng_for("springs", seed)
    one = np.concatenate([np.full(J.NV[t], J.NV[t] == 1) for t in model.joint_type])
    return model.replace(stiffness=rng.uniform(1.0, 50.0, model.nv) * one,
                         spring_reference=rng.uniform(-1.0, 1.0, model.nv) * one)


MODELS = [random_model(6, seed=1, branching=0.4),
          random_model(5, seed=2, floating_base=True, branching=0.4,
                       joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL))]


@pytest.mark.parametrize("model", MODELS, ids=["fixed", "floating-mixed"])
def test_the_spring_torque_in_rnea_aba_and_hybrid(model):
    s = sprung(model)
    q, v, a = random_state(model, np.random.default_rng(3), (4,))
    one = np.flatnonzero(J.NV[model.joint_type] == 1)
    expected = np.zeros((4, model.nv))
    expected[:, model.idx_v[one]] = s.stiffness[model.idx_v[one]] * (q[:, model.idx_q[one]]
                                                                      - s.spring_reference[model.idx_v[one]])
    assert_rel(rd.rnea(s, q, v, a) - rd.rnea(model, q, v, a), expected, 1e-10)
    assert_rel(rd.rnea(s, q[0], v[0], a[0]) - rd.rnea(model, q[0], v[0], a[0]), expected[0], 1e-10)  # fast path
    np.testing.assert_array_equal(rd.rnea(s, q, v, a, friction=False), rd.rnea(model, q, v, a, friction=False))
    np.testing.assert_array_equal(rd.rnea(s.rigid(), q, v, a), rd.rnea(model.rigid(), q, v, a))
    tau = rd.rnea(s, q, v, a)
    assert_rel(rd.aba(s, q, v, tau), a, 1e-9)
    assert_rel(rd.aba(s, q[1], v[1], tau[1]), a[1], 1e-9)
    known = np.concatenate([np.full(J.NV[t], i % 2 == 1) for i, t in enumerate(model.joint_type)])  # hybrid
    a_h, tau_h = rd.hybrid_dynamics(s, q, v, a, tau, known)
    assert_rel(a_h, a, 1e-9)
    assert_rel(tau_h, tau, 1e-9)


@pytest.mark.parametrize("model", MODELS, ids=["fixed", "floating-mixed"])
def test_derivatives_include_the_springs(model):
    s = sprung(model, seed=1)
    q, v, a = random_state(model, np.random.default_rng(4))
    dq, dv, M = rd.rnea_derivatives(s, q, v, a)
    dq0, dv0, M0 = rd.rnea_derivatives(model, q, v, a)
    np.testing.assert_allclose(dq - dq0, np.diag(s.stiffness), rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(dv, dv0)
    h = 1e-6  # central differences of rnea along integrate's tangent directions
    fd = np.column_stack([(rd.rnea(s, rd.integrate(s, q, h * e), v, a) - rd.rnea(s, rd.integrate(s, q, -h * e), v, a))
                          / (2 * h) for e in np.eye(model.nv)])
    assert_rel(dq, fd, 1e-6)
    tau = rd.rnea(s, q, v, a)
    da_dq, _, _ = rd.aba_derivatives(s, q, v, tau)
    fd = np.column_stack([(rd.aba(s, rd.integrate(s, q, h * e), v, tau) - rd.aba(s, rd.integrate(s, q, -h * e), v, tau))
                          / (2 * h) for e in np.eye(model.nv)])
    assert_rel(da_dq, fd, 1e-6)


def test_a_mass_on_a_spring_oscillates_at_sqrt_k_over_m_and_keeps_its_energy():
    m, k, ref, x0, armature = 2.0, 50.0, 0.1, 0.3, 0.5
    b = rd.ModelBuilder("oscillator", gravity=(0.0, 0.0, -9.81))
    b.add_link("base")
    b.add_link("cart", mass=m, inertia=np.eye(3) * 1e-3)
    b.add_joint("slide", "prismatic", "base", "cart", axis=(1, 0, 0), stiffness=k, spring_reference=ref,
                armature=armature)
    model = b.build()
    run = rd.simulate(model, np.array([x0]), np.zeros(1), 2.0, 1e-3, integrator="rk4")
    w = np.sqrt(k / (m + armature))
    np.testing.assert_allclose(run.q[:, 0], ref + (x0 - ref) * np.cos(w * run.t), rtol=0, atol=1e-9)
    assert np.ptp(run.energy) < 1e-9 * 0.5 * k * (x0 - ref) ** 2
    np.testing.assert_allclose(run.potential - run.potential[0], 0.5 * k * ((run.q[:, 0] - ref) ** 2 - (x0 - ref) ** 2),
                               rtol=0, atol=1e-12)


def test_a_sprung_pendulum_conserves_energy():
    model = sprung(rd.models.load("double_pendulum"), seed=2)
    run = rd.simulate(model, np.array([0.5, -0.4]), np.zeros(2), 3.0, 1e-3, integrator="rk4")
    assert np.ptp(run.energy) < 1e-8 * np.abs(run.kinetic).max()
    assert np.abs(run.potential - rd.potential_energy(model, run.q)).max() > 1e-3  # the springs' share is in


def test_springs_are_refused_where_they_cannot_be():
    model = MODELS[1]
    spherical = next(i for i in range(model.nbodies) if model.joint_type[i] == J.SPHERICAL)
    stiff = np.zeros(model.nv)
    stiff[model.idx_v[spherical]] = 1.0
    with pytest.raises(rd.ModelError, match=f"body {spherical}: joint springs .* on a spherical joint"):
        model.replace(stiffness=stiff)
    with pytest.raises(rd.ModelError, match="stiffness must be finite and non-negative"):
        model.replace(stiffness=-stiff)
    with pytest.raises(rd.ModelError, match="spring_reference must be finite"):
        model.replace(spring_reference=np.full(model.nv, np.nan))
    b = rd.ModelBuilder()
    b.add_link("a")
    b.add_link("b", mass=1.0, inertia=np.eye(3))
    with pytest.raises(rd.ModelError, match="joint springs on a free joint"):
        b.add_joint("j", "free", "a", "b", stiffness=1.0)
    with pytest.raises(rd.ModelError, match="stiffness must be finite and >= 0"):
        b.add_joint("j", "revolute", "a", "b", stiffness=-1.0)


def test_what_cannot_hold_springs_says_so():
    model = sprung(rd.models.load("double_pendulum"))
    with pytest.warns(rd.RobodynWarning, match=r"joint springs \(stiffness, spring_reference\)"):
        rd.write_urdf(model)
    from robodyn.interop import to_pinocchio

    with pytest.warns(rd.RobodynWarning, match="joint springs of .* not converted"):
        to_pinocchio(model)
    with warnings.catch_warnings():  # the point masses are raised to MuJoCo's bound, with a warning
        warnings.simplefilter("ignore", rd.RobodynWarning)
        text = rd.write_mjcf(model)
    back = rd.load_mjcf(text)
    np.testing.assert_array_equal(back.stiffness, model.stiffness)
    np.testing.assert_array_equal(back.spring_reference, model.spring_reference)
