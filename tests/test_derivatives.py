"""Analytical derivatives of the dynamics (robodyn.rnea_derivatives, robodyn.aba_derivatives)
on random trees of every joint type: against finite differences of robodyn's own rnea and aba
(Richardson-extrapolated central differences, along the tangent directions of integrate), the
identities with crba, coriolis_matrix and inverse_mass_matrix, the pendulum's closed form,
batches and bad input. Agreement with Pinocchio's computeRNEADerivatives and
computeABADerivatives on every example-robot-data URDF is in test_pinocchio.py."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, G, assert_rel, check_batch, check_input_validation, fixed_base_models, input_checks,
                     massless_leaf_model, pendulum, random_models, rng_for, states, with_friction_and_armature)
from robodyn.random import random_model

# Central differences with steps h and h/2 combined (Richardson): the error is O(h^4) times the
# fifth derivative (about 1e-12 at h = 1e-3 for these trees) plus rounding of order
# eps |f| / h (about 1e-13 |f|); the tolerance leaves a factor of 100 above both.
STEP = 1e-3
FD_TOL = 1e-8


def richardson(f, n: int) -> np.ndarray:
    """Columns ``k`` of the derivative of ``f(eps e_k)`` at 0 (``f`` maps a (n,) step to a vector)."""
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        d = [(f(h * e) - f(-h * e)) / (2 * h) for h in (STEP, STEP / 2)]
        cols.append((4 * d[1] - d[0]) / 3)
    return np.stack(cols, axis=-1)


def by_differences(fun, model, q, v, x, **kw):
    """``(d fun / dq, d fun / dv)`` of ``fun(model, q, v, x, **kw)`` by differences, ``q`` moved
    along ``integrate``."""
    dq = richardson(lambda d: fun(model, rd.integrate(model, q, d), v, x, **kw), model.nv)
    dv = richardson(lambda d: fun(model, q, v + d, x, **kw), model.nv)
    return dq, dv


@random_models
@pytest.mark.parametrize("frame", (None,) + F_EXT_FRAMES)
def test_rnea_derivatives_are_the_differences_of_rnea(model, frame):
    rng = rng_for(model.name, "rnea-derivatives", frame)
    q, v, a = states(model, "rnea-derivatives", frame)
    kw = {} if frame is None else {"f_ext": rng.standard_normal((model.nbodies, 6)), "f_ext_frame": frame}
    dq, dv, da = rd.rnea_derivatives(model, q, v, a, **kw)
    fd_q, fd_v = by_differences(rd.rnea, model, q, v, a, **kw)
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
    fd_q, fd_v = by_differences(rd.rnea, m, q, v, a, f_ext=f, f_ext_frame="world")
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


@random_models
def test_aba_derivatives_are_the_differences_of_aba(model):
    rng = rng_for(model.name, "aba-derivatives")
    m = with_friction_and_armature(model, rng, 0.2)
    q, v, tau = states(model, "aba-derivatives")
    f = rng.standard_normal((model.nbodies, 6))
    for kw in ({}, {"f_ext": f, "f_ext_frame": "local_world_aligned"}):
        dq, dv, dtau = rd.aba_derivatives(m, q, v, tau, **kw)
        fd_q, fd_v = by_differences(rd.aba, m, q, v, tau, **kw)
        assert_rel(dq, fd_q, FD_TOL, "dqdd_dq")
        assert_rel(dv, fd_v, FD_TOL, "dqdd_dv")
        assert_rel(dtau, rd.inverse_mass_matrix(m, q), 1e-12, "dqdd_dtau")
        # the derivative of rnea(q, v, aba(q, v, tau)) = tau
        qdd = rd.aba(m, q, v, tau, **kw)
        r_q, r_v, M = rd.rnea_derivatives(m, q, v, qdd, **kw)
        assert_rel(M @ dq, -r_q, 1e-9, "M dqdd_dq = -dtau_dq")
        assert_rel(M @ dv, -r_v, 1e-9, "M dqdd_dv = -dtau_dv")


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
    """``m L^2 qdd = tau + m g L sin(theta)``: ``dtau/dq = -m g L cos(theta)``, ``dtau/dqdd = m L^2``,
    ``dqdd/dq = g cos(theta) / L``, ``dqdd/dtau = 1 / (m L^2)``, nothing depends on ``v``."""
    m, L = 2.0, 0.7
    model = pendulum(m, L)
    for theta in (0.0, 0.4, 2.5):
        q, v, x = np.array([theta]), np.array([1.3]), np.array([0.8])
        dq, dv, da = rd.rnea_derivatives(model, q, v, x)
        assert_rel(dq, [[-m * G * L * np.cos(theta)]], 1e-12)
        assert_rel(dv, [[0.0]], 1e-12)
        assert_rel(da, [[m * L * L]], 1e-12)
        dq, dv, dtau = rd.aba_derivatives(model, q, v, x)
        assert_rel(dq, [[G * np.cos(theta) / L]], 1e-12)
        assert_rel(dv, [[0.0]], 1e-12)
        assert_rel(dtau, [[1 / (m * L * L)]], 1e-12)


def _stacked(fun):
    def call(model, q, v, x, check_finite=True):
        return np.stack(fun(model, q, v, x, check_finite=check_finite), axis=-3)
    return call


@pytest.mark.parametrize("fun, x", [(rd.rnea_derivatives, "a"), (rd.aba_derivatives, "tau")])
def test_batch(fun, x):
    call = _stacked(fun)
    for model in (random_model(7, seed=31, floating_base=True), random_model(4, seed=32)):
        check_batch(lambda model, **arrays: call(model, *arrays.values()), model, ("q", "v", x))


@pytest.mark.parametrize("fun, x", [(rd.rnea_derivatives, "a"), (rd.aba_derivatives, "tau")])
def test_general_path_equals_the_fast_path(fun, x):
    """Lists and a zero wrench take the general path; arrays without wrenches the compiled fast path."""
    model = random_model(6, seed=33, floating_base=True)
    q, v, a = states(model, "paths")
    fast = fun(model, q, v, a)
    for other in (fun(model, list(q), list(v), list(a)), fun(model, q, v, a, np.zeros((model.nbodies, 6)))):
        for mine, theirs in zip(other, fast):
            assert_rel(mine, theirs, 1e-14)


@pytest.mark.parametrize("fun, x", [(rd.rnea_derivatives, "a"), (rd.aba_derivatives, "tau")])
@input_checks
def test_bad_input(fun, x, aspect):
    call = _stacked(fun)
    check_input_validation(lambda model, check_finite=True, **arrays: call(model, *arrays.values(),
                                                                         check_finite=check_finite),
                           ("q", "v", x), aspect)


@pytest.mark.parametrize("floating_base", [False, True])
def test_aba_derivatives_of_a_singular_model(floating_base):
    model = massless_leaf_model(floating_base)
    q = rd.random.random_state(model, np.random.default_rng(0))[0]
    z = np.zeros(model.nv)
    with pytest.raises(ValueError, match=r"aba_derivatives: the articulated inertia of body \d+ \('finger', "
                                         r"joint 'knuckle'\) is singular"):
        rd.aba_derivatives(model, q, z, z)
    rd.rnea_derivatives(model, q, z, z)  # inverse dynamics is defined


@random_models
def test_derivatives_of_the_terms_are_their_differences(model):
    m = with_friction_and_armature(model, rng_for(model.name, "terms"), 0.2)  # the terms leave friction out
    q, v, _ = states(model, "terms")
    dg = rd.gravity_derivatives(m, q)
    assert_rel(dg, richardson(lambda d: rd.gravity(m, rd.integrate(m, q, d)), m.nv), FD_TOL, "dg/dq")
    nq, nv = rd.nonlinear_effects_derivatives(m, q, v)
    fd_q, fd_v = by_differences(lambda m_, q_, v_, _: rd.nonlinear_effects(m_, q_, v_), m, q, v, None)
    assert_rel(nq, fd_q, FD_TOL, "d nle/dq")
    assert_rel(nv, fd_v, FD_TOL, "d nle/dv")
    for armature in (True, False):
        pq, M = rd.generalized_momentum_derivatives(m, q, v, armature=armature)
        fd_q, fd_v = by_differences(lambda m_, q_, v_, _: rd.generalized_momentum(m_, q_, v_, armature=armature),
                                    m, q, v, None)
        assert_rel(pq, fd_q, FD_TOL, "d(M v)/dq")
        assert_rel(M, fd_v, FD_TOL, "d(M v)/dv")
        assert_rel(M, rd.crba(m, q, armature=armature), 1e-12)


def test_derivatives_of_the_terms_batch_and_bad_input():
    model = random_model(5, seed=34, floating_base=True)
    Q, V, _ = states(model, "terms-batch", size=(2, 3))
    for fun, args in ((rd.gravity_derivatives, (Q,)), (rd.nonlinear_effects_derivatives, (Q, V)),
                      (rd.generalized_momentum_derivatives, (Q, V))):
        out = fun(model, *args)
        for i in np.ndindex(2, 3):
            one = fun(model, *(x[i] for x in args))
            for x, y in zip(out if isinstance(out, tuple) else (out,), one if isinstance(one, tuple) else (one,)):
                assert x.shape == (2, 3, model.nv, model.nv)
                assert_rel(x[i], y, 1e-12)
        with pytest.raises(ValueError, match=r"q contains NaN or Inf"):
            fun(model, np.full(model.nq, np.nan), *args[1:])
        with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\)"):
            fun(model, np.zeros(model.nq + 1), *args[1:])
