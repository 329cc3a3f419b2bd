"""Joint friction beyond viscous and Coulomb: the Stribeck effect in every algorithm (smooth
law) and exact stiction in simulation (set-valued law).

Oracles: the closed form of the friction torque, central differences for its derivatives, a
sliding block that stops at ``t = I v0 / Fc`` after ``I v0^2 / (2 Fc)``, breakaway exactly at
the static level, a pendulum held by static friction, the complementarity conditions of the
friction solve against a brute-force quadratic programme, and dissipation (friction never
does positive work).
"""

import warnings

import numpy as np
import pytest
from scipy.optimize import minimize

import robodyn as rd
from robodyn import joints as J
from robodyn.errors import ModelError, RobodynWarning
from robodyn.random import random_model, random_state
from robodyn.simulation.stiction import box_friction, complementarity_residual, friction_bound

from helpers import assert_rel, pendulum, richardson, rng_for


def stribeck(model, seed=0, smoothing=0.0):
    """``model`` with random viscous, Coulomb and Stribeck friction on every dof."""
    rng = rng_for("stribeck", model.name, seed)
    return model.replace(damping=rng.uniform(0.1, 1.0, model.nv), coulomb=rng.uniform(0.2, 1.0, model.nv),
                         stribeck=rng.uniform(0.1, 0.8, model.nv), stribeck_velocity=rng.uniform(0.05, 0.5, model.nv),
                         coulomb_smoothing=smoothing)


MODELS = [random_model(6, seed=1, branching=0.4),
          random_model(5, seed=2, floating_base=True, branching=0.4,
                       joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL))]


def friction_formula(model, v):
    sgn = np.tanh(v / model.coulomb_smoothing) if model.coulomb_smoothing > 0 else np.sign(v)
    level = model.coulomb + model.stribeck * np.exp(-(v / model.stribeck_velocity) ** 2)
    return model.damping * v + level * sgn


@pytest.mark.parametrize("smoothing", [0.0, 0.05])
@pytest.mark.parametrize("model", MODELS, ids=["fixed", "floating-mixed"])
def test_the_stribeck_torque_in_rnea_aba_and_hybrid(model, smoothing):
    s = stribeck(model, smoothing=smoothing)
    q, v, a = random_state(model, np.random.default_rng(3), (4,))
    v = 0.3 * v  # around the Stribeck velocities, where the curve bends
    expected = friction_formula(s, v)
    assert_rel(rd.rnea(s, q, v, a) - rd.rnea(s, q, v, a, friction=False), expected, 1e-10)
    assert_rel(rd.rnea(s, q[0], v[0], a[0]) - rd.rnea(s, q[0], v[0], a[0], friction=False), expected[0], 1e-10)
    np.testing.assert_array_equal(rd.rnea(s.rigid(), q, v, a), rd.rnea(model.rigid(), q, v, a))
    tau = rd.rnea(s, q, v, a)
    assert_rel(rd.aba(s, q, v, tau), a, 1e-9)
    known = np.concatenate([np.full(J.NV[t], i % 2 == 1) for i, t in enumerate(model.joint_type)])
    a_h, tau_h = rd.hybrid_dynamics(s, q, v, a, tau, known)
    assert_rel(a_h, a, 1e-9)
    assert_rel(tau_h, tau, 1e-9)
    at_rest = rd.rnea(s, q[0], np.zeros(model.nv), a[0]) - rd.rnea(s, q[0], np.zeros(model.nv), a[0], friction=False)
    np.testing.assert_array_equal(at_rest, 0.0)  # sgn(0) = 0: the set-valued law is simulate's


@pytest.mark.parametrize("model", MODELS, ids=["fixed", "floating-mixed"])
def test_derivatives_include_the_stribeck_slope(model):
    s = stribeck(model, seed=1, smoothing=0.05)
    q, v, a = random_state(model, np.random.default_rng(4))
    v = 0.3 * v
    dq, dv, _ = rd.rnea_derivatives(s, q, v, a)
    assert_rel(dv, richardson(lambda d: rd.rnea(s, q, v + d, a), model.nv, step=1e-4), 1e-6)
    tau = rd.rnea(s, q, v, a)
    da_dq, da_dv, _ = rd.aba_derivatives(s, q, v, tau)
    assert_rel(da_dv, richardson(lambda d: rd.aba(s, q, v + d, tau), model.nv, step=1e-4), 1e-6)
    dq0, dv0, _ = rd.rnea_derivatives(s.replace(stribeck=np.zeros(model.nv)), q, v, a)
    np.testing.assert_array_equal(dq, dq0)  # friction depends on v only
    assert np.abs(dv - dv0).max() > 1e-3     # and the Stribeck slope is there


def test_stribeck_needs_a_velocity_and_sane_values():
    model = pendulum()
    with pytest.raises(ModelError, match="stribeck_velocity > 0"):
        model.replace(stribeck=[0.5])
    for field, bad in (("stribeck", -1.0), ("stribeck_velocity", -0.1), ("stribeck", np.inf), ("stribeck", np.nan)):
        with pytest.raises(ModelError, match=field):
            model.replace(**{field: [bad]})
    s = model.replace(coulomb=[0.3], stribeck=[0.2], stribeck_velocity=[0.1])
    assert s.replace(name="x").stribeck[0] == 0.2 and s.rigid().stribeck[0] == 0.0
    import pickle
    t = pickle.loads(pickle.dumps(s))
    assert rd.rnea(t, [0.1], [0.05], [0.0]) == rd.rnea(s, [0.1], [0.05], [0.0])


def test_writers_say_the_stribeck_friction_is_dropped():
    s = pendulum().replace(coulomb=[0.3], stribeck=[0.2], stribeck_velocity=[0.1])
    for write in (rd.io.write_urdf, rd.io.write_mjcf):
        with pytest.warns(RobodynWarning, match="Stribeck"):
            write(s)
    with pytest.warns(RobodynWarning, match="Stribeck"):
        rd.interop.to_pinocchio(s)


# -- the friction solve ----------------------------------------------------------------------------

def test_box_friction_solves_the_complementarity_problem():
    rng = rng_for("box friction")
    for trial in range(100):
        m = int(rng.integers(1, 8))
        A = rng.normal(size=(m, m))
        scale = np.diag(10.0 ** rng.uniform(-3, 3, m))      # badly scaled, like a robot's M^-1
        G = scale @ (A @ A.T + 0.1 * np.eye(m)) @ scale
        b = rng.normal(size=m) * np.sqrt(np.diag(G))
        bound = rng.uniform(0.0, 2.0, m)
        sol = box_friction(G, b, bound)
        assert np.all(np.abs(sol.f) <= bound * (1 + 1e-15))
        assert sol.residual <= 1e-11 * max(1.0, np.abs(b).max()), (trial, sol)
        assert sol.residual == complementarity_residual(G, b, bound, sol.f)
        # the same minimiser as a general-purpose bounded solver of 1/2 f'Gf - f'b
        ref = minimize(lambda f: 0.5 * f @ G @ f - f @ b, np.zeros(m), jac=lambda f: G @ f - b,
                       bounds=list(zip(-bound, bound)), method="L-BFGS-B", options=dict(ftol=1e-15, gtol=1e-13))
        value = 0.5 * sol.f @ G @ sol.f - sol.f @ b
        assert value <= ref.fun + 1e-9 * max(1.0, abs(ref.fun))


def test_a_wrong_friction_is_caught_by_the_residual():
    G, b, bound = np.array([[2.0, 0.5], [0.5, 1.0]]), np.array([1.0, -3.0]), np.array([0.1, 0.2])
    f = box_friction(G, b, bound).f
    assert complementarity_residual(G, b, bound, f) < 1e-14
    assert complementarity_residual(G, b, bound, -f) > 0.1
    assert complementarity_residual(G, b, bound, 2 * f) > 0.1  # outside the box


# -- exact stiction in simulation ---------------------------------------------------------------

def turntable(inertia=0.5, coulomb=2.0, stribeck=0.0, vs=0.0):
    """A disc on a vertical axis (gravity does no work): ``I a = tau - friction``."""
    b = rd.ModelBuilder("turntable")
    b.add_link("base")
    b.add_link("disc", mass=1.0, inertia=np.diag([inertia, inertia, inertia]))
    b.add_joint("spin", "revolute", "base", "disc", axis=(0, 0, 1))
    return b.build().replace(coulomb=[coulomb], stribeck=[stribeck], stribeck_velocity=[vs])


def test_a_sliding_disc_stops_where_coulomb_says_and_stays():
    I, Fc, v0, dt = 0.5, 2.0, 3.0, 1e-3
    traj = rd.simulate(turntable(I, Fc), [0.0], [v0], 1.5, dt, stiction=True)
    t_stop = I * v0 / Fc                                             # 0.75 s
    moving = traj.v[:, 0] > 0
    assert abs(traj.t[np.argmin(moving)] - t_stop) <= dt + 1e-12
    assert np.all(traj.v[traj.t > t_stop + dt, 0] == 0.0)              # at rest exactly
    assert abs(traj.q[-1, 0] - I * v0 ** 2 / (2 * Fc)) < 2 * v0 * dt   # 2.25 rad
    np.testing.assert_allclose(traj.joint_friction[traj.t < t_stop - dt, 0], Fc)
    np.testing.assert_array_equal(traj.joint_friction[traj.t > t_stop + dt, 0], 0.0)
    assert traj.integrator == "semi_implicit_euler"


def test_breakaway_happens_exactly_at_the_static_level():
    Fc, Fx, vs, I, dt = 1.0, 0.5, 0.1, 0.5, 1e-3
    model = turntable(I, Fc, Fx, vs)
    below = rd.simulate(model, [0.2], [0.0], 1.0, dt, controller=lambda t, q, v: np.array([0.999 * (Fc + Fx)]),
                        stiction=True)
    np.testing.assert_array_equal(below.v, 0.0)
    np.testing.assert_array_equal(below.q, 0.2)
    np.testing.assert_allclose(below.joint_friction[:, 0], 0.999 * (Fc + Fx), rtol=1e-12)
    u = 1.2 * Fc  # above the Coulomb level but below the breakaway: a joint at rest stays put
    held = rd.simulate(model, [0.0], [0.0], 0.5, dt, controller=lambda t, q, v: np.array([u]), stiction=True)
    np.testing.assert_array_equal(held.v, 0.0)
    # the same torque on a joint already sliding keeps it sliding (the Stribeck curve's hysteresis)
    slide = rd.simulate(model, [0.0], [0.5], 1.0, dt, controller=lambda t, q, v: np.array([u]), stiction=True)
    assert np.all(slide.v[:, 0] > 0.4)
    # once sliding it follows I v' = u - F(v): the velocity the smooth ODE reaches (first order in dt)
    v_end = slide.v[-1, 0]
    ode = rd.simulate(model, [0.0], [0.5], 1.0, 1e-4, controller=lambda t, q, v: np.array([u]), integrator="rk4")
    assert abs(v_end - ode.v[-1, 0]) < 5e-3 * abs(ode.v[-1, 0])
    above = rd.simulate(model, [0.0], [0.0], 0.2, dt, controller=lambda t, q, v: np.array([1.01 * (Fc + Fx)]),
                        stiction=True)
    assert above.v[-1, 0] > 0


def test_static_friction_holds_a_pendulum_that_the_smooth_law_lets_creep():
    m, L = 2.0, 0.7
    q0 = 0.3
    hold = 1.1 * m * 9.81 * L * np.sin(q0)  # the static level just above the gravity torque
    model = pendulum(m, L).replace(coulomb=[hold])
    held = rd.simulate(model, [q0], [0.0], 2.0, 1e-3, stiction=True)
    np.testing.assert_array_equal(held.q[:, 0], q0)
    # m L^2 a = tau + m g L sin(q) - f: the friction takes the whole gravity torque
    np.testing.assert_allclose(held.joint_friction[:, 0], m * 9.81 * L * np.sin(q0), rtol=1e-12)
    smooth = rd.simulate(model.replace(coulomb_smoothing=0.01), [q0], [0.0], 2.0, 1e-3)
    assert abs(smooth.q[-1, 0] - q0) > 1e-3  # tanh(v / eps) is zero at rest: the pendulum creeps
    weak = rd.simulate(pendulum(m, L).replace(coulomb=[0.9 * hold / 1.1]), [q0], [0.0], 0.5, 1e-3, stiction=True)
    assert weak.q[-1, 0] > q0 + 1e-3


def test_stiction_on_a_robot_never_does_positive_work_and_solves_exactly():
    model = rd.models.load("panda")
    model = model.replace(coulomb=np.full(model.nv, 2.0), stribeck=np.full(model.nv, 1.0),
                          stribeck_velocity=np.full(model.nv, 0.05), damping=np.full(model.nv, 0.1))
    q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.7])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RobodynWarning)  # every friction solve converged
        traj = rd.simulate(model, q0, np.full(model.nv, 0.8), 1.0, 1e-3, stiction=True)
    v_next = traj.v[1:]
    power = np.einsum("ki,ki->k", traj.joint_friction[:-1], v_next)
    assert np.all(power >= -1e-12)                               # f_k v+_k = F_k |v+_k| >= 0
    bound = friction_bound(model, traj.v[:-1])
    sliding = v_next != 0
    np.testing.assert_allclose(np.abs(traj.joint_friction[:-1][sliding]), bound[sliding], rtol=1e-12)
    assert np.all(np.abs(traj.joint_friction[:-1]) <= bound * (1 + 1e-12))
    stuck = ~sliding
    assert stuck[-100:].any()                                     # some joints came to rest under gravity
    # the motion between samples is the semi-implicit Euler step with these friction torques
    k = 500
    a = rd.aba(model, traj.q[k], traj.v[k], -traj.joint_friction[k], friction=False) \
        - rd.aba(model, traj.q[k], traj.v[k], np.zeros(model.nv), friction=False) \
        + rd.aba(model.replace(coulomb=np.zeros(model.nv), stribeck=np.zeros(model.nv)), traj.q[k], traj.v[k],
                 np.zeros(model.nv))
    assert_rel(traj.v[k + 1], traj.v[k] + 1e-3 * a, 1e-9)


def test_stiction_options_are_checked():
    model = turntable()
    for kw in (dict(integrator="rk4"), dict(integrator="RK45"), dict(constraints=[object()])):
        with pytest.raises(ValueError, match="stiction"):
            rd.simulate(model, [0.0], [1.0], 0.1, 1e-3, stiction=True, **kw)


def test_the_friction_torques_round_trip_through_the_log(tmp_path):
    model = turntable()
    traj = rd.simulate(model, [0.0], [1.0], 0.1, 1e-3, stiction=True)
    traj.to_csv(tmp_path / "run.csv")
    back = rd.Trajectory.from_csv(tmp_path / "run.csv", model)
    np.testing.assert_allclose(back.joint_friction, traj.joint_friction, rtol=1e-15)
    plain = rd.simulate(model, [0.0], [1.0], 0.1, 1e-3)
    assert plain.joint_friction is None
