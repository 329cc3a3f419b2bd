"""Analytical derivatives of forward dynamics (robodyn.aba_derivatives) on random trees of every
joint type: against Richardson differences of robodyn's own aba (along the tangent directions of
integrate) with external wrenches in every frame, friction and armature, the pendulum's closed
form, batches, the fast path, bad input and singular models. Agreement with Pinocchio's
computeABADerivatives on every example-robot-data URDF is in test_pinocchio.py."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, FD_TOL, G, assert_rel, check_batch, input_checks,
                     massless_leaf_model, pendulum, random_models, rng_for, states, tangent_differences,
                     with_friction_and_armature)
from robodyn.algorithms import aba_derivatives as kernels
from robodyn.random import random_model
from test_rnea_derivatives import _stacked, breadth_first_tree, check_bad_input, check_paths


@random_models
def test_aba_derivatives_are_the_differences_of_aba(model):
    rng = rng_for(model.name, "aba-derivatives")
    m = with_friction_and_armature(model, rng, 0.2)
    q, v, tau = states(model, "aba-derivatives")
    f = rng.standard_normal((model.nbodies, 6))
    for kw in ({}, *({"f_ext": f, "frame": frame} for frame in F_EXT_FRAMES)):
        dq, dv, dtau = rd.aba_derivatives(m, q, v, tau, **kw)
        fd_q, fd_v = tangent_differences(rd.aba, m, q, v, tau, **kw)
        assert_rel(dq, fd_q, FD_TOL, "dqdd_dq")
        assert_rel(dv, fd_v, FD_TOL, "dqdd_dv")
        assert_rel(dtau, rd.inverse_mass_matrix(m, q), 1e-12, "dqdd_dtau")
        # the derivative of rnea(q, v, aba(q, v, tau)) = tau
        qdd = rd.aba(m, q, v, tau, **kw)
        r_q, r_v, M = rd.rnea_derivatives(m, q, v, qdd, **kw)
        assert_rel(M @ dq, -r_q, 1e-9, "M dqdd_dq = -dtau_dq")
        assert_rel(M @ dv, -r_v, 1e-9, "M dqdd_dv = -dtau_dv")


def test_pendulum_closed_form():
    """``m L^2 qdd = tau + m g L sin(theta)``: ``dqdd/dq = g cos(theta) / L``, ``dqdd/dtau =
    1 / (m L^2)``, nothing depends on ``v``."""
    m, L = 2.0, 0.7
    model = pendulum(m, L)
    for theta in (0.0, 0.4, 2.5):
        dq, dv, dtau = rd.aba_derivatives(model, np.array([theta]), np.array([1.3]), np.array([0.8]))
        assert_rel(dq, [[G * np.cos(theta) / L]], 1e-12)
        assert_rel(dv, [[0.0]], 1e-12)
        assert_rel(dtau, [[1 / (m * L * L)]], 1e-12)


def test_a_tree_not_numbered_depth_first():
    model = breadth_first_tree()
    q, v, tau = states(model, "breadth-first")
    dq, dv, dtau = rd.aba_derivatives(model, q, v, tau)
    fd_q, fd_v = tangent_differences(rd.aba, model, q, v, tau)
    assert_rel(dq, fd_q, FD_TOL)
    assert_rel(dv, fd_v, FD_TOL)
    assert_rel(dtau, np.linalg.inv(rd.crba(model, q)), 1e-9)


def test_batch():
    call = _stacked(rd.aba_derivatives)
    for model in (random_model(7, seed=31, floating_base=True), random_model(4, seed=32)):
        check_batch(lambda model, **arrays: call(model, *arrays.values()), model, ("q", "v", "tau"))


def test_general_path_equals_the_fast_path():
    check_paths(rd.aba_derivatives, kernels._derivatives_packed, kernels._derivatives_batch)


@input_checks
def test_bad_input(aspect):
    check_bad_input(rd.aba_derivatives, ("q", "v", "tau"), aspect)


@pytest.mark.parametrize("floating_base", [False, True])
def test_aba_derivatives_of_a_singular_model(floating_base):
    model = massless_leaf_model(floating_base)
    q = rd.random.random_state(model, np.random.default_rng(0))[0]
    z = np.zeros(model.nv)
    with pytest.raises(ValueError, match=r"aba_derivatives: the articulated inertia of body \d+ \('finger', "
                                         r"joint 'knuckle'\) is singular"):
        rd.aba_derivatives(model, q, z, z)
    rd.rnea_derivatives(model, q, z, z)  # inverse dynamics is defined
