"""Mimic joints as true couplings (``rd.CoupledModel``, ``load_urdf(mimic="couple")``).

Oracles, each independent of the map ``tau = G^T tau_full`` the implementation uses:

* Pinocchio's own mimic joints (``buildModelFromUrdf(..., mimic=True)``: rnea, crba and the
  frame Jacobians, the algorithms it supports for them) on every example-robot-data URDF with
  mimic joints that it accepts, fixed and floating base;
* the full tree (every joint free) under one ``CouplingConstraint`` per mimic joint: its
  constrained forward dynamics (a KKT solve with the constraints' Jacobian) must move exactly as
  the coupled model's, with friction, armature, springs and external wrenches;
* finite differences of robodyn's own functions along ``rd.integrate`` of the coupled model
  (derivatives, Jacobians, the Coriolis matrix's ``Mdot - 2 C`` skew symmetry), energies and the
  identities between the algorithms, on seeded random trees mixing every joint type with
  chains of mimic joints (a mimic of a mimic) and negative multipliers.
"""

from __future__ import annotations

import pickle
import re
import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from conftest import erd_id, example_robot_urdfs
from helpers import MIXED, ONE_DOF, assert_rel, check_batch, rng_for, states, tangent_differences
from robodyn import joints as J
from robodyn.random import random_model

# (bodies, seed, floating base, branching, joint types)
CASES = [(7, 21, False, 0.3, ONE_DOF), (8, 22, True, 0.4, ONE_DOF), (11, 23, False, 0.5, MIXED),
         (11, 24, True, 0.4, MIXED)]


def coupled_model(n, seed, floating_base, branching, joint_types) -> rd.CoupledModel:
    """A random tree with friction, armature and springs everywhere and three mimic joints: the
    last 1-dof joint follows the first, the one before it follows the last (a chain), the third
    follows the second; multipliers of both signs, offsets."""
    full = random_model(n, seed, floating_base, branching, joint_types)
    rng = np.random.default_rng(seed)
    one = [name for name, t in zip(full.body_joint_names, full.joint_type) if J.NV[t] == 1]
    assert len(one) >= 5
    full = full.replace(damping=rng.uniform(0.1, 1.0, full.nv), coulomb=rng.uniform(0.1, 1.0, full.nv),
                        armature=rng.uniform(0.01, 0.1, full.nv), coulomb_smoothing=0.3,
                        stiffness=np.where(J.NV[full.joint_type].repeat(J.NV[full.joint_type]) == 1,
                                           rng.uniform(0.0, 2.0, full.nv), 0.0),
                        spring_reference=np.where(J.NV[full.joint_type].repeat(J.NV[full.joint_type]) == 1,
                                                  rng.uniform(-1, 1, full.nv), 0.0))

    def ratio():
        return float(rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 2.0))

    mimic = [(one[-1], one[0], ratio(), rng.uniform(-0.5, 0.5)), (one[-2], one[-1], ratio(), rng.uniform(-0.5, 0.5)),
             (one[2], one[1], ratio(), 0.0)]
    return rd.CoupledModel(full, mimic)


MODELS = [coupled_model(*c) for c in CASES]
IDS = [f"n{n}-seed{s}-{'floating' if fb else 'fixed'}{'-mixed' if J.SPHERICAL in jt else ''}"
       for n, s, fb, _, jt in CASES]
coupled_models = pytest.mark.parametrize("model", MODELS, ids=IDS)


def full_state(model, q, v):
    """``(E(q), G v)`` computed here, by the joint names (not by the model's matrices)."""
    full = model.full
    qf, vf = np.zeros(full.nq), np.zeros(full.nv)
    qf[model.independent_q], vf[model.independent_v] = q, v
    body = {name: i for i, name in enumerate(full.body_joint_names)}
    for joint, source, r, o in model.mimic:
        i, s = body[joint], body[source]
        qf[full.idx_q[i]] = r * qf[full.idx_q[s]] + o
        vf[full.idx_v[i]] = r * vf[full.idx_v[s]]
    return qf, vf


def couplings(model):
    return [rd.CouplingConstraint(source, joint, r, o) for joint, source, r, o in model.mimic]


# -- the model --------------------------------------------------------------------------
@coupled_models
def test_coupled_model_has_the_independent_coordinates(model):
    full = model.full
    assert model.nv == full.nv - 3 and model.nq == full.nq - 3
    mimics = {j for j, _, _, _ in model.mimic}
    assert model.joint_names == tuple(n for n in full.joint_names if n not in mimics)
    assert len(model.dof_names) == model.nv and len(model.q_names) == model.nq
    assert not mimics & set(model.dof_names)
    q, v, _ = states(model, "layout")
    qf, vf = full_state(model, q, v)
    np.testing.assert_allclose(model.P @ q + model.offset, qf, rtol=0, atol=1e-15)
    np.testing.assert_allclose(model.G @ v, vf, rtol=0, atol=1e-15)
    k = [full.dof_names.index(n) for n in model.dof_names]
    for key in ("lower", "upper", "velocity_limit", "effort_limit"):
        np.testing.assert_array_equal(getattr(model, key), getattr(full, key)[k])
    assert "mimic:" in repr(model) and model.name == full.name and model.nbodies == full.nbodies
    copy = pickle.loads(pickle.dumps(model))
    assert copy.mimic == model.mimic and np.array_equal(copy.G, model.G)
    assert_rel(rd.rnea(copy, q, v, v), rd.rnea(model, q, v, v), 0.0)


# -- against the constrained full tree -------------------------------------------------------
@coupled_models
@pytest.mark.parametrize("frame", ("local", "world"))
def test_forward_dynamics_is_the_full_tree_under_coupling_constraints(model, frame):
    """Friction, armature, springs on every joint (the mimic joints' included) and external
    wrenches: the coupled model's ``aba`` moves the full tree as its constrained dynamics
    does, with the torques on the independent joints and none on the mimic joints."""
    rng = rng_for(model.name, "constrained", frame)
    q, v, _ = states(model, "constrained", frame)
    tau = rng.standard_normal(model.nv)
    f_ext = rng.standard_normal((model.nbodies, 6))
    a = rd.aba(model, q, v, tau, f_ext, frame)
    qf, vf = full_state(model, q, v)
    tau_full = np.zeros(model.full.nv)
    tau_full[model.independent_v] = tau
    # the wrenches enter the full tree's constrained dynamics as joint forces J^T f
    tau_full += rd.rnea(model.full, qf, vf, np.zeros_like(vf), friction=False) - rd.rnea(
        model.full, qf, vf, np.zeros_like(vf), f_ext, frame, friction=False)
    res = rd.constrained_dynamics(model.full, qf, vf, tau_full, couplings(model))
    assert_rel(model.G @ a, res.a, 1e-9, "accelerations of the full tree")
    assert_rel(rd.rnea(model, q, v, a, f_ext, frame), tau, 1e-9, "rnea inverts aba")
    # and the reduced mass matrix is the constrained one: G^T M G, checked by its action
    M = rd.crba(model, q)
    assert_rel(M, M.T, 1e-14)
    assert np.all(np.linalg.eigvalsh(M) > 0)


@coupled_models
def test_hybrid_dynamics_of_a_coupled_model(model):
    rng = rng_for(model.name, "hybrid")
    q, v, a = states(model, "hybrid")
    tau = rng.standard_normal(model.nv)
    mask = np.zeros(model.nv, bool)
    for i in range(model.nbodies):  # the independent dofs of every other joint known
        names = [n for n in model.dof_names if n.split(":")[0] == model.body_joint_names[i]]
        if i % 2 and names:
            mask[[model.dof_names.index(n) for n in names]] = True
    a_h, tau_h = rd.hybrid_dynamics(model, q, v, a, tau, mask)
    assert_rel(a_h[mask], a[mask], 0.0)
    assert_rel(tau_h[~mask], tau[~mask], 0.0)
    assert_rel(rd.rnea(model, q, v, a_h), tau_h, 1e-9)
    assert_rel(rd.hybrid_dynamics(model, q, v, a, tau, np.ones(model.nv, bool))[1], rd.rnea(model, q, v, a), 1e-12)
    assert_rel(rd.hybrid_dynamics(model, q, v, a, tau, np.zeros(model.nv, bool))[0], rd.aba(model, q, v, tau), 1e-9)


@coupled_models
def test_constraints_on_a_coupled_model(model):
    """A point of the last body held still by a bilateral constraint, and a further coupling
    between two independent joints: the constraint accelerations vanish."""
    q, v, _ = states(model, "point")
    tau = rng_for(model.name, "point").standard_normal(model.nv)
    a_name, b_name = model.joint_names[0], model.joint_names[1]
    cons = [rd.PointConstraint(model.nbodies - 1, np.zeros(3), np.zeros(3)),
            rd.CouplingConstraint(a_name, b_name, 0.5)]
    res = rd.constrained_dynamics(model, q, v, tau, cons)
    J = rd.jacobian(model, q, model.nbodies - 1, "local_world_aligned")[:3]
    p = rd.frame_pose(model, q, model.link_names[-1])
    # the point's classical acceleration J a + Jdot v in world axes is zero
    acc = J @ res.a + rd.jacobian_dot_times_v(model, q, v, model.nbodies - 1, "local_world_aligned")[:3]
    assert np.abs(acc).max() < 1e-8 * max(1.0, np.abs(res.a).max()) and p.shape == (4, 4)
    ka, kb = model.dof_names.index(a_name), model.dof_names.index(b_name)
    assert abs(res.a[kb] - 0.5 * res.a[ka]) < 1e-9 * max(1.0, np.abs(res.a).max())


# -- identities and finite differences ----------------------------------------------------
@coupled_models
def test_terms_and_energies(model):
    q, v, a = states(model, "terms")
    M = rd.crba(model, q)
    M0 = rd.crba(model, q, armature=False)
    g, h = rd.gravity(model, q), rd.nonlinear_effects(model, q, v)
    assert_rel(rd.rnea(model, q, v, a, friction=False), M @ a + h, 1e-9)
    assert_rel(rd.rnea(model, q, np.zeros(model.nv), np.zeros(model.nv), friction=False), g, 1e-12)
    assert_rel(rd.generalized_momentum(model, q, v), M @ v, 1e-9)
    assert_rel(rd.kinetic_energy(model, q, v), 0.5 * v @ M0 @ v, 1e-9)
    assert_rel(rd.mass_matrix_from_jacobians(model, q), M, 1e-9)
    assert_rel(rd.inverse_mass_matrix(model, q) @ M, np.eye(model.nv), 1e-9)
    # gravity is the gradient of the potential energy along the coupled motion
    h_ = 1e-5
    dU = np.array([(rd.potential_energy(model, rd.integrate(model, q, h_ * e)) -
                    rd.potential_energy(model, rd.integrate(model, q, -h_ * e))) / (2 * h_) for e in np.eye(model.nv)])
    assert_rel(dU, g, 1e-6, "dU/dq")
    C = rd.coriolis_matrix(model, q, v)
    assert_rel(C @ v, h - g, 1e-9)
    assert_rel(np.einsum("ijk,k->ij", rd.christoffel_symbols(model, q), v), C, 1e-9)
    step = 1e-5
    Mdot = (rd.crba(model, rd.integrate(model, q, step * v), armature=False)
            - rd.crba(model, rd.integrate(model, q, -step * v), armature=False)) / (2 * step)
    S = Mdot - 2 * C
    assert_rel(S + S.T, np.zeros_like(S), 1e-6, "Mdot - 2C skew")


@coupled_models
def test_derivatives_by_differences(model):
    q, v, a = states(model, "derivatives")
    f_ext = rng_for(model.name, "wrench").standard_normal((model.nbodies, 6))
    dq, dv, da = rd.rnea_derivatives(model, q, v, a, f_ext)
    fq, fv = tangent_differences(lambda m, q_, v_, a_: rd.rnea(m, q_, v_, a_, f_ext), model, q, v, a)
    assert_rel(dq, fq, 1e-6, "dtau/dq")
    assert_rel(dv, fv, 1e-6, "dtau/dv")
    assert_rel(da, rd.crba(model, q), 1e-12)
    tau = rd.rnea(model, q, v, a)
    Aq, Av, Minv = rd.aba_derivatives(model, q, v, tau)
    fq, fv = tangent_differences(lambda m, q_, v_, t_: rd.aba(m, q_, v_, t_), model, q, v, tau)
    assert_rel(Aq, fq, 1e-6, "da/dq")
    assert_rel(Av, fv, 1e-6, "da/dv")
    assert_rel(Minv, rd.inverse_mass_matrix(model, q), 1e-9)
    gq = rd.gravity_derivatives(model, q)
    assert_rel(gq, tangent_differences(lambda m, q_, v_, x: rd.gravity(m, q_), model, q, v, a)[0], 1e-6)
    nq, nv = rd.nonlinear_effects_derivatives(model, q, v)
    fq, fv = tangent_differences(lambda m, q_, v_, x: rd.nonlinear_effects(m, q_, v_), model, q, v, a)
    assert_rel(nq, fq, 1e-6)
    assert_rel(nv, fv, 1e-6)
    pq, pM = rd.generalized_momentum_derivatives(model, q, v)
    assert_rel(pq, tangent_differences(lambda m, q_, v_, x: rd.generalized_momentum(m, q_, v), model, q, v, a)[0],
               1e-6)
    second = rd.rnea_second_derivatives(model, q, v, a)
    fq, fv = tangent_differences(lambda m, q_, v_, a_: rd.rnea_derivatives(m, q_, v_, a_)[0], model, q, v, a)
    assert_rel(second.d2tau_dq2, fq, 1e-5, "d2tau/dq2")
    assert_rel(second.d2tau_dadq, tangent_differences(lambda m, q_, v_, a_: rd.crba(m, q_), model, q, v, a)[0], 1e-5)


@coupled_models
def test_kinematics_by_differences(model):
    q, v, a = states(model, "kinematics")
    body = model.nbodies - 1
    J = rd.jacobian(model, q, body, "local_world_aligned")
    step = 1e-6
    T1, T0 = (rd.frame_pose(model, rd.integrate(model, q, s * v), model.link_names[body]) for s in (step, -step))
    assert_rel(J[:3] @ v, (T1[:3, 3] - T0[:3, 3]) / (2 * step), 1e-6, "linear velocity")
    W = (T1[:3, :3] - T0[:3, :3]) / (2 * step) @ rd.frame_pose(model, q, model.link_names[body])[:3, :3].T
    assert_rel(J[3:] @ v, [W[2, 1], W[0, 2], W[1, 0]], 1e-6, "angular velocity")
    c1, c0 = (rd.center_of_mass(model, rd.integrate(model, q, s * v)) for s in (step, -step))
    assert_rel(rd.com_jacobian(model, q) @ v, (c1 - c0) / (2 * step), 1e-6, "centre of mass")
    dVq, dVv = rd.frame_velocity_derivatives(model, q, v, body)
    fq, fv = tangent_differences(lambda m, q_, v_, x: rd.jacobian(m, q_, body) @ v_, model, q, v, a)
    assert_rel(dVq, fq, 1e-6)
    assert_rel(dVv, fv, 1e-9)
    dAq, dAv, dAa = rd.frame_acceleration_derivatives(model, q, v, a, body)
    acc = lambda m, q_, v_, a_: rd.jacobian(m, q_, body) @ a_ + rd.jacobian_dot_times_v(m, q_, v_, body)  # noqa: E731
    fq, fv = tangent_differences(acc, model, q, v, a)
    assert_rel(dAq, fq, 1e-6)
    assert_rel(dAv, fv, 1e-6)
    assert_rel(dAa, rd.jacobian(model, q, body), 1e-12)
    # Jdot v by differences of J along the motion
    J1, J0 = (rd.jacobian(model, rd.integrate(model, q, s * v), body) for s in (step, -step))
    assert_rel(rd.jacobian_dot_times_v(model, q, v, body), (J1 - J0) / (2 * step) @ v, 1e-6, "Jdot v")
    # forward kinematics of the full tree at E(q)
    qf, _ = full_state(model, q, v)
    assert_rel(rd.forward_kinematics(model, q), rd.forward_kinematics(model.full, qf), 0.0)


@coupled_models
def test_integrate_and_difference(model):
    q, v, _ = states(model, "integrate")
    q1 = rd.integrate(model, q, v)
    assert q1.shape == (model.nq,)
    assert_rel(rd.difference(model, q, q1), v, 1e-9)
    Jq, Jv = rd.integrate_jacobians(model, q, v)
    fq = np.stack([rd.difference(model, q1, rd.integrate(model, rd.integrate(model, q, 1e-6 * e), v))
                   - rd.difference(model, q1, rd.integrate(model, rd.integrate(model, q, -1e-6 * e), v))
                   for e in np.eye(model.nv)], axis=1) / 2e-6
    assert_rel(Jq, fq, 1e-6)
    J0, J1 = rd.difference_jacobians(model, q, q1)
    assert Jv.shape == J0.shape == J1.shape == (model.nv, model.nv)
    qf, vf = full_state(model, q, v)
    assert_rel(rd.integrate(model.full, qf, vf)[model.independent_q], q1, 1e-12)


@coupled_models
def test_regressors(model):
    q, v, a = states(model, "regressor")
    theta = model.inertial_parameters()
    assert_rel(rd.regressor(model, q, v, a) @ theta, rd.rnea(model, q, v, a, friction=False, armature=False), 1e-9)
    kw = dict(damping=True, coulomb=True, stiffness=True, armature=True, offset=True)
    from robodyn.algorithms.regressor import extended_parameters, extra_columns

    Y = rd.regressor(model, q, v, a, **kw)
    assert Y.shape[1] == 10 * model.nbodies + 5 * model.full.nv == 10 * model.nbodies + len(extra_columns(model, **kw))
    assert_rel(Y @ extended_parameters(model, **kw), rd.rnea(model, q, v, a), 1e-9)
    assert_rel(rd.slotine_li_regressor(model, q, v, v, a), rd.regressor(model, q, v, a), 1e-12)
    assert_rel(rd.kinetic_energy_regressor(model, q, v) @ theta, rd.kinetic_energy(model, q, v), 1e-9)
    assert_rel(rd.potential_energy_regressor(model, q) @ theta, rd.potential_energy(model, q), 1e-9)


@coupled_models
@pytest.mark.parametrize("fn,names", [
    (lambda m, q, v, a: rd.rnea(m, q, v, a), ("q", "v", "a")),
    (lambda m, q, v, tau: rd.aba(m, q, v, tau), ("q", "v", "tau")),
    (lambda m, q: rd.crba(m, q), ("q",)),
    (lambda m, q, v: rd.coriolis_matrix(m, q, v), ("q", "v")),
    (lambda m, q, v, a: rd.rnea_derivatives(m, q, v, a)[0], ("q", "v", "a")),
    (lambda m, q, v, tau: rd.aba_derivatives(m, q, v, tau)[1], ("q", "v", "tau")),
], ids=["rnea", "aba", "crba", "coriolis", "rnea_derivatives", "aba_derivatives"])
def test_batches(model, fn, names):
    check_batch(lambda m, **x: fn(m, **x), model, names, 1e-11)


def test_out_and_bad_input():
    model = MODELS[0]
    q, v, a = states(model, "out")
    out = np.empty(model.nv)
    assert rd.rnea(model, q, v, a, out=out) is out
    assert_rel(out, rd.rnea(model, q, v, a), 0.0)
    with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\)"):
        rd.rnea(model, np.zeros(model.full.nq), v, a)
    with pytest.raises(ValueError, match=rf"a: expected shape \(\.\.\., {model.nv}\)"):
        rd.rnea(model, q, v, np.zeros(model.full.nv))
    with pytest.raises(ValueError, match="NaN"):
        rd.aba(model, q, v, np.full(model.nv, np.nan))
    with pytest.raises(ValueError, match="NaN"):
        rd.rnea(model, np.full(model.nq, np.nan), v, a)


def test_coupled_model_checks_its_couplings():
    full = random_model(5, 3)
    a, b, c = full.body_joint_names[:3]
    chain = rd.CoupledModel(full, [(c, b, 2.0, 0.1), (b, a, -3.0, 0.2)])  # c = 2 (-3 a + 0.2) + 0.1
    assert chain.mimic == ((c, a, -6.0, pytest.approx(0.5)), (b, a, -3.0, 0.2)) and chain.nv == full.nv - 2
    with pytest.raises(rd.ModelError, match="mimic joint 'nope' is not a joint of the model"):
        rd.CoupledModel(full, [("nope", a, 1.0, 0.0)])
    with pytest.raises(rd.ModelError, match=f"joint {a!r} mimics itself"):
        rd.CoupledModel(full, [(a, a, 1.0, 0.0)])
    with pytest.raises(rd.ModelError, match="mimic joints form a cycle"):
        rd.CoupledModel(full, [(a, b, 1.0, 0.0), (b, c, 1.0, 0.0), (c, a, 1.0, 0.0)])
    with pytest.raises(rd.ModelError, match=f"joint {a!r} mimics two joints"):
        rd.CoupledModel(full, [(a, b, 1.0, 0.0), (a, c, 1.0, 0.0)])
    with pytest.raises(rd.ModelError, match="must be finite"):
        rd.CoupledModel(full, [(a, b, np.nan, 0.0)])
    floating = random_model(3, 4, floating_base=True)
    with pytest.raises(rd.ModelError, match="source joint 'root_joint' is a free joint"):
        rd.CoupledModel(floating, [(floating.body_joint_names[1], "root_joint", 1.0, 0.0)])
    with pytest.raises(TypeError, match="full must be a robodyn Model"):
        rd.CoupledModel("robot", [])


def test_functions_without_couplings_say_so():
    """What does not take a coupled model yet refuses it, saying so, never with a wrong answer:
    every field in the full tree's coordinates raises."""
    model = MODELS[0]
    q = rd.random.random_configuration(model, rng_for("refusals"))
    say = "does not take a model with mimic couplings.*model.full.*mimic='independent'"
    for key in ("kernel", "idx_q", "idx_v", "damping", "armature", "stiffness"):
        with pytest.raises(rd.ModelError, match=say):
            getattr(model, key)
        assert not hasattr(model, key)
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        _ = model.nonsense
    with pytest.raises(rd.ModelError, match=say):
        rd.inertia_bounds(model)


# -- URDF files ---------------------------------------------------------------------------
MIMIC_FILES = [p for p in example_robot_urdfs() if "<mimic" in p.read_text()]


def _load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_urdf(path, physical="warn", **kw)


def test_the_example_robot_data_files_with_mimic_joints_are_known():
    assert sorted(erd_id(p) for p in MIMIC_FILES) == sorted(PINOCCHIO_MIMIC + PINOCCHIO_REFUSES_MIMIC + FIXED_ONLY)


# Files whose mimic joints Pinocchio builds (mimic=True); those it refuses ("The parent joint of
# the mimic joint is not in the kinematic tree": a source after its mimic joint in its tree
# order, or a source that does not exist); those whose mimic elements sit on fixed joints only.
PINOCCHIO_MIMIC = ["baxter_description/urdf/baxter.urdf", "panda_description/urdf/panda.urdf",
                   "panda_description/urdf/panda_collision.urdf", "pr2_description/urdf/pr2.urdf",
                   "tiago_pro_description/robots/tiago_pro.urdf"]
PINOCCHIO_REFUSES_MIMIC = ["alex_description/urdf/alex_psyonic_hands.urdf", "romeo_description/urdf/romeo.urdf",
                           "talos_data/robots/talos_full_v2.urdf", "talos_data/robots/talos_full_v2_box.urdf"]
FIXED_ONLY = ["talos_data/robots/talos_left_arm.urdf", "talos_data/robots/talos_reduced.urdf",
              "talos_data/robots/talos_reduced_box.urdf", "talos_data/robots/talos_reduced_corrected.urdf"]


def _path(rel):
    return next(p for p in MIMIC_FILES if erd_id(p) == rel)


def _pin_q(model, pm, q):
    """Pinocchio's configuration of the coupled model's ``q`` (continuous joints as cos, sin)."""
    qp = np.zeros(pm.nq)
    full = model.full
    for j in range(1, pm.njoints):
        joint = pm.joints[j]
        if joint.shortname() == "JointModelMimic":
            continue
        i = full.body_joint_names.index(pm.names[j])
        k = int(np.flatnonzero(model.independent_q == full.idx_q[i])[0])
        assert joint.idx_v == int(np.flatnonzero(model.independent_v == full.idx_v[i])[0])  # the same order
        n = int(J.NQ[full.joint_type[i]])
        qp[joint.idx_q:joint.idx_q + joint.nq] = [np.cos(q[k]), np.sin(q[k])] if joint.nq == 2 and joint.nv == 1 \
            else q[k:k + n]
    return qp


@pytest.mark.parametrize("rel", PINOCCHIO_MIMIC)
@pytest.mark.parametrize("floating_base", (False, True), ids=("fixed", "floating"))
def test_mimic_joints_agree_with_pinocchio(rel, floating_base):
    """rnea, crba and the Jacobian of every link, against Pinocchio's mimic joints."""
    path = _path(rel)
    model = _load(path, floating_base=floating_base)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer(), mimic=True) if floating_base \
        else pin.buildModelFromUrdf(str(path), mimic=True)
    n_mimic = sum(joint.shortname() == "JointModelMimic" for joint in pm.joints)
    assert isinstance(model, rd.CoupledModel) and len(model.mimic) == n_mimic and model.nv == pm.nv
    data = pm.createData()
    for k in range(3):
        rng = rng_for(rel, floating_base, k)
        q = rd.random.random_configuration(model, rng)
        v, a = rng.standard_normal((2, model.nv))
        qp = _pin_q(model, pm, q)
        assert_rel(rd.rnea(model, q, v, a, friction=False, armature=False), pin.rnea(pm, data, qp, v, a), 1e-9, "rnea")
        Mp = pin.crba(pm, data, qp)
        assert_rel(rd.crba(model, q, armature=False), np.triu(Mp) + np.triu(Mp, 1).T, 1e-9, "crba")
        pin.computeJointJacobians(pm, data, qp)
        pin.updateFramePlacements(pm, data)
        for name in model.link_names[::3]:
            Jp = pin.getFrameJacobian(pm, data, pm.getFrameId(name), pin.LOCAL_WORLD_ALIGNED)
            assert_rel(rd.jacobian(model, q, name, "local_world_aligned"), Jp, 1e-9, f"Jacobian of {name}")


@pytest.mark.parametrize("rel", PINOCCHIO_MIMIC + ["talos_data/robots/talos_full_v2.urdf",
                                                    "talos_data/robots/talos_full_v2_box.urdf"])
def test_mimic_files_move_as_their_full_trees_under_couplings(rel):
    """Every file with mimic joints on moving joints (Pinocchio refuses some: robodyn resolves a
    source that comes later in the tree): forward dynamics against the constrained full tree."""
    model = _load(_path(rel), floating_base=True)
    assert isinstance(model, rd.CoupledModel)
    rng = rng_for(rel, "constrained")
    q = rd.random.random_configuration(model, rng)
    v, tau = rng.standard_normal((2, model.nv))
    qf, vf = full_state(model, q, v)
    tau_full = np.zeros(model.full.nv)
    tau_full[model.independent_v] = tau
    res = rd.constrained_dynamics(model.full, qf, vf, tau_full, couplings(model))
    assert_rel(model.G @ rd.aba(model, q, v, tau), res.a, 1e-8, rel)


def test_romeo_hands_have_massless_links():
    """Romeo's thumb links have no inertia about their joints: the coupled model loads, its
    forward dynamics refuses with a message (as the full tree's articulated-body pass does)."""
    model = _load(_path("romeo_description/urdf/romeo.urdf"))
    assert isinstance(model, rd.CoupledModel) and len(model.mimic) == 22
    q = rd.random.random_configuration(model, rng_for("romeo"))
    with pytest.raises(ValueError, match="aba: the mass matrix of 'romeo' in its independent coordinates is not "
                                         "positive definite"):
        rd.aba(model, q, np.zeros(model.nv), np.zeros(model.nv))


def test_alex_mimics_a_joint_the_file_does_not_have():
    """Its mimic joints name a source ``index_q1`` the file lacks (likewise the other fingers):
    loaded as independent joints with a warning that names them (Pinocchio's default reads them
    so; with mimic=True it refuses the file)."""
    path = _path("alex_description/urdf/alex_psyonic_hands.urdf")
    with pytest.warns(rd.RobodynWarning, match=r"source is not a moving joint.*Left_index_q2 \(source 'index_q1'\)"):
        model = rd.load_urdf(path)
    assert isinstance(model, rd.Model) and model.nv == 39


@pytest.mark.parametrize("rel", FIXED_ONLY)
def test_mimic_elements_on_fixed_joints_are_ignored(rel):
    with pytest.warns(rd.RobodynWarning, match=r"ignored elements without rigid-body dynamics: .*<mimic>"):
        model = rd.load_urdf(_path(rel))
    assert isinstance(model, rd.Model)


def test_urdf_mimic_errors():
    urdf = ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
            '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>'
            '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>{}</joint>'
            '</robot>')
    with pytest.raises(rd.ModelError, match=r"<mimic> \(line 1\).*without a joint attribute|<mimic.*without a joint"):
        rd.load_urdf(urdf.format('<mimic multiplier="2"/>'))
    model = rd.load_urdf(urdf.format('<mimic joint="j1" multiplier="-2" offset="0.1"/>'))
    assert model.mimic == (("j2", "j1", -2.0, 0.1),) and model.nv == 1
    assert_rel(rd.forward_kinematics(model, [0.3]), rd.forward_kinematics(model.full, [0.3, -0.5]), 0.0)
    with pytest.raises(rd.ModelError, match="multiplier"):
        rd.load_urdf(urdf.format('<mimic joint="j1" multiplier="two"/>'))


# -- simulation and control ---------------------------------------------------------------
def _reduced_rk4(model, q, v, dt, steps, controller=None):
    """The coupled model's own RK4 (fixed base, 1-dof joints: q + dt v), written here."""
    def f(t, q, v):
        tau = np.zeros(model.nv) if controller is None else controller(t, q, v)
        return rd.aba(model, q, v, np.clip(tau, -model.effort_limit, model.effort_limit))

    for s in range(steps):
        t = s * dt
        k1q, k1v = v, f(t, q, v)
        k2q, k2v = v + dt / 2 * k1v, f(t + dt / 2, q + dt / 2 * k1q, v + dt / 2 * k1v)
        k3q, k3v = v + dt / 2 * k2v, f(t + dt / 2, q + dt / 2 * k2q, v + dt / 2 * k2v)
        k4q, k4v = v + dt * k3v, f(t + dt, q + dt * k3q, v + dt * k3v)
        q, v = q + dt / 6 * (k1q + 2 * k2q + 2 * k3q + k4q), v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    return q, v


def test_simulation_is_the_coupled_models_own_integration():
    """RK4 and semi-implicit Euler on a fixed base: the samples equal the coupled model's own
    integration written out here (the full tree under the couplings keeps them exactly)."""
    model = MODELS[0]
    rng = rng_for("simulate")
    q0, v0 = rd.random.random_configuration(model, rng), rng.standard_normal(model.nv)
    law = rd.control.PDGravity(model, q0 + 0.2, kp=20.0, kd=3.0)
    traj = rd.simulate(model, q0, v0, 0.1, 0.01, law, "rk4")
    assert traj.model is model and traj.q.shape == (11, model.nq) and traj.tau.shape == (11, model.nv)
    q, v = _reduced_rk4(model, q0, v0, 0.01, 10, law)
    assert_rel(traj.q[-1], q, 1e-12)
    assert_rel(traj.v[-1], v, 1e-12)
    assert_rel(traj.tau[3], np.clip(law(0.03, traj.q[3], traj.v[3]), -model.effort_limit, model.effort_limit), 1e-12)
    assert traj.lyapunov is not None and traj.q_desired.shape == traj.q.shape
    euler = rd.simulate(model, q0, v0, 0.05, 0.01, integrator="semi_implicit_euler")
    q, v = q0, v0
    for _ in range(5):
        v = v + 0.01 * rd.aba(model, q, v, np.zeros(model.nv))
        q = q + 0.01 * v
    assert_rel(euler.q[-1], q, 1e-12)
    assert_rel(euler.v[-1], v, 1e-12)


def test_simulation_of_a_floating_coupled_model_conserves_energy():
    """Without friction, springs excepted (conservative), a free-floating tree with mimic
    joints keeps its energy (RK4 to its order) and its mimic joints on their couplings."""
    model = rd.CoupledModel(MODELS[3].full.replace(damping=np.zeros(MODELS[3].full.nv),
                                                   coulomb=np.zeros(MODELS[3].full.nv)), MODELS[3].mimic)
    rng = rng_for("energy")
    q0, v0 = rd.random.random_configuration(model, rng), 0.5 * rng.standard_normal(model.nv)
    traj = rd.simulate(model, q0, v0, 0.2, 0.002)
    assert np.abs(traj.energy - traj.energy[0]).max() < 1e-6 * max(1.0, abs(traj.energy[0]))
    assert traj.constraint_force is None  # the couplings' forces are internal


def test_simulation_with_constraints_and_wrenches_on_a_coupled_model():
    model = MODELS[1]
    q0 = rd.random.random_configuration(model, rng_for("pinned"))
    point = rd.PointConstraint(model.nbodies - 1, np.zeros(3), rd.frame_pose(model, q0, model.link_names[-1])[:3, 3])
    traj = rd.simulate(model, q0, np.zeros(model.nv), 0.05, 0.005, constraints=[point],
                       f_ext=np.ones((model.nbodies, 6)))
    assert traj.constraint_force.shape == (11, 3)
    tip = np.array([rd.frame_pose(model, q, model.link_names[-1])[:3, 3] for q in traj.q])
    assert np.abs(tip - tip[0]).max() < 1e-6


def test_contacts_with_constraints_are_refused_on_a_coupled_model():
    model = MODELS[0]
    q0 = rd.random.random_configuration(model, rng_for("refuse"))
    from robodyn.contact import Contacts, Plane, Sphere

    touch = Contacts([Sphere(model.nbodies - 1, 0.05)], surfaces=[Plane(height=0.0)])
    with pytest.raises(ValueError, match="constraints: not with contacts"):
        rd.simulate(model, q0, np.zeros(model.nv), 0.01, 0.001, contacts=touch,
                    constraints=rd.CouplingConstraint(*model.joint_names[:2], 1.0))


def _box_friction(W, b, bound, sweeps=20000):
    """``|f| <= bound`` complementary to ``b - W f`` by projected Gauss-Seidel (the test's own)."""
    f = np.zeros(b.shape[0])
    for _ in range(sweeps):
        for k in range(f.shape[0]):
            f[k] = np.clip(f[k] + (b[k] - W[k] @ f) / W[k, k], -bound[k], bound[k])
    return f


def test_stiction_of_a_coupled_model_is_its_own_friction_step():
    """Every dof of the tree with dry friction (mimic joints' included) resists the coupled
    model's coordinates: the step below, written here in the independent coordinates (the dry
    friction box of coordinate i is sum_k |G[k, i]| F_k), is the simulation's."""
    model = MODELS[0]
    full = model.full.replace(coulomb=np.linspace(1.0, 12.0, model.full.nv), stribeck=np.full(model.full.nv, 0.3),
                              stribeck_velocity=np.full(model.full.nv, 0.05), damping=np.full(model.full.nv, 0.2))
    model = rd.CoupledModel(full, model.mimic)
    dry = rd.CoupledModel(full.replace(coulomb=np.zeros(full.nv), stribeck=np.zeros(full.nv)), model.mimic)
    q0 = rd.random.random_configuration(model, rng_for("stiction"))
    dt, steps = 2e-3, 60
    traj = rd.simulate(model, q0, np.zeros(model.nv), steps * dt, dt, stiction=True)
    q, v = q0.copy(), np.zeros(model.nv)
    absG = np.abs(model.G)
    for s in range(steps):
        v_free = v + dt * rd.aba(dry, q, v, np.zeros(model.nv))
        W = dt * np.linalg.inv(rd.crba(model, q))
        vf = model.G @ v
        bound = absG.T @ (full.coulomb + full.stribeck * np.exp(-(vf / full.stribeck_velocity) ** 2))
        f = _box_friction(W, v_free, bound)
        assert_rel(traj.joint_friction[s], f, 1e-7, f"friction at step {s}")
        v = v_free - W @ f
        v[np.abs(f) < bound] = 0.0
        q = rd.integrate(model, q, dt * v)
        assert_rel(traj.v[s + 1], v, 1e-7, f"velocity at step {s + 1}")
        assert_rel(traj.q[s + 1], q, 1e-9, f"configuration at step {s + 1}")
    assert np.any(traj.v[-1] == 0.0) and np.any(traj.v[-1] != 0.0), "some joints stick, others slide"
    qf = rd.coupling.expand_q(model, traj.q)
    for joint, source, r, o in model.mimic:  # the couplings hold
        i, k = (full.idx_q[full.body_joint_names.index(n)] for n in (joint, source))
        assert_rel(qf[:, i], r * qf[:, k] + o, 1e-12)


PENDULUM = """<robot name="pendulum">
  <link name="base"/><link name="arm">{arm}</link><link name="hand">{hand}</link>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
  <joint name="wrist" type="continuous"><parent link="arm"/><child link="hand"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><dynamics friction="{friction}"/><mimic joint="shoulder" multiplier="2"/></joint>
</robot>"""


@pytest.mark.parametrize("margin,sticks", [(1.01, True), (0.99, False)])
def test_a_mimic_joints_friction_holds_its_source_with_the_multiplier(margin, sticks):
    """The only dry friction is the wrist's, a mimic of the shoulder with multiplier 2: the
    shoulder holds still while gravity's torque on it is below twice the wrist's friction."""
    parts = dict(arm=_INERTIAL.format(c="0.2 0 0", m=1.0, i=0.01), hand=_INERTIAL.format(c="0.1 0 0", m=0.5, i=0.005))
    q0 = np.array([0.3])
    g = rd.gravity(rd.load_urdf(PENDULUM.format(friction=0.0, **parts)), q0)[0]
    model = rd.load_urdf(PENDULUM.format(friction=margin * abs(g) / 2.0, **parts))
    traj = rd.simulate(model, q0, np.zeros(1), 0.2, 1e-3, stiction=True)
    if sticks:
        assert np.all(traj.v == 0.0) and np.all(traj.q == q0)
        assert_rel(traj.joint_friction[-1], [-g], 1e-9, "the friction holds the robot (M a = -g - f = 0)")
    else:
        assert np.abs(traj.v[-1, 0]) > 1e-3
        assert_rel(np.abs(traj.joint_friction[-1]), [margin * abs(g)], 1e-6, "sliding: the full box")


_INERTIAL = '<inertial><origin xyz="{c}"/><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0.0002" ' \
            'ixz="0" iyz="0.0003"/></inertial>'
# A body on a free joint, an arm on a hinge and a paddle that turns back by the same angle about the
# same axis (multiplier -1): the paddle keeps its pose in the body, welded to it.
LOCKED = """<robot name="locked">
  <link name="base">{base}</link><link name="arm">{arm}</link><link name="paddle">{paddle}</link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0.1 0.05 -0.02" rpy="0.3 0.2 0.1"/><axis xyz="0.6 0 0.8"/></joint>
  <joint name="follower" type="{kind}"><parent link="{parent}"/><child link="paddle"/>{origin}
    <axis xyz="0.6 0 0.8"/>{mimic}</joint>
</robot>"""


def _locked(coupled: bool) -> rd.Model:
    parts = dict(base=_INERTIAL.format(c="0 0 0.02", m=2.0, i=0.02), arm=_INERTIAL.format(c="0.1 0 0", m=0.5, i=0.004),
                 paddle=_INERTIAL.format(c="0.05 0.1 -0.03", m=0.7, i=0.006))
    if coupled:
        xml = LOCKED.format(kind="continuous", parent="arm", origin="", mimic='<mimic joint="hinge" multiplier="-1"/>',
                            **parts)
    else:
        xml = LOCKED.format(kind="fixed", parent="base", origin='<origin xyz="0.1 0.05 -0.02" rpy="0.3 0.2 0.1"/>',
                            mimic="", **parts)
    return rd.load_urdf(xml, floating_base=True)


def test_contacts_of_a_coupled_model_are_those_of_its_equivalent_tree():
    """The coupled model (a paddle on a mimic joint that undoes its arm's turn) falls on the
    floor, bounces and slides as the tree with the paddle welded to the body: the coupled
    contact step (G^T M G, J G) against the plain one, same contacts on the same links."""
    from robodyn.contact import Contacts, Plane, Sphere

    coupled, welded = _locked(True), _locked(False)
    assert isinstance(coupled, rd.CoupledModel) and coupled.nv == welded.nv == 7 and coupled.full.nv == 8

    def touch(model):
        return Contacts([Sphere("paddle", 0.03, (0.1, 0.2, -0.05), "p1"), Sphere("paddle", 0.02, (-0.1, 0.0, 0.05), "p2"),
                         Sphere("arm", 0.025, (0.2, 0.0, 0.0), "arm"), Sphere("base", 0.04, name="base")],
                        surfaces=[Plane(height=0.0, friction=0.6, restitution=0.3)], tolerance=1e-12,
                        max_iterations=500)

    q0 = np.array([0.0, 0.0, 0.15, 0.1, -0.2, 0.3, 0.9, 0.4])
    q0[3:7] /= np.linalg.norm(q0[3:7])
    v0 = np.array([0.3, -0.1, -0.5, 1.0, 2.0, -1.5, 3.0])
    runs = [rd.simulate(m, q0, v0, 0.4, 0.001, contacts=touch(m)) for m in (coupled, welded)]
    a, b = runs
    assert np.any(a.contact_force[..., 2] > 0) and np.any(a.contact_force[:, 0, 2] > 0)  # the paddle touches
    assert_rel(a.q, b.q, 1e-8)
    assert_rel(a.v, b.v, 1e-8)
    assert_rel(a.contact_force, b.contact_force, 1e-6)
    assert_rel(a.energy, b.energy, 1e-8)
    # the full tree's state stayed on the coupling (the paddle's angle is minus the arm's)
    qf = rd.coupling.expand_q(coupled, a.q)
    assert_rel(qf[:, 8], -qf[:, 7], 1e-15)


HAND = """<robot name="hand">
  <link name="palm">{palm}</link><link name="left">{finger}</link><link name="right">{finger}</link>
  <joint name="left" type="prismatic"><parent link="palm"/><child link="left"/><origin xyz="0 0.03 -0.02"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
  <joint name="right" type="prismatic"><parent link="palm"/><child link="right"/><origin xyz="0 -0.03 -0.02"/>
    <axis xyz="0 -1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/><mimic joint="left"/></joint>
</robot>"""


def test_a_coupled_gripper_rests_on_the_floor():
    """A floating palm with two fingers on prismatic joints, the second a mimic of the first
    (as Panda's hand), standing on its fingertips and palm corners: at rest the normal forces
    carry the weight, the friction forces of the fingertips cancel, and the fingers keep their
    coupling."""
    from robodyn.contact import Contacts, Plane, Sphere

    hand = rd.load_urdf(HAND.format(palm=_INERTIAL.format(c="0 0 0", m=0.6, i=0.002),
                                    finger=_INERTIAL.format(c="0 0 -0.02", m=0.05, i=0.002)), floating_base=True)
    assert isinstance(hand, rd.CoupledModel) and hand.nv == 7
    spheres = [Sphere("palm", 0.01, (x, 0.0, -0.06), f"palm{x:+}") for x in (-0.04, 0.04)]
    spheres += [Sphere(name, 0.01, (0.0, 0.0, -0.04), name) for name in ("left", "right")]
    q0 = np.array([0.0, 0.0, 0.08, 0.0, 0.0, 0.0, 1.0, 0.01])
    run = rd.simulate(hand, q0, np.zeros(7), 1.0, 0.001, contacts=Contacts(spheres, surfaces=[Plane(friction=0.8)]))
    weight = -hand.full.theta[:, 0].sum() * hand.gravity[2]
    assert np.all(run.contact_force[-1, :, 2] > 0)
    assert_rel(run.contact_force[-1, :, 2].sum(), weight, 1e-6)
    assert_rel(run.contact_force[-1, :, :2].sum(axis=0), np.zeros(2), 1e-6)
    assert np.abs(run.v[-1]).max() < 1e-6
    qf = rd.coupling.expand_q(hand, run.q)
    assert_rel(qf[:, 8], qf[:, 7], 1e-15)


def test_joint_pd_on_a_coupled_floating_model():
    model = MODELS[1]
    q0 = rd.random.random_configuration(model, rng_for("jointpd"))
    law = rd.control.JointPD(model, q0, 10.0, 1.0)
    assert law.actuated.tolist() == list(range(6, model.nv))
    q = rd.integrate(model, q0, 0.1 * np.ones(model.nv))
    tau = law(0.0, q, np.zeros(model.nv))
    assert np.all(tau[:6] == 0)
    assert_rel(tau[6:], 10.0 * (q0 - q)[law.q_index], 1e-12)


# -- command line -------------------------------------------------------------------------
def test_command_line_on_a_urdf_with_mimic_joints(capsys, tmp_path):
    """info marks the mimic joint; simulate (with and without the ground), view and bench
    (compared with Pinocchio's mimic joints where Pinocchio runs the algorithm) run on the
    coupled model; never a traceback."""
    from robodyn.cli import main

    path = str(_path("panda_description/urdf/panda.urdf"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        assert main(["info", path]) == 0
        out = capsys.readouterr().out
        assert "CoupledModel: nq=8, nv=8" in out and "panda_finger_joint2 = 1 panda_finger_joint1" in out
        assert main(["simulate", path, "--duration", "0.02", "--controller", "pd-gravity"]) == 0
        assert "20 steps" in capsys.readouterr().out
        assert main(["view", path, "--png", str(tmp_path / "panda.png")]) == 0
        assert (tmp_path / "panda.png").stat().st_size > 1000
        assert main(["bench", path, "--batch", "10"]) == 0
        out = capsys.readouterr().out
        assert "no Pinocchio time: Pinocchio does not run that algorithm on mimic joints" in out
        assert re.search(r"aba \(batch\) +[0-9.]+ *\n", out)  # robodyn's time, no Pinocchio's
        assert re.search(r"rnea \(batch\) +[0-9.]+ +[0-9.]+ +[0-9.]+", out)
        assert main(["simulate", path, "--ground", "--duration", "0.01", "--drop", "0.01"]) == 0
        out = capsys.readouterr().out
        assert main(["simulate", path, "--ground", "--duration", "0.01", "--drop", "0.01", "--mimic", "independent"]) == 0
        spheres = re.search(r"contacts: \d+ on the ground \([^)]*\)", capsys.readouterr().out).group()
        assert "10 steps" in out and spheres in out  # the same collision spheres on the same links
        assert main(["info", path, "--mimic", "independent"]) == 0
        assert "Model 'panda': nq=9, nv=9" in capsys.readouterr().out


def test_excite_and_identify_commands_on_a_coupled_model(capsys, tmp_path):
    """robodyn excite writes a trajectory of the independent joints; robodyn identify, on that
    trajectory with the coupled model's torques, writes a URDF with the <mimic> element whose
    model reproduces the torques."""
    from robodyn.cli import main
    from robodyn.io.log import read_log, write_log

    path = str(_path("panda_description/urdf/panda.urdf"))
    model = _load(_path("panda_description/urdf/panda.urdf"))
    traj = tmp_path / "excite.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        assert main(["excite", path, "--duration", "2", "--period", "2", "--harmonics", "2", "--samples", "30",
                     "--maxiter", "3", "--rate", "100", "--out", str(traj)]) == 0
        log = read_log(traj, model)
        assert log.q.shape[1] == model.nv == 8
        data = tmp_path / "data.csv"
        write_log(data, model, log.t, log.q, v=log.v, a=log.a, tau=rd.rnea(model, log.q, log.v, log.a))
        assert main(["identify", path, str(data), "--out", str(tmp_path / "id.urdf")]) == 0
        assert "Traceback" not in capsys.readouterr().err
        found = rd.load_urdf(tmp_path / "id.urdf")
    assert isinstance(found, rd.CoupledModel) and found.mimic == model.mimic
    tau = rd.rnea(model, log.q, log.v, log.a)
    assert_rel(rd.rnea(found, log.q, log.v, log.a), tau, 1e-6)


@pytest.mark.parametrize("integrator", ["semi_implicit_euler", "rk4"])
@pytest.mark.parametrize("index", [0, 3], ids=["fixed", "floating-mixed"])
def test_linearize_a_coupled_model_against_differences_of_simulate(index, integrator):
    from test_linearize import DT, TOL, by_differences

    model = MODELS[index]
    q, v, tau = states(model, "linearize", integrator)
    A, B = rd.linearize(model, q, v, tau, DT, integrator)
    fd_A, fd_B = by_differences(model, q, v, tau, integrator)
    assert A.shape == (2 * model.nv, 2 * model.nv) and B.shape == (2 * model.nv, model.nv)
    assert_rel(A, fd_A, TOL, "A")
    assert_rel(B, fd_B, TOL, "B")


def test_identification_of_a_coupled_model():
    """The base parameters and the estimate from exact torques: the coupled model's own
    parameters (friction, springs and armature of every joint of the tree, the mimic joints'
    included), and the identified model is a coupled model with the same dynamics."""
    from robodyn import identification as ident
    from robodyn.identification.base import random_states

    model = MODELS[0]
    rng = rng_for("identify")
    q, v, a = random_states(model, 300, rng)
    assert q.shape == (300, model.nq)
    log = ident.Log(np.arange(300) * 0.01, q, v, a, rd.rnea(model, q, v, a))
    result = ident.identify(model, log, damping=True, coulomb=True, stiffness=True, armature=True, offset=True)
    assert_rel(result.estimate.beta, result.beta_nominal, 1e-9)
    found = result.identified_model()
    assert isinstance(found, rd.CoupledModel) and found.mimic == model.mimic
    assert_rel(rd.rnea(found, q[:5], v[:5], a[:5]), rd.rnea(model, q[:5], v[:5], a[:5]), 1e-8)


@pytest.mark.parametrize("index", [0, 1], ids=["fixed", "floating"])
def test_write_urdf_round_trip_of_a_coupled_model(index, tmp_path):
    """The tree with a <mimic> on each mimic joint: robodyn reads back the same couplings and
    dynamics, and Pinocchio builds its mimic joints from the file (same rnea and crba)."""
    model = MODELS[index]
    full = model.full
    one = np.repeat(J.NV[full.joint_type] == 1, J.NV[full.joint_type])  # URDF: friction on 1-dof joints only
    rigid = rd.CoupledModel(full.replace(coulomb=np.zeros(full.nv), stiffness=np.zeros(full.nv),
                                         spring_reference=np.zeros(full.nv), armature=np.zeros(full.nv),
                                         coulomb_smoothing=0.0, damping=full.damping * one,
                                         lower=np.where(one, -3.0, -np.inf), upper=np.where(one, 3.0, np.inf)),
                            model.mimic)
    path = tmp_path / "coupled.urdf"
    rd.write_urdf(rigid, path)
    back = rd.load_urdf(path, floating_base=model.floating_base)
    assert isinstance(back, rd.CoupledModel)
    assert sorted(back.mimic) == sorted((j, s, pytest.approx(r), pytest.approx(o)) for j, s, r, o in model.mimic)
    q, v, a = states(model, "write")
    # the loader orders a link's children by joint name: match the coordinates by name
    iq = [back.q_names.index(n) for n in rigid.q_names]
    iv = [back.dof_names.index(n) for n in rigid.dof_names]
    qb, vb, ab = np.empty(back.nq), np.empty(back.nv), np.empty(back.nv)
    qb[iq], vb[iv], ab[iv] = q, v, a
    tau = rd.rnea(rigid, q, v, a)
    assert_rel(rd.rnea(back, qb, vb, ab)[iv], tau, 1e-9)
    if model.floating_base:
        return
    pm = pin.buildModelFromUrdf(str(path), mimic=True)
    data = pm.createData()
    qp = _pin_q(back, pm, qb)
    assert_rel(pin.rnea(pm, data, qp, vb, ab)[iv], rd.rnea(rigid, q, v, a, friction=False), 1e-9)
    Mp = pin.crba(pm, data, qp)
    assert_rel((np.triu(Mp) + np.triu(Mp, 1).T)[np.ix_(iv, iv)], rd.crba(rigid, q), 1e-9)
