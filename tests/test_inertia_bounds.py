"""Certified bounds of M(q)'s eigenvalues (robodyn.inertia_bounds): the planar arm against
its closed form (MLS eq. 4.11: the eigenvalues over cos q2 in [-1, 1]) to the requested 1 %;
PUMA 560 over its joint limits (to 10 % and 1 %), the Panda on a box about a pose and over its
full joint limits (to 10 %), and a random serial chain with armature over all angles (to 10 %):
20,000 seeded samples, the box's corners and a local search for the extremes all inside the
certified interval, which is within the tolerance of the extremes found; a random revolute
tree on a random small box; the Fourier series the method rests on (degree 2 in each angle,
no dependence on a joint attached to the world) and the chain certificate's identity (the
bodies' terms, telescoped by arbitrary multipliers, sum to ``s (x^T M x - t |x|^2)``); the
pendulum (one joint, attached to the world) in one box; more boxes never loosen the interval;
bad input.

The Panda is the built-in 7R arm (``rd.models.load("panda")``: no gripper, so no prismatic
finger joints, which inertia_bounds rejects). Over its full joint limits the direct branch and
bound does not get near 10 % (its remainder needs boxes about 0.1 rad wide in six joints);
the chain certificate does, with one-joint boxes (module docstring).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.optimize import minimize

import robodyn as rd
from robodyn import joints as J
from robodyn.algorithms import inertia_bounds as ib
from robodyn.random import random_model

from helpers import rng_for

PANDA_POSE = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
SAMPLES = 20000


def box_of(name, half_width):
    """``(model, lower, upper)``: the joint limits, or a box of ``half_width`` about PANDA_POSE;
    ``"chain"``: a random serial chain of 5 revolute joints with armature, all angles."""
    if name == "chain":
        model = random_model(5, seed=2, branching=0.0, joint_types=(J.REVOLUTE,))
        model = model.replace(armature=rng_for("inertia-bounds-armature").uniform(0.0, 0.05, 5) * model.total_mass)
        return model, np.full(5, -np.pi), np.full(5, np.pi)
    model = rd.models.load(name)
    if half_width is None:
        return model, model.lower, model.upper
    return model, np.maximum(PANDA_POSE - half_width, model.lower), np.minimum(PANDA_POSE + half_width, model.upper)


def extremes(model, lower, upper, *keys):
    """``(eigenvalues (N, nv), smallest, largest)``: of ``M`` at SAMPLES seeded points of the box and
    at its corners; the extremes refined by a bounded local search from the best samples."""
    Q = rng_for("inertia-bounds", *keys).uniform(lower, upper, (SAMPLES, model.nv))
    corners = np.array(list(itertools.product(*zip(lower, upper))))
    Q = np.vstack([Q, corners])
    w = np.linalg.eigvalsh(rd.crba(model, Q))
    found = [w[:, 0].min(), w[:, -1].max()]
    for col, sign in ((0, 1.0), (-1, -1.0)):
        for start in Q[np.argsort(sign * w[:, col])[:3]]:
            res = minimize(lambda q: sign * np.linalg.eigvalsh(rd.crba(model, q))[col], start, method="L-BFGS-B",
                           bounds=list(zip(lower, upper)))
            value = np.linalg.eigvalsh(rd.crba(model, np.clip(res.x, lower, upper)))[col]
            found[col] = min(found[0], value) if col == 0 else max(found[1], value)
    return w, found[0], found[1]


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
    assert bounds.boxes < 100


@pytest.mark.parametrize("name, half_width, rtol, most", [
    ("puma560", None, 0.1, 300),
    ("puma560", None, 0.01, 1500),
    ("panda", 0.1, 0.1, 600),
    ("panda", None, 0.1, 4000),
    ("chain", None, 0.1, 4000),
], ids=["puma560-10%", "puma560-1%", "panda-box-10%", "panda-limits-10%", "chain-all-angles-10%"])
def test_robots_reach_the_tolerance_and_every_sample_is_inside(name, half_width, rtol, most):
    model, lower, upper = box_of(name, half_width)
    bounds = rd.inertia_bounds(model, lower, upper, rtol=rtol)
    w, low, high = extremes(model, lower, upper, name, half_width)
    assert bounds.lambda_m <= w[:, 0].min() and bounds.lambda_M >= w[:, -1].max()
    assert bounds.lambda_m <= low and bounds.lambda_M >= high
    assert bounds.lambda_m <= bounds.sampled_min <= bounds.sampled_max <= bounds.lambda_M
    # within rtol of the extremes found (the search's and the branch and bound's samples)
    assert bounds.lambda_m >= (1 - rtol) * min(low, bounds.sampled_min)
    assert bounds.lambda_M <= (1 + rtol) * max(high, bounds.sampled_max)
    assert bounds.boxes <= most


def test_bounds_hold_on_a_three_joint_arm():
    model = rd.models.load("elbow_3r")
    lower, upper = np.array([-1.0, -0.5, -1.0]), np.array([1.0, 0.5, 1.0])
    bounds = rd.inertia_bounds(model, lower, upper, max_boxes=300)
    Q = rng_for("inertia-bounds").uniform(lower, upper, (20000, 3))
    w = np.linalg.eigvalsh(rd.crba(model, Q))
    assert bounds.lambda_m <= w[:, 0].min() and bounds.lambda_M >= w[:, -1].max()
    assert bounds.boxes <= 300


@pytest.mark.parametrize("seed", [3, 4])
def test_bounds_hold_on_a_random_tree_and_box(seed):
    model = random_model(5, seed=seed, branching=0.5, joint_types=(J.REVOLUTE,))
    rng = rng_for("inertia-bounds-tree", seed)
    centre = rng.uniform(-np.pi, np.pi, model.nv)
    half = rng.uniform(0.05, 0.3, model.nv)
    bounds = rd.inertia_bounds(model, centre - half, centre + half, rtol=0.05, max_boxes=4000)
    w, low, high = extremes(model, centre - half, centre + half, "tree", seed)
    assert bounds.lambda_m <= low and bounds.lambda_M >= high
    assert bounds.lambda_m <= bounds.sampled_min and bounds.sampled_max <= bounds.lambda_M
    assert bounds.lambda_m >= 0.95 * bounds.sampled_min and bounds.lambda_M <= 1.05 * bounds.sampled_max


def test_a_point_box_gives_the_eigenvalues_there():
    model = rd.models.load("puma560")
    q = rng_for("inertia-bounds-point").uniform(model.lower, model.upper)
    w = np.linalg.eigvalsh(rd.crba(model, q))
    bounds = rd.inertia_bounds(model, q, q, rtol=0.0)
    assert bounds.boxes == 1
    assert w[0] - 1e-8 * w[-1] <= bounds.lambda_m <= w[0] and w[-1] <= bounds.lambda_M <= w[-1] * (1 + 1e-8)


def test_a_joint_attached_to_the_world_alone_gives_its_inertia():
    """The pendulum: M does not depend on its one joint (attached to the world), so the global
    bounds of the whole box are already its one eigenvalue, in one box."""
    model = rd.models.load("pendulum")
    M = rd.crba(model, np.zeros(1))[0, 0]
    bounds = rd.inertia_bounds(model, rtol=0.0)
    assert bounds.boxes == 1
    assert M * (1 - 1e-8) <= bounds.lambda_m <= M <= bounds.lambda_M <= M * (1 + 1e-8)


def test_more_boxes_never_loosen_the_interval():
    model, lower, upper = box_of("puma560", None)
    runs = [rd.inertia_bounds(model, lower, upper, rtol=0.0, max_boxes=k) for k in (1, 9, 65, 257, 1025)]
    for fewer, more in zip(runs, runs[1:]):
        assert more.lambda_m >= fewer.lambda_m and more.lambda_M <= fewer.lambda_M
        assert more.sampled_min <= fewer.sampled_min and more.sampled_max >= fewer.sampled_max
    assert [r.boxes for r in runs] == [1, 9, 65, 257, 1025]


def test_the_fourier_series_of_m():
    """What the method rests on: M is a trigonometric polynomial of degree 2 in each angle, so
    5 samples per joint give it exactly, and it does not depend on the joint attached to the
    world. The Panda: grid over joints 2..7, series evaluated at random points."""
    model = rd.models.load("panda")
    n = model.nv
    angles = 2 * np.pi * np.arange(5) / 5
    grid = np.zeros((5 ** (n - 1), n))
    grid[:, 1:] = np.array(list(itertools.product(angles, repeat=n - 1)))
    A = np.fft.fftn(rd.crba(model, grid).reshape((5,) * (n - 1) + (n, n)), axes=tuple(range(n - 1))) / 5 ** (n - 1)
    freq = np.array(list(itertools.product(np.fft.fftfreq(5, 1 / 5), repeat=n - 1)))
    Q = rng_for("inertia-bounds-fourier").uniform(-np.pi, np.pi, (5, n))
    for q in Q:
        series = np.einsum("f,fij->ij", np.exp(1j * freq @ q[1:]), A.reshape(-1, n, n))
        M = rd.crba(model, q)
        assert np.abs(series.imag).max() <= 1e-12 * np.abs(M).max()
        assert np.abs(series.real - M).max() <= 1e-12 * np.abs(M).max()


def test_the_chain_certificate_telescopes_to_m():
    """What the chain certificate rests on: with any multipliers Lambda_i, the bodies' terms
    ``y_i^T K_i(q_i) y_i`` (``y_i = [V_(i-1); x_i]``, ``y_1 = [x_0; x_1]``) sum to ``s (x^T M(q) x -
    t |x|^2)``, M from crba (armature included), for both sides; and each K_i is a
    trigonometric polynomial of degree 2 in its own angle (5 samples give it exactly)."""
    model, _, _ = box_of("chain", None)
    n = model.nv
    rng = rng_for("inertia-bounds-chain")
    q, x, t = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n), 0.3
    multipliers = rng.normal(size=21 * (n - 2))
    V, terms = ib._joint_maps(model, 0, q[:1])[0, :, 6] * x[0], []
    for i in range(1, n):
        Phi = ib._joint_maps(model, i, q[i:i + 1])[0]
        y = np.r_[x[0], x[1]] if i == 1 else np.r_[V, x[i]]
        V = Phi @ np.r_[V, x[i]]
        terms.append((i, y))
    M = rd.crba(model, q)
    for side in (1.0, -1.0):
        total = 0.0
        for i, y in terms:
            C, F, var, _ = ib._chain_terms(model, i, q[i:i + 1], side, t)
            total += y @ (C[0] - np.einsum("p,pij->ij", multipliers[var], F[0])) @ y
        assert abs(total - side * (x @ M @ x - t * x @ x)) <= 1e-10 * (abs(x) @ np.abs(M) @ abs(x) + 1.0)
    angles = 2 * np.pi * np.arange(5) / 5
    C, F, var, _ = ib._chain_terms(model, 2, angles, 1.0, t)
    K = C - np.einsum("p,bpij->bij", multipliers[var], F)
    A = np.fft.fft(K, axis=0) / 5                           # K(q) = sum_k A_k exp(i k q), k in -2..2
    for qq in rng.uniform(-np.pi, np.pi, 3):
        series = np.einsum("k,kij->ij", np.exp(1j * np.fft.fftfreq(5, 1 / 5) * qq), A).real
        C, F, var, _ = ib._chain_terms(model, 2, np.array([qq]), 1.0, t)
        assert np.abs(series - (C[0] - np.einsum("p,pij->ij", multipliers[var], F[0]))).max() <= 1e-10 * np.abs(K).max()


def test_bad_input():
    with pytest.raises(ValueError, match="revolute joints only"):
        rd.inertia_bounds(rd.models.load("scara"))
    planar = rd.models.load("planar_2r")
    with pytest.raises(ValueError, match="lower > upper"):
        rd.inertia_bounds(planar, [0.0, 1.0], [1.0, 0.0])
    with pytest.raises(ValueError, match="2 finite numbers"):
        rd.inertia_bounds(planar, [0.0, 1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="2 finite numbers"):
        rd.inertia_bounds(planar, [0.0, -np.inf], [1.0, 0.0])
    with pytest.raises(ValueError, match="rtol"):
        rd.inertia_bounds(planar, rtol=-0.1)
    with pytest.raises(ValueError, match="max_boxes"):
        rd.inertia_bounds(planar, max_boxes=0)
    with pytest.raises(ValueError, match="at most 7 joints"):
        rd.inertia_bounds(random_model(9, seed=1, branching=0.0, joint_types=(J.REVOLUTE,)))
