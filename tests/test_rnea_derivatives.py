"""Analytical derivatives of inverse dynamics (robodyn.rnea_derivatives) on random trees of
every joint type: against Richardson differences of robodyn's own rnea (along the tangent
directions of integrate) with external wrenches in every frame, friction and armature, the
identities with crba and coriolis_matrix, the pendulum's closed form, trees not numbered depth
first, batches (wrenches included) and bad input. Agreement with Pinocchio's
computeRNEADerivatives on every example-robot-data URDF is in test_pinocchio.py."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, FD_TOL, G, assert_rel, check_batch, check_input_validation, check_wrench_batches,
                     fixed_base_models, input_checks, pendulum, random_models, rng_for, states, tangent_differences,
                     with_friction_and_armature)
from robodyn.algorithms import rnea_derivatives as kernels
from robodyn.random import random_model


@random_models
@pytest.mark.parametrize("frame", (None,) + F_EXT_FRAMES)
def test_rnea_derivatives_are_the_differences_of_rnea(model, frame):
    rng = rng_for(model.name, "rnea-derivatives", frame)
    q, v, a = states(model, "rnea-derivatives", frame)
    kw = {} if frame is None else {"f_ext": rng.standard_normal((model.nbodies, 6)), "frame": frame}
    dq, dv, da = rd.rnea_derivatives(model, q, v, a, **kw)
    fd_q, fd_v = tangent_differences(rd.rnea, model, q, v, a, **kw)
    assert_rel(dq, fd_q, FD_TOL, "dtau_dq")
    assert_rel(dv, fd_v, FD_TOL, "dtau_dv")
    assert_rel(da, rd.crba(model, q), 1e-12, "dtau_da")


@random_models
@pytest.mark.parametrize("smoothing", [0.0, 0.3])
def test_friction_and_armature(model, smoothing):
    rng = rng_for(model.name, "friction", smoothing)
    m = with_friction_and_armature(model, rng, smoothing)
    q, v, a = states(model, "friction", smoothing)
    f = rng.standard_normal((model.nbodies, 6))
    dq, dv, da = rd.rnea_derivatives(m, q, v, a, f, "world")
    fd_q, fd_v = tangent_differences(rd.rnea, m, q, v, a, f_ext=f, frame="world")
    assert_rel(dq, fd_q, FD_TOL, "dtau_dq")
    assert_rel(dv, fd_v, FD_TOL, "dtau_dv")
    assert_rel(da, rd.crba(m, q), 1e-12, "dtau_da with armature")
    plain = rd.rnea_derivatives(m, q, v, a, f, "world", friction=False, armature=False)
    assert_rel(plain[0], dq, 1e-12, "friction does not depend on q")
    assert_rel(plain[2], rd.crba(m, q, armature=False), 1e-12)
    extra = dv - plain[1]
    assert_rel(extra - np.diag(np.diag(extra)), np.zeros_like(extra), 1e-12, "friction is per joint")
    slope = 0.0 if smoothing == 0 else (1 - np.tanh(v / smoothing) ** 2) / smoothing
    assert_rel(np.diag(extra), m.damping + m.coulomb * slope, 1e-12, "b + Fc d sgn(v)/dv")
    assert not np.allclose(extra, 0)


@fixed_base_models
def test_velocity_derivative_is_twice_the_coriolis_matrix(model):
    """``C(q, v) v`` is quadratic in ``v`` with Christoffel symbols symmetric in their last two
    indices, so ``d(C v)/dv = 2 C(q, v)`` (and ``a`` and gravity do not enter). Fixed bases
    only: a free joint's velocity is a twist, not the derivative of coordinates, and its
    Coriolis matrix has no such symmetry."""
    q, v, a = states(model, "coriolis")
    assert_rel(rd.rnea_derivatives(model, q, v, a, friction=False)[1], 2 * rd.coriolis_matrix(model, q, v), 1e-9)


@random_models
def test_configuration_derivative_holds_dM_dt(model):
    """At ``v = 0``, ``(dtau/dq(q, 0, a) - dtau/dq(q, 0, 0)) v = (dM/dt) a = (C + C^T) a``."""
    q, v, a = states(model, "mdot")
    zero = np.zeros(model.nv)
    Ma = rd.rnea_derivatives(model, q, zero, a)[0] - rd.rnea_derivatives(model, q, zero, zero)[0]
    C = rd.coriolis_matrix(model, q, v)
    assert_rel(Ma @ v, (C + C.T) @ a, 1e-9)


def test_pendulum_closed_form():
    """``m L^2 qdd = tau + m g L sin(theta)``: ``dtau/dq = -m g L cos(theta)``, ``dtau/dqdd =
    m L^2``, nothing depends on ``v``."""
    m, L = 2.0, 0.7
    model = pendulum(m, L)
    for theta in (0.0, 0.4, 2.5):
        dq, dv, da = rd.rnea_derivatives(model, np.array([theta]), np.array([1.3]), np.array([0.8]))
        assert_rel(dq, [[-m * G * L * np.cos(theta)]], 1e-12)
        assert_rel(dv, [[0.0]], 1e-12)
        assert_rel(da, [[m * L * L]], 1e-12)


def breadth_first_tree():
    """Six bodies numbered level by level (parents ``[-1, 0, 0, 1, 2, 3]``): the subtree of body 1
    (bodies 1, 3, 5) is not a contiguous range of indices."""
    rng = np.random.default_rng(5)
    base = random_model(6, seed=1)
    return rd.Model(parent=[-1, 0, 0, 1, 2, 3], joint_type=[0, 0, 1, 0, 0, 0],
                    joint_axis=rng.standard_normal((6, 3)), X_tree_R=base.X_tree_R,
                    X_tree_p=rng.standard_normal((6, 3)), theta=base.theta,
                    link_names=[f"l{i}" for i in range(6)], body_joint_names=[f"j{i}" for i in range(6)])


def test_a_tree_not_numbered_depth_first_whatever_the_workspace_holds():
    """The kernel's scratch starts uninitialised: its result must not depend on what it holds."""
    model = breadth_first_tree()
    q, v, a = states(model, "breadth-first")
    dq, dv, M = rd.rnea_derivatives(model, q, v, a)
    fd_q, fd_v = tangent_differences(rd.rnea, model, q, v, a)
    assert_rel(dq, fd_q, FD_TOL)
    assert_rel(dv, fd_v, FD_TOL)
    assert_rel(M, rd.crba(model, q), 1e-12)
    k = model.kernel
    ws = kernels.workspace(model.nbodies, model.nv)
    for fill in (0.0, 1.0, 2.0, 3.0, np.nan):
        ws[0][:] = fill
        out = [np.empty((model.nv, model.nv)) for _ in range(3)]
        status = kernels.derivatives_one(k.ints, k.body, k.dofs[(True, True)], k.params[True], q, v, a,
                                         k.zero_wrench, -1, True, *out, ws)
        assert status == 0
        for x, y in zip(out, (dq, dv, M)):
            assert_rel(x, y, 1e-12, f"workspace filled with {fill}")


def _stacked(fun):
    def call(model, q, v, x, check_finite=True):
        return np.stack(fun(model, q, v, x, check_finite=check_finite), axis=-3)
    return call


def test_batch():
    call = _stacked(rd.rnea_derivatives)
    for model in (random_model(7, seed=31, floating_base=True), random_model(4, seed=32)):
        check_batch(lambda model, **arrays: call(model, *arrays.values()), model, ("q", "v", "a"))


@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_batch_of_wrenches(frame):
    """Wrenches per state (B, nb, 6), one for all (nb, 6) or (1, nb, 6)."""
    check_wrench_batches(rd.rnea_derivatives, random_model(5, seed=35, floating_base=True), frame, 4, 1e-12)


def check_paths(fun, packed, batch):
    """Plain float64 vectors take the compiled fast path ``packed`` (checked), lists and a zero
    wrench the general path: the same results."""
    model = random_model(6, seed=33, floating_base=True)
    q, v, x = states(model, "paths")
    fast = kernels.fast_path(packed, batch, model, q, v, x, True, True, True)
    assert fast is not None
    for other in (fun(model, list(q), list(v), list(x)), fun(model, q, v, x, np.zeros((model.nbodies, 6)))):
        for mine, theirs in zip(other, fast):
            assert_rel(mine, theirs, 1e-14)


def check_bad_input(fun, names, aspect):
    call = _stacked(fun)
    check_input_validation(lambda model, check_finite=True, **arrays: call(model, *arrays.values(),
                                                                         check_finite=check_finite),
                           names, aspect)


def test_general_path_equals_the_fast_path():
    check_paths(rd.rnea_derivatives, kernels._derivatives_packed, kernels._derivatives_batch)


@input_checks
def test_bad_input(aspect):
    check_bad_input(rd.rnea_derivatives, ("q", "v", "a"), aspect)
