"""Certified bounds of M(q)'s eigenvalues (robodyn.inertia_bounds): the planar arm against
its closed form (MLS eq. 4.11: the eigenvalues over cos q2 in [-1, 1]) to the requested 1 %,
and on a 3-dof arm every sampled eigenvalue inside the certified interval; bad input."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd

from helpers import rng_for


def test_planar_arm_against_its_closed_form():
    model = rd.models.load("planar_2r")
    bounds = rd.inertia_bounds(model, rtol=0.01)
    # the closed form: M depends on q2 only; its eigenvalues over a fine grid of q2
    q2 = np.linspace(-np.pi, np.pi, 200001)
    M = rd.crba(model, np.stack([np.zeros_like(q2), q2], axis=1))
    w = np.linalg.eigvalsh(M)
    true_min, true_max = w[:, 0].min(), w[:, -1].max()
    assert bounds.lambda_m <= true_min and bounds.lambda_M >= true_max
    assert bounds.lambda_m >= 0.99 * true_min * (1 - 1e-9) - 1e-12
    assert bounds.lambda_M <= 1.01 * true_max
    assert bounds.sampled_min >= true_min - 1e-12 and bounds.sampled_max <= true_max + 1e-12


def test_bounds_hold_on_a_three_joint_arm():
    model = rd.models.load("elbow_3r")
    lower, upper = np.array([-1.0, -0.5, -1.0]), np.array([1.0, 0.5, 1.0])
    bounds = rd.inertia_bounds(model, lower, upper, max_boxes=300)
    Q = rng_for("inertia-bounds").uniform(lower, upper, (20000, 3))
    w = np.linalg.eigvalsh(rd.crba(model, Q))
    assert bounds.lambda_m <= w[:, 0].min() and bounds.lambda_M >= w[:, -1].max()
    assert bounds.boxes <= 300


def test_bad_input():
    with pytest.raises(ValueError, match="revolute joints only"):
        rd.inertia_bounds(rd.models.load("scara"))
    with pytest.raises(ValueError, match="lower > upper"):
        rd.inertia_bounds(rd.models.load("planar_2r"), [0.0, 1.0], [1.0, 0.0])
