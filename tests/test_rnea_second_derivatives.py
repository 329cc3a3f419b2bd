"""Second-order derivatives of inverse dynamics (robodyn.rnea_second_derivatives).

Oracles: sympy's second derivatives of robodyn's closed-form equations of motion (planar 2R arm,
elbow arm, with friction and springs); Richardson differences of robodyn.rnea_derivatives
along the tangent directions of integrate (random trees of every joint type, Panda, Solo12,
external wrenches in every frame, Stribeck friction) and of robodyn.crba; the identities with
the Christoffel symbols (``d2(C v)/dv2 = Gamma + Gamma^T``, ``Gamma`` from ``dM/dq`` on fixed
bases); the symmetries, and on free, spherical and planar joints the Lie bracket that breaks
the symmetry of ``d2tau_dq2``. Pinocchio 4.1's Python bindings do not expose
``computeRNEASecondOrderDerivatives``, so it is not an oracle here."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd
from helpers import (F_EXT_FRAMES, FD_TOL, G, PLANAR_2R, assert_rel, check_batch, check_input_validation,
                     check_wrench_batches, fixed_base_models, input_checks, pendulum, planar_2r, random_models,
                     richardson, rng_for, states)
from robodyn import joints as J
from robodyn.layout import MOTION
from robodyn.random import random_model

NAMES = ("d2tau_dq2", "d2tau_dqdv", "d2tau_dv2", "d2tau_dadq")


def second_differences(model, q, v, a, **kw):
    """The four tensors by Richardson differences of ``rd.rnea_derivatives``: along ``q`` (by
    ``rd.integrate``) of ``dtau_dq`` and ``M``, along ``v`` of ``dtau_dq`` and ``dtau_dv``;
    and ``d2tau_dqdv`` again along ``q`` of ``dtau_dv`` (``[:, j, k] = d/dq_j dtau_dv[:, k]``)."""
    along_q = richardson(lambda d: np.stack(rd.rnea_derivatives(model, rd.integrate(model, q, d), v, a, **kw)),
                         model.nv)
    along_v = richardson(lambda d: np.stack(rd.rnea_derivatives(model, q, v + d, a, **kw)), model.nv)
    return {"d2tau_dq2": along_q[0], "d2tau_dqdv": along_v[0], "d2tau_dv2": along_v[1], "d2tau_dadq": along_q[2],
            "d2tau_dqdv (dtau_dv along q)": np.swapaxes(along_q[1], 1, 2)}


def check_differences(model, q, v, a, tol=FD_TOL, **kw):
    out = rd.rnea_second_derivatives(model, q, v, a, **kw)
    for name, want in second_differences(model, q, v, a, **kw).items():
        assert_rel(getattr(out, name.split()[0]), want, tol, name)
    return out


def with_passive_forces(model, rng, smoothing):
    """Damping, Coulomb friction and armature on every dof, springs on the joints of one dof."""
    n = model.nv
    one_dof = np.repeat(J.NV[model.joint_type] == 1, J.NV[model.joint_type])
    return model.replace(damping=rng.uniform(0.1, 1.0, n), coulomb=rng.uniform(0.1, 1.0, n),
                         stiffness=rng.uniform(0.5, 5.0, n) * one_dof,
                         spring_reference=rng.uniform(-1.0, 1.0, n) * one_dof, armature=rng.uniform(0.01, 0.1, n),
                         coulomb_smoothing=smoothing)


def solo12():
    path = rd.models.example_robot_urdf("solo12")  # example-robot-data: a test dependency
    with warnings.catch_warnings():  # the URDF's <contact> elements, ignored
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_urdf(path, floating_base=True)


# -- exact oracle: sympy on the closed forms ---------------------------------------------------
@pytest.mark.parametrize("name", ["planar_2r", "elbow_3r"])
def test_second_derivatives_of_the_closed_forms(name):
    """sympy differentiates ``tau = M a + C v + g + tau_p`` of ``rd.symbolic`` twice (damping,
    smoothed Coulomb friction, springs, armature): equal to 1e-10."""
    import sympy as sp
    base = planar_2r(**PLANAR_2R) if name == "planar_2r" else rd.models.load(name)
    rng = rng_for(name, "closed-form")
    model = with_passive_forces(base, rng, 0.05)
    eom = rd.symbolic.equations_of_motion(model)
    q, v, a, n = list(eom.q), list(eom.v), list(eom.a), model.nv
    wrt = {"d2tau_dq2": (q, q), "d2tau_dqdv": (q, v), "d2tau_dv2": (v, v), "d2tau_dadq": (a, q)}
    exprs = [[[[sp.diff(eom.tau[i], y[j], x[k]) for k in range(n)] for j in range(n)] for i in range(n)]
             for y, x in wrt.values()]
    closed = sp.lambdify([q, v, a], exprs, "numpy")
    for s in range(4):
        qs, vs, as_ = states(model, "closed-form", s)
        want = np.array(closed(qs, vs, as_), dtype=float)
        out = rd.rnea_second_derivatives(model, qs, vs, as_)
        for t, name_ in enumerate(NAMES):
            assert_rel(getattr(out, name_), want[t], 1e-10, f"{name_} at state {s}")


def test_pendulum_closed_form():
    """``tau = m L^2 qdd - m g L sin(theta)``: ``d2tau/dq2 = m g L sin(theta)``, nothing else."""
    m, L = 2.0, 0.7
    model = pendulum(m, L)
    for theta in (0.0, 0.4, 2.5):
        out = rd.rnea_second_derivatives(model, np.array([theta]), np.array([1.3]), np.array([0.8]))
        assert_rel(out.d2tau_dq2, [[[m * G * L * np.sin(theta)]]], 1e-12)
        for name in NAMES[1:]:
            assert_rel(getattr(out, name), [[[0.0]]], 1e-12, name)


# -- differences of rnea_derivatives ---------------------------------------------------------
@random_models
def test_differences_on_random_trees(model):
    q, v, a = states(model, "second-differences")
    check_differences(model, q, v, a)


@pytest.mark.parametrize("frame", F_EXT_FRAMES)
@pytest.mark.parametrize("floating", [False, True])
def test_external_wrenches(frame, floating):
    """Wrenches in the body frame turn with their body, in world axes they keep their direction
    (about the world origin, or about the moving body origin)."""
    model = random_model(5, seed=41, floating_base=floating, branching=0.4, joint_types=J.AXIAL + (J.SPHERICAL,
                                                                                               J.PLANAR))
    q, v, a = states(model, "wrenches", frame)
    f = rng_for("wrenches", frame, floating).standard_normal((model.nbodies, 6))
    out = check_differences(model, q, v, a, f_ext=f, frame=frame)
    plain = rd.rnea_second_derivatives(model, q, v, a)
    assert not np.allclose(out.d2tau_dq2, plain.d2tau_dq2)
    for name in ("d2tau_dqdv", "d2tau_dv2", "d2tau_dadq"):  # a fixed wrench enters through q only
        assert_rel(getattr(out, name), getattr(plain, name), 1e-12, name)


def test_a_tree_not_numbered_depth_first():
    """Six bodies numbered level by level (parents ``[-1, 0, 0, 1, 2, 3]``): the subtree of body 1
    (bodies 1, 3, 5) is not a contiguous range of indices."""
    rng = np.random.default_rng(5)
    base = random_model(6, seed=1)
    model = rd.Model(parent=[-1, 0, 0, 1, 2, 3], joint_type=[0, 0, 1, 0, 0, 0],
                     joint_axis=rng.standard_normal((6, 3)), X_tree_R=base.X_tree_R,
                     X_tree_p=rng.standard_normal((6, 3)), theta=base.theta,
                     link_names=[f"l{i}" for i in range(6)], body_joint_names=[f"j{i}" for i in range(6)])
    q, v, a = states(model, "breadth-first")
    check_differences(model, q, v, a)


def test_panda():
    model = rd.models.load("panda")
    q, v, a = states(model, "panda")
    check_differences(model, q, v, a)


def test_solo12_floating_base():
    model = solo12()
    q, v, a = states(model, "solo12")
    check_differences(model, q, v, a)


@pytest.mark.parametrize("smoothing", [0.0, 0.3])
def test_friction_with_the_stribeck_effect(smoothing):
    """``d2/dv2 (b v + (Fc + Fx exp(-(v / v_s)^2)) sgn(v))`` on the diagonal of ``d2tau_dv2``,
    nothing else; the springs and the armature have no second derivative."""
    base = random_model(4, seed=43, floating_base=True, joint_types=J.AXIAL + (J.SPHERICAL,))
    rng = rng_for("stribeck", smoothing)
    model = with_passive_forces(base, rng, smoothing).replace(
        stribeck=rng.uniform(0.1, 1.0, base.nv), stribeck_velocity=rng.uniform(0.5, 2.0, base.nv))
    q, v, a = states(model, "stribeck", smoothing)
    out = check_differences(model, q, v, a)
    plain = rd.rnea_second_derivatives(model, q, v, a, friction=False)
    for name in NAMES:
        assert_rel(getattr(rd.rnea_second_derivatives(model, q, v, a, armature=False), name), getattr(out, name),
                   0.0, f"{name}: the armature changes nothing")
        extra = getattr(out, name) - getattr(plain, name)
        if name != "d2tau_dv2":
            assert_rel(extra, np.zeros_like(extra), 0.0, f"{name}: friction enters through v only")
    extra = out.d2tau_dv2 - plain.d2tau_dv2
    k = np.arange(model.nv)
    diagonal = extra[k, k, k].copy()
    extra[k, k, k] = 0.0
    assert_rel(extra, np.zeros_like(extra), 0.0, "friction is per joint")
    assert np.abs(diagonal).max() > 1e-3


# -- M(q) and the Christoffel symbols --------------------------------------------------------
@random_models
def test_mass_matrix_derivative(model):
    """``d2tau_dadq[:, j, k] = d/dq_k M[:, j]`` (Richardson differences of ``rd.crba`` along
    ``integrate``), symmetric in ``i, j``; ``a`` and ``v`` do not enter."""
    q, v, a = states(model, "dM")
    out = rd.rnea_second_derivatives(model, q, v, a)
    dM = richardson(lambda d: rd.crba(model, rd.integrate(model, q, d)), model.nv)
    assert_rel(out.d2tau_dadq, dM, FD_TOL, "dM/dq")
    assert_rel(out.d2tau_dadq, np.swapaxes(out.d2tau_dadq, 0, 1), 1e-13, "symmetric in i, j")
    other = rd.rnea_second_derivatives(model, q, 2 * v + 1, -a)
    assert_rel(other.d2tau_dadq, out.d2tau_dadq, 1e-13, "independent of v and a")


@random_models
def test_velocity_hessian_is_the_christoffel_symbols(model):
    """``C(q, v) v = sum_jk Gamma_ijk v_j v_k``, so ``d2tau_dv2 = Gamma + Gamma^T`` (last two
    axes), independent of ``v`` and ``a`` (friction off), symmetric in ``j, k``."""
    q, v, a = states(model, "christoffel")
    G = rd.christoffel_symbols(model, q)
    out = rd.rnea_second_derivatives(model, q, v, a, friction=False)
    assert_rel(out.d2tau_dv2, G + np.swapaxes(G, 1, 2), 1e-12, "Gamma + Gamma^T")
    assert_rel(out.d2tau_dv2, np.swapaxes(out.d2tau_dv2, 1, 2), 1e-13, "symmetric in j, k")
    other = rd.rnea_second_derivatives(model, q, 3 * v - 1, 2 * a, friction=False)
    assert_rel(other.d2tau_dv2, out.d2tau_dv2, 1e-13, "independent of v and a")


@fixed_base_models
def test_fixed_base_symmetries(model):
    """Joints of one dof: coordinates add, so ``d2tau_dq2`` is symmetric in ``j, k``; and
    ``Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2`` ties ``d2tau_dv2`` to
    ``d2tau_dadq``."""
    q, v, a = states(model, "symmetries")
    out = rd.rnea_second_derivatives(model, q, v, a, friction=False)
    assert_rel(out.d2tau_dq2, np.swapaxes(out.d2tau_dq2, 1, 2), 1e-12, "d2tau_dq2 symmetric in j, k")
    dM = out.d2tau_dadq
    assert_rel(out.d2tau_dv2, dM + np.swapaxes(dM, 1, 2) - np.transpose(dM, (2, 0, 1)), 1e-12,
               "d2tau_dv2 from dM/dq")


@pytest.mark.parametrize("model", [random_model(6, seed=44, floating_base=True, branching=0.4,
                                                joint_types=(J.REVOLUTE, J.SPHERICAL, J.PLANAR, J.HELICAL))],
                         ids=["floating-spherical-planar"])
def test_tangent_directions_of_a_joint_do_not_commute(model):
    """For dofs ``j, k`` of one free, spherical or planar joint ``exp(a) exp(b) = exp(a + b +
    [a, b] / 2 + ...)``, so ``d2tau_dq2[:, j, k] - d2tau_dq2[:, k, j] = dtau_dq @ [S_k, S_j]``
    (the bracket ``S_k x S_j`` in the joint's coordinates); for dofs of different joints the
    steps commute and the tensor is symmetric."""
    q, v, a = states(model, "bracket")
    D = rd.rnea_second_derivatives(model, q, v, a).d2tau_dq2
    dq = rd.rnea_derivatives(model, q, v, a)[0]
    want = np.swapaxes(D, 1, 2).copy()
    S_all = model.kernel.dofs[(True, True)][:, MOTION:MOTION + 6]
    seen = 0
    for i in range(model.nbodies):
        n = J.NV[model.joint_type[i]]
        if n == 1:
            continue
        dofs = np.arange(model.idx_v[i], model.idx_v[i] + n)
        S = S_all[dofs]  # (n, 6) in the child frame
        for j in dofs:
            for k in dofs:
                sk, sj = S_all[k], S_all[j]
                bracket = np.concatenate([np.cross(sk[3:], sj[:3]) + np.cross(sk[:3], sj[3:]), np.cross(sk[3:], sj[3:])])
                coords = np.linalg.lstsq(S.T, bracket, rcond=None)[0]
                assert_rel(S.T @ coords, bracket, 1e-14, "the joint's subalgebra is closed")
                want[:, j, k] += dq[:, dofs] @ coords
        seen += 1
    assert seen >= 2
    assert_rel(D, want, 1e-12, "d2tau_dq2 = its transpose + dtau_dq [S_k, S_j]")
    assert not np.allclose(D, np.swapaxes(D, 1, 2))


# -- batches and bad input ---------------------------------------------------------------------
def _stacked(model, q, v, a, **kw):
    return np.stack(rd.rnea_second_derivatives(model, q, v, a, **kw), axis=-4)


def test_batch():
    for model in (random_model(3, seed=45, floating_base=True), random_model(4, seed=46)):
        check_batch(lambda model, **arrays: _stacked(model, *arrays.values()), model, ("q", "v", "a"))


@pytest.mark.parametrize("frame", F_EXT_FRAMES)
def test_batch_of_wrenches(frame):
    """Wrenches per state (B, nb, 6), one for all (nb, 6) or (1, nb, 6)."""
    check_wrench_batches(rd.rnea_second_derivatives, random_model(3, seed=47, floating_base=True), frame, 3, 1e-14)


def test_result_type_and_shapes():
    model = random_model(3, seed=48, floating_base=True)
    q, v, a = states(model, "shapes", size=(2, 1))
    out = rd.rnea_second_derivatives(model, q, v, a)
    assert type(out).__name__ == "RNEASecondDerivatives" and out._fields == NAMES
    assert all(x.shape == (2, 1) + (model.nv,) * 3 for x in out)
    assert rd.RNEASecondDerivatives is type(out)


@input_checks
def test_bad_input(aspect):
    check_input_validation(lambda model, check_finite=True, **arrays: _stacked(model, *arrays.values(),
                                                                             check_finite=check_finite),
                           ("q", "v", "a"), aspect)


def test_bad_wrenches_and_frames():
    model = random_model(3, seed=49)
    q, v, a = states(model, "bad-wrenches")
    with pytest.raises(ValueError, match="frame must be one of"):
        rd.rnea_second_derivatives(model, q, v, a, np.zeros((model.nbodies, 6)), "body")
    with pytest.raises(ValueError, match=r"f_ext: expected shape \(\.\.\., %d, 6\)" % model.nbodies):
        rd.rnea_second_derivatives(model, q, v, a, np.zeros((model.nbodies, 3)))
    with pytest.raises(ValueError, match="f_ext: contains NaN"):
        rd.rnea_second_derivatives(model, q, v, a, np.full((model.nbodies, 6), np.nan))
