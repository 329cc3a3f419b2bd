"""Numeric robustness: extreme states and models against a 40-digit reference.

States near kinematic singularities and at the joint limits, large velocities and
accelerations, tiny, huge and badly mixed masses. Each result either agrees with the mpmath
reference (``mp_reference``) within a tolerance scaled by the size of the terms and, for the
forward dynamics, by the condition number of ``M``, or the call raises a clear ``ValueError``.
Floating bases are checked against Pinocchio on the same extreme states. Finally every public
function is swept with inputs that overflow double precision: it returns finite numbers or
raises, never NaN or Inf.

Error model (Higham, "Accuracy and Stability of Numerical Algorithms", ch. 7): a backward
stable computation of ``tau = M a + h`` errs by ``eps (|M| |a| + |h|)``; the forward dynamics
solves a system perturbed by that much, so ``|da| <= eps (kappa(M) |a| + |M^-1| |h|)``.
"""

from __future__ import annotations

import numpy as np
import pytest

import mp_reference as ref
import robodyn as rd
from helpers import rng_for
from robodyn.random import random_model, random_state

EPS = np.finfo(float).eps
SLACK = 4.0  # constant of the error bounds, which grow with the number of joints n


def _scaled(model: rd.Model, masses: np.ndarray) -> rd.Model:
    """``model`` with body ``i``'s inertial parameters multiplied by ``masses[i]``."""
    return model.replace(theta=model.theta * np.asarray(masses)[:, None])


def _cases():
    panda, puma = rd.models.load("panda"), rd.models.load("puma560")
    tree = random_model(8, seed=11, branching=0.5)
    rng = np.random.default_rng(5)
    mixed = _scaled(tree, 10.0 ** rng.uniform(-4, 4, tree.nbodies))
    zeros = np.zeros(7)
    cases = {
        # Panda at q = 0: shoulder, elbow and wrist axes aligned (kinematic singularity)
        "panda-singular": (panda, zeros, np.full(7, 0.5), np.full(7, -0.3)),
        "panda-lower-limits": (panda, panda.lower.copy(), np.full(7, 1.0), np.ones(7)),
        "panda-upper-limits": (panda, panda.upper.copy(), -np.ones(7), np.ones(7)),
        "panda-fast": (panda, np.full(7, 0.3), np.full(7, 1e3), np.full(7, 1e2)),
        # accelerations large enough to stand out of the rounding of h ~ |v|^2 = 1e12 (the
        # error bound of aba is about 4 rad/s^2 here): at a = 0 the exact answer is rounding
        # noise, which zeros would match as well as any algorithm
        "panda-very-fast": (panda, np.full(7, -0.7), np.linspace(-1e6, 1e6, 7), np.linspace(1e5, -1e5, 7)),
        "panda-huge-acceleration": (panda, np.full(7, 0.2), np.ones(7), np.full(7, 1e8)),
        # PUMA 560 wrist singularity: q5 = 0 aligns joints 4 and 6
        "puma-wrist-singular": (puma, np.array([0.1, -0.5, 0.4, 0.3, 0.0, -0.2]), np.ones(6), np.ones(6)),
        "tree-tiny-masses": (_scaled(tree, np.full(8, 1e-6)),) + random_state(tree, rng_for("tiny")),
        "tree-huge-masses": (_scaled(tree, np.full(8, 1e6)),) + random_state(tree, rng_for("huge")),
        "tree-mixed-masses": (mixed,) + random_state(tree, rng_for("mixed")),
        "tree-mixed-fast": (mixed, random_state(tree, rng_for("mf"))[0], np.full(8, 300.0), np.full(8, -50.0)),
    }
    return cases


CASES = _cases()
# Well-conditioned cases without cancellation, where the bound itself proves 8 correct digits.
ACCURATE = {"panda-singular", "panda-lower-limits", "panda-upper-limits", "panda-huge-acceleration",
            "puma-wrist-singular", "tree-tiny-masses", "tree-huge-masses"}
cases = pytest.mark.parametrize("case", sorted(CASES))


def _magnitudes(model, q, v, a):
    """Norms of the terms of ``tau = M a + C v + g`` (double precision is enough for a bound)."""
    M = rd.crba(model, q, armature=False)
    C = rd.coriolis_matrix(model, q, v)
    g = rd.gravity(model, q)
    return M, np.linalg.norm(M, 2) * np.linalg.norm(a) + np.linalg.norm(C, 2) * np.linalg.norm(v) + np.linalg.norm(g)


@cases
def test_rnea_matches_high_precision(case):
    model, q, v, a = CASES[case]
    tau = rd.rnea(model, q, v, a, friction=False, armature=False)
    exact = ref.to_float(ref.rnea(model, q, v, a))
    _, scale = _magnitudes(model, q, v, a)
    assert np.linalg.norm(tau - exact) <= SLACK * model.nv * EPS * scale


@cases
def test_crba_matches_high_precision(case):
    model, q = CASES[case][:2]
    M = rd.crba(model, q, armature=False)
    exact = ref.to_float(ref.mass_matrix(model, q))
    assert np.linalg.norm(M - exact, 2) <= SLACK * model.nv * EPS * np.linalg.norm(exact, 2)
    assert np.array_equal(M, M.T)


@cases
def test_aba_matches_high_precision_within_condition_number(case):
    model, q, v, a = CASES[case]
    tau = rd.rnea(model, q, v, a, friction=False, armature=False)
    acc = rd.aba(model, q, v, tau, friction=False, armature=False)
    exact = ref.to_float(ref.aba(model, q, v, tau))
    M, scale = _magnitudes(model, q, v, exact)
    kappa = np.linalg.cond(M)
    bound = SLACK * model.nv * EPS * (kappa * np.linalg.norm(exact) + np.linalg.norm(np.linalg.inv(M), 2) * scale)
    assert np.linalg.norm(acc - exact) <= bound
    # the bound is not vacuous: it proves three correct digits on every case (at worst 2.4e-5
    # on panda-very-fast), so that a wrong answer such as zeros violates it
    assert bound <= 1e-3 * np.linalg.norm(exact)
    if case in ACCURATE:  # these accelerations are accurate
        assert bound <= 1e-8 * np.linalg.norm(exact)


def test_the_cases_span_the_ranges_they_claim():
    """The mixed-mass tree is badly conditioned and the fast states are fast: the cases test
    what their names say."""
    assert np.linalg.cond(rd.crba(*CASES["tree-mixed-masses"][:2])) > 1e6
    assert np.linalg.cond(rd.crba(*CASES["panda-singular"][:2])) < 1e6
    assert np.abs(CASES["panda-very-fast"][2]).max() == 1e6


def _pin_talos_like():
    """A floating-base random tree with mixed masses, converted to Pinocchio."""
    from robodyn.interop import to_pinocchio

    # parents [-1, 0, 0, 2, 3, 4, 2, 6, 7, 6]: three branch points, in the depth-first order
    # a Pinocchio model needs (``to_pinocchio`` refuses other orders)
    tree = random_model(9, seed=8, floating_base=True, branching=0.6)
    rng = np.random.default_rng(8)
    model = _scaled(tree, 10.0 ** rng.uniform(-3, 3, tree.nbodies))
    return model, to_pinocchio(model)


@pytest.mark.parametrize("speed", [1.0, 1e3, 1e5])
def test_floating_base_extreme_states_match_pinocchio(speed):
    """Velocities scaled by ``speed`` and accelerations by ``speed ** 2``, the size of the
    velocity-product terms ``h``: with ordinary accelerations at speed 1e5 the rounding of
    ``h``, which grows as ``speed ** 2``, bounds the error of the forward dynamics only to
    about 200 |a|, which any answer, zeros included, would meet."""
    import pinocchio as pin

    model, pm = _pin_talos_like()
    data = pm.createData()
    q, v, a = random_state(model, rng_for("pin", speed))
    v, a = v * speed, a * speed ** 2
    tau = rd.rnea(model, q, v, a)
    M, scale = _magnitudes(model, q, v, a)
    assert np.linalg.norm(tau - pin.rnea(pm, data, q, v, a)) <= SLACK * model.nv * EPS * scale
    acc = rd.aba(model, q, v, tau)
    kappa = np.linalg.cond(M)
    bound = SLACK * model.nv * EPS * (kappa * np.linalg.norm(a) + np.linalg.norm(np.linalg.inv(M), 2) * scale)
    assert bound <= 1e-6 * np.linalg.norm(a)  # not vacuous: at most 1.2e-7 |a| on these states
    assert np.linalg.norm(acc - pin.aba(pm, data, q, v, tau)) <= 2 * bound
    assert np.linalg.norm(acc - a) <= 2 * bound


# --- no silent NaN: every public function, inputs that overflow double precision ----------

def _overflow_model():
    tree = random_model(5, seed=4, floating_base=True, branching=0.5)
    return tree


def _public_calls(model, q, v, a):
    body = model.link_names[-1]
    return {
        "rnea": lambda: rd.rnea(model, q, v, a),
        "aba": lambda: rd.aba(model, q, v, a),
        "crba": lambda: rd.crba(model, q),
        "gravity": lambda: rd.gravity(model, q),
        "nonlinear_effects": lambda: rd.nonlinear_effects(model, q, v),
        "generalized_momentum": lambda: rd.generalized_momentum(model, q, v),
        "coriolis_matrix": lambda: rd.coriolis_matrix(model, q, v),
        "christoffel_symbols": lambda: rd.christoffel_symbols(model, q),
        "kinetic_energy": lambda: rd.kinetic_energy(model, q, v),
        "potential_energy": lambda: rd.potential_energy(model, q),
        "center_of_mass": lambda: rd.center_of_mass(model, q),
        "com_jacobian": lambda: rd.com_jacobian(model, q),
        "jacobian": lambda: rd.jacobian(model, q, body),
        "jacobian_dot_times_v": lambda: rd.jacobian_dot_times_v(model, q, v, body),
        "forward_kinematics": lambda: rd.forward_kinematics(model, q),
        "frame_pose": lambda: rd.frame_pose(model, q, body),
        "hybrid_dynamics": lambda: rd.hybrid_dynamics(model, q, v, a, a, np.arange(model.nv) >= 6),
        "inverse_mass_matrix": lambda: rd.inverse_mass_matrix(model, q),
        "regressor": lambda: rd.regressor(model, q, v, a),
        "slotine_li_regressor": lambda: rd.slotine_li_regressor(model, q, v, v, a),
        "kinetic_energy_regressor": lambda: rd.kinetic_energy_regressor(model, q, v),
        "potential_energy_regressor": lambda: rd.potential_energy_regressor(model, q),
        "integrate": lambda: rd.integrate(model, q, v),
        "task_space_inertia": lambda: rd.task_space_inertia(model, q, body),
    }


def _extreme_inputs(model):
    rng = rng_for("overflow")
    q, v, a = random_state(model, rng)
    big_q = q.copy()
    big_q[:3] = 1e308  # base position at the edge of double precision
    prismatic = [int(model.idx_q[i]) for i in range(model.nbodies) if model.joint_type[i] == rd.joints.PRISMATIC]
    big_q[prismatic] = -1e308
    return {
        "huge-velocity": (q, np.full(model.nv, 1e200), a),
        "huge-acceleration": (q, v, np.full(model.nv, 1e308)),
        "huge-positions": (big_q, v, a),
        "huge-everything": (big_q, np.full(model.nv, 1e300), np.full(model.nv, -1e300)),
    }


@pytest.mark.parametrize("inputs", ["huge-velocity", "huge-acceleration", "huge-positions", "huge-everything"])
def test_no_public_function_returns_nan_or_inf(inputs):
    model = _overflow_model()
    assert any(model.joint_type == rd.joints.PRISMATIC)
    q, v, a = _extreme_inputs(model)[inputs]
    raised = 0
    for name, call in _public_calls(model, q, v, a).items():
        try:
            out = call()
        except ValueError as e:
            assert "not finite" in str(e), (name, str(e))
            raised += 1
            continue
        assert np.isfinite(out).all(), f"{name} returned NaN/Inf for {inputs}"
    assert raised > 0  # these inputs do overflow something


def test_overflow_error_names_the_function_and_the_scale():
    model = rd.models.load("panda")
    with pytest.raises(ValueError, match=r"rnea: the result is not finite .*largest input magnitude 1e\+200"):
        rd.rnea(model, np.zeros(7), np.full(7, 1e200), np.zeros(7))
    with pytest.raises(ValueError, match="aba: the result is not finite"):
        rd.aba(model, np.zeros((2, 7)), np.full(7, 1e200), np.zeros(7))


def test_unchecked_calls_skip_the_result_check():
    """``check_finite=False`` is the documented opt-out: no check of inputs or results."""
    model = rd.models.load("panda")
    tau = rd.rnea(model, np.zeros(7), np.full(7, 1e200), np.zeros(7), check_finite=False)
    assert not np.isfinite(tau).all()

