"""Inverse mass matrix (robodyn.inverse_mass_matrix): the inverse of crba on random trees, with
armature, columns of aba, the two-link arm, Pinocchio's computeMinverse on URDFs, batches,
singular models and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import (PLANAR_2R, assert_rel, check_batch, check_input_validation, input_checks, massless_leaf_model,
                     planar_2r, planar_2r_terms, random_models, rng_for, states)
from urdf_subset import load_pair, pairs


@random_models
def test_inverse_of_crba(model):
    q, _, _ = states(model, "minv")
    Minv = rd.inverse_mass_matrix(model, q)
    assert np.array_equal(Minv, Minv.T)
    assert_rel(Minv, np.linalg.inv(rd.crba(model, q)), 1e-9)
    assert_rel(Minv @ rd.crba(model, q), np.eye(model.nv), 1e-9)


@random_models
def test_with_armature(model):
    m = model.replace(armature=rng_for(model.name, "armature").uniform(0.01, 0.5, model.nv))
    q, _, _ = states(m, "armature")
    assert_rel(rd.inverse_mass_matrix(m, q), np.linalg.inv(rd.crba(m, q)), 1e-9)
    assert_rel(rd.inverse_mass_matrix(m, q, armature=False), np.linalg.inv(rd.crba(m, q, armature=False)), 1e-9)


@random_models
def test_columns_are_accelerations_of_unit_forces(model):
    q, _, _ = states(model, "columns")
    Minv = rd.inverse_mass_matrix(model, q)
    no_gravity = model.replace(gravity=(0.0, 0.0, 0.0))
    for k in (0, model.nv - 1):
        e = np.zeros(model.nv)
        e[k] = 1.0
        assert_rel(Minv[:, k], rd.aba(no_gravity, q, np.zeros(model.nv), e), 1e-9, f"column {k}")


def test_two_link_arm_closed_form():
    model = planar_2r(**PLANAR_2R)
    for q2 in (0.3, 1.7, -2.5):
        M, _, _ = planar_2r_terms([0.4, q2], [0.0, 0.0], **PLANAR_2R)
        assert_rel(rd.inverse_mass_matrix(model, np.array([0.4, q2])), np.linalg.inv(M), 1e-12)


@pytest.mark.parametrize("path, floating_base", pairs())
def test_urdf_against_pinocchio(path, floating_base):
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    for trial in range(2):
        q, _, _ = states(model, "urdf", trial)
        Minv = pin.computeMinverse(pm, data, pair.pin_q(q))
        assert_rel(rd.inverse_mass_matrix(model, q), np.triu(Minv) + np.triu(Minv, 1).T, 1e-9)


@random_models
def test_batch(model):
    check_batch(lambda model, q: rd.inverse_mass_matrix(model, q), model, ["q"])


@input_checks
def test_input_validation(aspect):
    def call(model, q, check_finite=True):
        return rd.inverse_mass_matrix(model, q, check_finite=check_finite)

    check_input_validation(call, ["q"], aspect)


def test_singular_model():
    model = massless_leaf_model()
    with pytest.raises(ValueError, match=r"inverse_mass_matrix: the articulated inertia of body 1 \('finger', "
                                         r"joint 'knuckle'\) is singular, so M\(q\) is singular"):
        rd.inverse_mass_matrix(model, np.zeros(2))
    with pytest.raises(ValueError, match="'finger'"):
        rd.inverse_mass_matrix(model, np.zeros((3, 2)))
