"""Hybrid dynamics (robodyn.hybrid_dynamics): rnea and aba at the two extremes, a partitioned
solve of the equation of motion in between (random trees and example-robot-data URDFs with
Pinocchio's M and h; external wrenches in the three frames against Pinocchio's rnea and aba),
the two-link arm in closed form, batches, singular bodies and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, PLANAR_2R, assert_rel, massless_leaf_model, planar_2r, planar_2r_terms,
                     random_models, rng_for, states, with_friction_and_armature)
from robodyn import joints as J
from test_pinocchio import _pin_forces
from urdf_subset import load_pair, pairs


def random_mask(model: rd.Model, rng: np.random.Generator) -> np.ndarray:
    """A random mask with both kinds of entries where possible, the dofs of one joint alike
    (a free joint's six, a spherical joint's three)."""
    mask = rng.random(model.nv) < 0.5
    for i in range(model.nbodies):
        k, n = model.idx_v[i], J.NV[model.joint_type[i]]
        mask[k:k + n] = mask[k]
    if model.nbodies > 1 and (mask.all() or not mask.any()):
        k = model.idx_v[-1]
        mask[k:] = not mask[k]
    return mask


def partitioned(M, h, a_known, tau_known, mask):
    """``M a + h = tau`` solved for ``a[~mask]`` and ``tau[mask]`` (dense, the reference)."""
    k, u = mask, ~mask
    a = np.where(k, a_known, 0.0)
    a[u] = np.linalg.solve(M[np.ix_(u, u)], tau_known[u] - h[u] - M[np.ix_(u, k)] @ a_known[k])
    tau = np.where(k, M @ a + h, tau_known)
    return a, tau


@random_models
def test_all_known_is_rnea_and_none_known_is_aba(model):
    m = with_friction_and_armature(model, rng_for(model.name, "hd"), 0.05)
    q, v, a = states(m, "extremes")
    tau = rd.rnea(m, q, v, a)
    a_out, tau_out = rd.hybrid_dynamics(m, q, v, a, np.full(m.nv, np.nan), np.ones(m.nv, bool))
    assert np.array_equal(a_out, a)
    assert_rel(tau_out, tau, 1e-10, "all known")
    a_out, tau_out = rd.hybrid_dynamics(m, q, v, np.full(m.nv, np.nan), tau, np.zeros(m.nv, bool))
    assert np.array_equal(tau_out, tau)
    assert_rel(a_out, rd.aba(m, q, v, tau), 1e-10, "none known")


@random_models
@pytest.mark.parametrize("trial", range(3))
def test_mixed_masks_against_a_partitioned_solve(model, trial):
    q, v, a = states(model, "mixed", trial)
    rng = rng_for(model.name, "mask", trial)
    mask = random_mask(model, rng)
    tau_known = rng.standard_normal(model.nv)
    a_ref, tau_ref = partitioned(rd.crba(model, q), rd.nonlinear_effects(model, q, v), a, tau_known, mask)
    a_out, tau_out = rd.hybrid_dynamics(model, q, v, np.where(mask, a, np.nan), np.where(mask, np.nan, tau_known),
                                        mask, friction=False)
    assert_rel(a_out, a_ref, 1e-9, "a")
    assert_rel(tau_out, tau_ref, 1e-9, "tau")
    assert_rel(rd.rnea(model, q, v, a_out, friction=False), tau_out, 1e-9, "rnea(a) == tau")


@random_models
@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_friction_armature_and_external_wrenches(model, frame):
    """The hybrid solution satisfies rnea with the same friction, armature and wrenches."""
    m = with_friction_and_armature(model, rng_for(model.name, frame))
    q, v, a = states(m, "fext", frame)
    rng = rng_for(model.name, "fext-mask", frame)
    mask, tau_known = random_mask(m, rng), rng.standard_normal(m.nv)
    f_ext = rng.standard_normal((m.nbodies, 6))
    for kw in ({}, {"friction": False, "armature": False}):
        a_out, tau_out = rd.hybrid_dynamics(m, q, v, a, tau_known, mask, f_ext, frame, **kw)
        assert np.array_equal(a_out[mask], a[mask]) and np.array_equal(tau_out[~mask], tau_known[~mask])
        assert_rel(rd.rnea(m, q, v, a_out, f_ext, frame, **kw), tau_out, 1e-9, str(kw))


def test_two_link_arm_closed_form():
    """Shoulder acceleration and elbow torque given: the textbook M, C, g of the 2R arm."""
    model = planar_2r(**PLANAR_2R)
    rng = rng_for("2r-hybrid")
    for _ in range(3):
        q, qd = rng.uniform(-np.pi, np.pi, 2), rng.standard_normal(2)
        M, C, g = planar_2r_terms(q, qd, **PLANAR_2R)
        a1, tau2 = rng.standard_normal(), rng.standard_normal()
        a2 = (tau2 - M[1, 0] * a1 - (C @ qd + g)[1]) / M[1, 1]
        tau1 = M[0] @ [a1, a2] + (C @ qd + g)[0]
        a, tau = rd.hybrid_dynamics(model, q, qd, [a1, 0.0], [0.0, tau2], [True, False])
        assert_rel(a, [a1, a2], 1e-12)
        assert_rel(tau, [tau1, tau2], 1e-12)


@pytest.mark.parametrize("path, floating_base", pairs())
def test_urdf_against_pinocchio_terms(path, floating_base):
    """On real robots: the partitioned solve with Pinocchio's crba and nonLinearEffects, and
    Pinocchio's rnea and aba at the two extremes."""
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    for trial in range(2):
        q, v, a = states(model, "urdf", trial)
        rng = rng_for(path, floating_base, trial)
        mask, tau_known = random_mask(model, rng), rng.standard_normal(model.nv)
        qp = pair.pin_q(q)
        M = pin.crba(pm, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        a_ref, tau_ref = partitioned(M, pin.nonLinearEffects(pm, data, qp, v), a, tau_known, mask)
        a_out, tau_out = rd.hybrid_dynamics(model, q, v, a, tau_known, mask, friction=False)
        assert_rel(a_out, a_ref, 1e-8, "a")
        assert_rel(tau_out, tau_ref, 1e-8, "tau")
    # the extremes: Pinocchio's rnea and aba
    _, tau_out = rd.hybrid_dynamics(model, q, v, a, tau_known, np.ones(model.nv, bool), friction=False)
    assert_rel(tau_out, pin.rnea(pm, data, qp, v, a), 1e-9, "all known")
    a_out, _ = rd.hybrid_dynamics(model, q, v, a, tau_known, np.zeros(model.nv, bool), friction=False)
    assert_rel(a_out, pin.aba(pm, data, qp, v, tau_known), 1e-9, "none known")


@pytest.mark.parametrize("path, floating_base", pairs())
def test_urdf_external_wrenches_against_pinocchio(path, floating_base):
    """On real robots, with a wrench on every body in each frame (converted to Pinocchio's
    joint-frame forces by Pinocchio's placements): the given entries are kept, Pinocchio's
    rnea at the completed acceleration gives the completed forces, and Pinocchio's aba at the
    completed forces gives the completed acceleration."""
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    for frame in F_EXT_FRAMES:
        q, v, a = states(model, "urdf f_ext", frame)
        rng = rng_for(path, floating_base, "f_ext", frame)
        mask, tau_known = random_mask(model, rng), rng.standard_normal(model.nv)
        f_ext = rng.standard_normal((model.nbodies, 6))
        qp = pair.pin_q(q)
        pin.forwardKinematics(pm, data, qp)
        forces = _pin_forces(pm, f_ext, data, frame)
        a_out, tau_out = rd.hybrid_dynamics(model, q, v, np.where(mask, a, np.nan), np.where(mask, np.nan, tau_known),
                                            mask, f_ext, frame, friction=False)
        assert np.array_equal(a_out[mask], a[mask]) and np.array_equal(tau_out[~mask], tau_known[~mask])
        assert_rel(tau_out, pin.rnea(pm, data, qp, v, a_out, forces), 1e-9, f"tau, {frame}")
        assert_rel(a_out, pin.aba(pm, data, qp, v, tau_out, forces), 1e-9, f"a, {frame}")


def test_batch_matches_single_states():
    model = rd.random.random_model(6, seed=4, floating_base=True, branching=0.5)
    rng = rng_for("hd-batch")
    q, v, a = rd.random.random_state(model, rng, (2, 3))
    tau = rng.standard_normal((2, 3, model.nv))
    mask = random_mask(model, rng)
    a_out, tau_out = rd.hybrid_dynamics(model, q, v, a, tau, mask)
    assert a_out.shape == tau_out.shape == (2, 3, model.nv)
    for i in np.ndindex(2, 3):
        a1, t1 = rd.hybrid_dynamics(model, q[i], v[i], a[i], tau[i], mask)
        assert_rel(a_out[i], a1, 1e-12)
        assert_rel(tau_out[i], t1, 1e-12)
    # one configuration broadcast against four velocities
    a_out, _ = rd.hybrid_dynamics(model, q[0, 0], v[0], a[0, 0], tau[0, 0], mask)
    assert a_out.shape == (3, model.nv)
    assert_rel(a_out[2], rd.hybrid_dynamics(model, q[0, 0], v[0, 2], a[0, 0], tau[0, 0], mask)[0], 1e-12)


def test_singular_body_only_when_its_acceleration_is_unknown():
    model = massless_leaf_model()
    q, v = np.array([0.3, 0.2]), np.array([0.5, -1.0])
    with pytest.raises(ValueError, match=r"hybrid_dynamics: the articulated inertia of body 1 \('finger', joint "
                                         r"'knuckle'\) is singular.*prescribe the acceleration"):
        rd.hybrid_dynamics(model, q, v, np.zeros(2), np.zeros(2), [True, False])
    with pytest.raises(ValueError, match="'finger'"):
        rd.hybrid_dynamics(model, np.stack([q, q]), v, np.zeros(2), np.zeros(2), [True, False])
    # prescribing the massless joint's motion is well defined: the shoulder moves as a rigid arm
    a, tau = rd.hybrid_dynamics(model, q, v, [0.0, 2.0], [1.5, 0.0], [False, True])
    assert tau[1] == 0.0
    assert_rel(rd.rnea(model, q, v, a), tau, 1e-12)


def test_bad_masks():
    model = rd.random.random_model(3, seed=3, floating_base=True)
    q, v, a = states(model, "bad-mask")
    nv = model.nv
    call = rd.hybrid_dynamics
    with pytest.raises(ValueError, match=rf"known_mask: expected shape \({nv},\), got \({nv - 1},\)"):
        call(model, q, v, a, a, np.ones(nv - 1, bool))
    with pytest.raises(ValueError, match=rf"known_mask: expected shape \({nv},\), got \(2, {nv}\)"):
        call(model, q, v, a, a, np.ones((2, nv), bool))
    with pytest.raises(ValueError, match=r"known_mask: expected booleans \(or 0/1\), got float64"):
        call(model, q, v, a, a, np.full(nv, 0.5))
    partial = np.zeros(nv, bool)
    partial[:3] = True
    with pytest.raises(ValueError, match=r"known_mask: the 6 entries 0\.\.5 of free joint 'root_joint' must be all "
                                         r"True .* or all False"):
        call(model, q, v, a, a, partial)
    ints = np.r_[np.ones(6, int), np.zeros(nv - 6, int)]
    assert_rel(np.concatenate(call(model, q, v, a, a, ints)), np.concatenate(call(model, q, v, a, a, ints == 1)), 0)


def test_bad_states():
    model = rd.random.random_model(3, seed=3, floating_base=True)
    q, v, a = states(model, "bad-state")
    nv, nq = model.nv, model.nq
    mask = np.r_[np.zeros(6, bool), np.ones(nv - 6, bool)]
    call = rd.hybrid_dynamics
    for name, n in (("q", nq), ("v", nv), ("a_known", nv), ("tau_known", nv)):
        args = {"q": q, "v": v, "a_known": a, "tau_known": a}
        args[name] = np.zeros(n + 1)
        with pytest.raises(ValueError, match=rf"{name}: expected shape \(\.\.\., {n}\), got \({n + 1},\)"):
            call(model, known_mask=mask, **args)
    # NaN where it is read is an error naming the argument; where it is not read, ignored
    a_nan, tau_nan = a.copy(), a.copy()
    a_nan[-1], tau_nan[0] = np.nan, np.nan
    with pytest.raises(ValueError, match=r"hybrid_dynamics: a_known contains NaN or Inf \(first at index \(\d+,\)\)"):
        call(model, q, v, a_nan, a, mask)
    with pytest.raises(ValueError, match=r"hybrid_dynamics: tau_known contains NaN or Inf"):
        call(model, q, v, a, tau_nan, mask)
    with pytest.raises(ValueError, match=r"hybrid_dynamics: a_known contains NaN"):
        call(model, np.stack([q, q]), v, np.stack([a, a_nan]), a, mask)
    a_unread, tau_unread = a.copy(), a.copy()
    a_unread[0], tau_unread[-1] = np.nan, np.inf
    out = call(model, q, v, a_unread, tau_unread, mask)
    assert np.all(np.isfinite(np.concatenate(out)))
    bad_q = q.copy()
    bad_q[3:7] *= 2
    with pytest.raises(ValueError, match=r"q: quaternion of free joint 'root_joint'"):
        call(model, bad_q, v, a, a, mask)
    with pytest.raises(ValueError, match=r"f_ext: expected shape"):
        call(model, q, v, a, a, mask, np.zeros((2, 6)))
