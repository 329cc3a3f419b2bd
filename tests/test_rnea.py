"""Inverse dynamics (robodyn.rnea): external wrenches against Jacobians, friction and armature,
linearity in the acceleration, the pendulum in closed form, batches and bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, G, assert_rel, check_batch, check_input_validation, input_checks, pendulum,
                     random_model, random_models, rng_for, states, with_friction_and_armature)


@random_models
@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_wrench_on_one_body_is_jacobian_transpose(model, frame):
    """rnea(f_ext: wrench w on body b in frame F) == rnea() - J_b(F)^T w, for every body."""
    q, v, a = states(model, frame)
    rng = rng_for(model.name, frame, "wrench")
    tau0 = rd.rnea(model, q, v, a)
    for b in range(model.nbodies):
        w = rng.standard_normal(6)
        f_ext = np.zeros((model.nbodies, 6))
        f_ext[b] = w
        expected = tau0 - rd.jacobian(model, q, b, frame=frame).T @ w
        assert_rel(rd.rnea(model, q, v, a, f_ext, frame=frame), expected, 1e-9, f"body {b}")


@random_models
def test_wrenches_add_up(model):
    """Wrenches on all bodies at once: the sum of the single-body effects (linearity)."""
    q, v, a = states(model)
    f_ext = rng_for(model.name, "all").standard_normal((model.nbodies, 6))
    expected = rd.rnea(model, q, v, a)
    for b in range(model.nbodies):
        expected = expected - rd.jacobian(model, q, b, frame="local").T @ f_ext[b]
    assert_rel(rd.rnea(model, q, v, a, f_ext), expected, 1e-9)


@random_models
def test_friction_and_armature_terms(model):
    """tau = rigid-body tau + armature a + damping v + coulomb sign(v) (tanh(v/eps) when smoothed)."""
    q, v, a = states(model)
    rigid = rd.rnea(model, q, v, a)
    for eps, sgn in ((0.0, np.sign(v)), (0.3, np.tanh(v / 0.3))):
        m = with_friction_and_armature(model, rng_for(model.name, eps), smoothing=eps)
        full = m.armature * a + m.damping * v + m.coulomb * sgn
        assert_rel(rd.rnea(m, q, v, a), rigid + full, 1e-9, f"eps={eps}")
        assert_rel(rd.rnea(m, q, v, a, friction=False), rigid + m.armature * a, 1e-9)
        assert_rel(rd.rnea(m, q, v, a, armature=False), rigid + m.damping * v + m.coulomb * sgn, 1e-9)
        assert_rel(rd.rnea(m, q, v, a, friction=False, armature=False), rigid, 1e-9)
    # Coulomb friction at rest is zero with the exact sign
    m = with_friction_and_armature(model, rng_for(model.name, "rest"))
    assert_rel(rd.rnea(m, q, np.zeros(m.nv), a), rd.rnea(model, q, np.zeros(m.nv), a) + m.armature * a, 1e-9)


@random_models
def test_affine_in_acceleration(model):
    """rnea(q, v, a) == crba(q) a + rnea(q, v, 0): the mass matrix is the linear part."""
    q, v, a = states(model)
    assert_rel(rd.rnea(model, q, v, a), rd.crba(model, q) @ a + rd.rnea(model, q, v, np.zeros(model.nv)), 1e-9)


@random_models
def test_gravity_scales(model):
    """Gravity enters as a base acceleration: doubling it doubles rnea(q, 0, 0)."""
    q, _, _ = states(model)
    z = np.zeros(model.nv)
    heavy = model.replace(gravity=2 * model.gravity)
    assert_rel(rd.rnea(heavy, q, z, z), 2 * rd.rnea(model, q, z, z), 1e-9)
    assert_rel(rd.rnea(model.replace(gravity=np.zeros(3)), q, z, z), z, 1e-12)


@pytest.mark.parametrize("model", [pendulum(), pendulum(m=0.3, L=2.5), rd.models.load("pendulum")],
                         ids=["m2-L0.7", "m0.3-L2.5", "rd.models.pendulum"])
def test_pendulum_closed_form(model):
    """m L^2 qdd = tau + m g L sin(theta), theta = 0 upright: tau = m L^2 a - m g L sin(q)."""
    m = model.total_mass
    L = np.linalg.norm(rd.center_of_mass(model, [0.0]))
    for q, v, a in rng_for("pendulum", m, L).uniform(-4, 4, (5, 3)):
        tau = m * L ** 2 * a - m * G * L * np.sin(q)
        assert_rel(rd.rnea(model, [q], [v], [a]), [tau], 1e-12, f"q={q}")
        assert_rel(rd.aba(model, [q], [v], [tau]), [a], 1e-12, f"q={q}")
        assert_rel(rd.crba(model, [q]), [[m * L ** 2]], 1e-12)
        assert_rel(rd.gravity(model, [q]), [-m * G * L * np.sin(q)], 1e-12)
        assert_rel(rd.nonlinear_effects(model, [q], [v]), [-m * G * L * np.sin(q)], 1e-12)
        assert_rel(rd.coriolis_matrix(model, [q], [v]), [[0.0]], 1e-12)
        assert rd.kinetic_energy(model, [q], [v]) == pytest.approx(m * L ** 2 * v ** 2 / 2, rel=1e-12, abs=1e-12)
        assert rd.potential_energy(model, [q]) == pytest.approx(m * G * L * np.cos(q), rel=1e-12, abs=1e-12)
        assert_rel(rd.center_of_mass(model, [q]), [L * np.sin(q), 0.0, L * np.cos(q)], 1e-12)


def test_pendulum_built_in_is_upright_at_zero():
    """rd.models.load('pendulum') has its mass straight above the pivot at q = 0."""
    model = rd.models.load("pendulum")
    assert model.nv == 1
    c = rd.center_of_mass(model, [0.0])
    assert c[2] > 0 and np.hypot(c[0], c[1]) < 1e-12


def test_batch():
    check_batch(rd.rnea, random_model(6, seed=11, floating_base=True), ("q", "v", "a"))


def test_leading_dimensions_broadcast():
    """Leading (batch) dimensions broadcast as NumPy's do, not only a single state against a batch."""
    model = random_model(4, seed=13, floating_base=True)
    q, v, a = states(model, "broadcast", size=(2, 3))
    out = rd.rnea(model, q[:, :1], v[:1], a)  # (2, 1, nq), (1, 3, nv), (2, 3, nv)
    assert out.shape == (2, 3, model.nv)
    for i, j in np.ndindex(2, 3):
        assert_rel(out[i, j], rd.rnea(model, q[i, 0], v[0, j], a[i, j]), 1e-12)


def test_non_numeric_input():
    model = random_model(3, seed=1)
    q, v, a = states(model)
    with pytest.raises(ValueError, match=r"^q: expected an array of numbers, got str$"):
        rd.rnea(model, "q", v, a)
    with pytest.raises(ValueError, match=r"^v: expected an array of numbers, got dict$"):
        rd.rnea(model, q, {"v": 1.0}, a)


def test_batch_with_external_wrenches():
    """f_ext with the batch's shape pairs element by element; one f_ext (nb, 6) is shared."""
    model = random_model(5, seed=12, floating_base=False)
    q, v, a = states(model, "fext-batch", size=(2, 3))
    f_ext = rng_for("fext-batch").standard_normal((2, 3, model.nbodies, 6))
    for frame in F_EXT_FRAMES:
        out = rd.rnea(model, q, v, a, f_ext, frame=frame)
        shared = rd.rnea(model, q, v, a, f_ext[0, 0], frame=frame)
        for i in np.ndindex(2, 3):
            assert_rel(out[i], rd.rnea(model, q[i], v[i], a[i], f_ext[i], frame=frame), 1e-12)
            assert_rel(shared[i], rd.rnea(model, q[i], v[i], a[i], f_ext[0, 0], frame=frame), 1e-12)


@input_checks
def test_bad_input(aspect):
    check_input_validation(rd.rnea, ("q", "v", "a"), aspect)


def test_bad_external_wrenches():
    model = random_model(3, seed=1)
    q, v, a = states(model)
    nb = model.nbodies
    for bad in (np.zeros((nb, 3)), np.zeros((nb + 1, 6)), np.zeros(6)):
        with pytest.raises(ValueError, match=r"^f_ext: expected shape \(\.\.\., 3, 6\), got ") as err:
            rd.rnea(model, q, v, a, bad)
        assert str(err.value).endswith(str(bad.shape))
    f = np.zeros((nb, 6))
    f[1, 2] = np.nan
    with pytest.raises(ValueError, match="^f_ext: contains NaN"):
        rd.rnea(model, q, v, a, f)
    with pytest.raises(ValueError, match=r"^f_ext: batch shape \(4,\) does not match the states' \(\)$"):
        rd.rnea(model, q, v, a, np.zeros((4, nb, 6)))  # would enlarge an unbatched call
    three = [np.stack([x] * 3) for x in (q, v, a)]
    for batch in ((2, 3), (2,)):  # would enlarge the batch; does not broadcast
        with pytest.raises(ValueError, match=re.escape(f"f_ext: batch shape {batch} does not match the states' (3,)")):
            rd.rnea(model, *three, np.zeros(batch + (nb, 6)))
    with pytest.raises(ValueError, match="^frame must be one of"):
        rd.rnea(model, q, v, a, np.zeros((nb, 6)), frame="body")
