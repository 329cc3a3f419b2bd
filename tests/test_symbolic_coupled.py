"""robodyn.symbolic on models with mimic joints (``rd.CoupledModel``, ``robodyn.symbolic.mimic``).

The closed forms are in the independent coordinates only; every term is checked against the
numeric algorithms of the same coupled model (``rd.crba``, ``rd.coriolis_matrix``,
``rd.christoffel_symbols``, ``rd.gravity``, ``rd.rnea`` with and without friction,
``rd.regressor``, the energies), which map the full tree through ``G``, on seeded random
trees and a URDF with ``<mimic>``: chains of mimic joints, multipliers +-1 with offsets,
integer multipliers, prismatic mimic joints with non-unit and symbolic multipliers, and
friction, armature and springs on every joint (the mimic joints' included). The identity
``Mdot = C + C^T`` is checked exactly in the ring; the two derivation routes agree exactly on
the URDF (exact rotations); the couplings that are not trigonometric polynomials are refused.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import joints as J
from robodyn import symbolic as S
from robodyn.random import random_model

from helpers import assert_rel, rng_for
from test_symbolic import call_c, compile_c, random_states

TOL = 1e-10
ONE_DOF = (J.REVOLUTE, J.PRISMATIC)
# (bodies, seed, couplings) of random trees: joint types RRPPRR (parents -1 0 1 2 2 4) for
# (6, 2), RRRPRR (-1 0 1 2 3 3) for (6, 10), RPRP (-1 0 1 0) for (4, 8)
TREES = {
    # a chain (joint5 follows joint4, which follows joint0) of multipliers -1 and 1 with offsets,
    # and a prismatic joint following a prismatic one with a non-unit multiplier
    "chain-offsets": (6, 2, [("joint5", "joint4", -1.0, 0.4), ("joint4", "joint0", 1.0, -0.25),
                             ("joint3", "joint2", 2.5, 0.1)]),
    # integer multipliers (multiple angles) and a prismatic joint following a revolute one (a rack)
    "multiple-angles": (6, 10, [("joint5", "joint1", 2.0, 0.2), ("joint4", "joint0", -3.0, 0.0),
                                ("joint3", "joint2", 0.05, 0.01)]),
    # a small one for the regressor, whose derivation carries 10 symbols per body
    "small": (4, 8, [("joint2", "joint0", -1.0, 0.3), ("joint3", "joint1", -2.5, 0.05)]),
}


def passive(model: rd.Model, key) -> rd.Model:
    """``model`` with damping, smoothed Coulomb friction, armature and springs on every joint."""
    rng = rng_for(model.name, key, "passive")
    n = model.nv
    return model.replace(damping=rng.uniform(0.1, 1.0, n), coulomb=rng.uniform(0.1, 1.0, n),
                         armature=rng.uniform(0.01, 0.1, n), coulomb_smoothing=0.3,
                         stiffness=rng.uniform(0.5, 2.0, n), spring_reference=rng.uniform(-1, 1, n))


def random_tree(key: str) -> rd.CoupledModel:
    n, seed, mimic = TREES[key]
    full = random_model(n, seed, False, 0.4, ONE_DOF)
    return rd.CoupledModel(passive(full, key), mimic)


URDF = """<robot name="pinch">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.2 0 0.01"/><mass value="2"/>
    <inertia ixx="0.01" iyy="0.03" izz="0.03" ixy="0.001" ixz="0" iyz="0"/></inertial></link>
  <link name="lower"><inertial><origin xyz="0.15 0.01 0"/><mass value="1.2"/>
    <inertia ixx="0.005" iyy="0.02" izz="0.02" ixy="0" ixz="0.001" iyz="0"/></inertial></link>
  <link name="left"><inertial><origin xyz="0.03 0 0.01"/><mass value="0.1"/>
    <inertia ixx="0.0001" iyy="0.0002" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="right"><inertial><origin xyz="0.03 0 -0.01"/><mass value="0.15"/>
    <inertia ixx="0.0001" iyy="0.0002" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="slide"><inertial><origin xyz="0.02 0 0"/><mass value="0.3"/>
    <inertia ixx="0.0003" iyy="0.0002" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.4" friction="0.3"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/>
    <dynamics damping="0.2" friction="0.1"/></joint>
  <joint name="left_finger" type="revolute"><parent link="lower"/><child link="left"/><origin xyz="0.3 0.02 0"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="2" velocity="2"/><dynamics damping="0.05"/></joint>
  <joint name="right_finger" type="revolute"><parent link="lower"/><child link="right"/>
    <origin xyz="0.3 -0.02 0"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="2" velocity="2"/>
    <dynamics damping="0.03" friction="0.02"/><mimic joint="left_finger" multiplier="MULTIPLIER" offset="0.1"/></joint>
  <joint name="rack" type="prismatic"><parent link="lower"/><child link="slide"/><origin xyz="0.1 0 0"/>
    <axis xyz="1 0 0"/><limit lower="-0.1" upper="0.1" effort="5" velocity="1"/><dynamics damping="0.5"/>
    <mimic joint="elbow" multiplier="0.02" offset="0.01"/></joint>
</robot>"""


def urdf(multiplier: str = "-1") -> str:
    """The gripper arm: shoulder, elbow, left finger; the right finger follows the left one
    (``multiplier``, offset 0.1), a rack follows the elbow (0.02 m per rad)."""
    return URDF.replace("MULTIPLIER", multiplier)


MODELS = {**{key: random_tree(key) for key in TREES}, "urdf": rd.load_urdf(urdf())}
KEYS = list(MODELS)
TERMS = ("M", "C", "C_v", "g", "tau_p", "tau", "T", "U")


@pytest.fixture(scope="module")
def derived():
    """Each coupled model derived once (Lagrange route) with the NumPy functions of its terms,
    the default forms (recursions for M, C_v, g, tau_p, tau) and the expanded ones."""
    out = {}
    for key, model in MODELS.items():
        eom = S.equations_of_motion(model)
        f = {t: eom.to_function(t) for t in TERMS}
        f.update({f"{t} expanded": eom.to_function(t, "expanded") for t in ("M", "C_v", "g", "tau_p", "tau")})
        out[key] = (model, eom, f)
    return out


def full_coordinates(model: rd.CoupledModel, q, v):
    """``(q_full, v_full)`` of the full tree, computed here from the couplings by joint name."""
    full = model.full
    qf, vf = np.zeros(q.shape[:-1] + (full.nq,)), np.zeros(v.shape[:-1] + (full.nv,))
    qf[..., model.independent_q], vf[..., model.independent_v] = q, v
    for joint, source, r, o in model.mimic:
        i, s = full.body_joint_names.index(joint), full.body_joint_names.index(source)
        qf[..., full.idx_q[i]] = r * qf[..., full.idx_q[s]] + o
        vf[..., full.idx_v[i]] = r * vf[..., full.idx_v[s]]
    return qf, vf


# -- the model ---------------------------------------------------------------------------------
@pytest.mark.parametrize("key", KEYS)
def test_coordinates_are_the_independent_joints(key):
    model = MODELS[key]
    sm = S.from_model(model)
    assert sm.nv == model.nv == len(sm.q) == len(sm.v) == len(sm.a) and sm.nbodies == model.nbodies
    assert tuple(sm.joint_names[b] for b in sm.independent) == model.joint_names
    assert [(j, s) for j, s, _, _ in sm.mimic] == [(j, s) for j, s, _, _ in model.mimic]
    for (_, _, r, o), (_, _, r_num, o_num) in zip(sm.mimic, model.mimic):
        assert float(r) == r_num and float(o) == o_num
    assert "mimic: " in repr(sm)


def test_a_chain_is_resolved_as_the_numeric_model_resolves_it():
    """The couplings given by name, unresolved (joint5 -> joint4 -> joint0), on the symbolic
    model of the full tree: the same model as from the coupled one."""
    model = MODELS["chain-offsets"]
    sm = S.from_model(model.full).replace(mimic=TREES["chain-offsets"][2])
    assert sm.mimic == S.from_model(model).mimic
    assert sm.coupling == S.from_model(model).coupling
    k, r, o = sm.coupling[sm.joint_names.index("joint5")]
    assert (sm.independent[k], r, o) == (0, -1, sp.Rational(13, 20))  # -(q0 - 1/4) + 2/5


# -- the terms against the numeric algorithms --------------------------------------------------
@pytest.mark.parametrize("key", KEYS)
def test_terms_match_the_numeric_algorithms(derived, key):
    model, eom, f = derived[key]
    q, v, a = random_states(model, 8, "terms")
    g = rd.gravity(model, q)
    tau_p = rd.rnea(model, q, v, 0 * a) - rd.rnea(model, q, v, 0 * a, friction=False)
    expected = {"M": rd.crba(model, q), "C": rd.coriolis_matrix(model, q, v), "g": g,
                "C_v": rd.nonlinear_effects(model, q, v) - g, "tau_p": tau_p, "tau": rd.rnea(model, q, v, a)}
    args = {"M": (q,), "C": (q, v), "g": (q,), "C_v": (q, v), "tau_p": (q, v), "tau": (q, v, a)}
    for term, value in expected.items():
        assert_rel(f[term](*args[term]), value, TOL, term)
        if f"{term} expanded" in f:
            assert_rel(f[f"{term} expanded"](*args[term]), value, TOL, f"{term}, expanded")
    assert np.abs(tau_p).min() > 1e-3  # the passive forces are there to be checked
    assert_rel(f["M"](q[0]), expected["M"][0], TOL, "M, one state")


@pytest.mark.parametrize("key", KEYS)
def test_mimic_joints_passive_forces_act_through_G_transpose(derived, key):
    """``tau_p`` on a source coordinate holds its mimic joints' friction and springs times the
    multiplier: the full tree's passive forces at ``(P q + o, G v)`` mapped by ``G^T``, here
    computed from the joint names."""
    model, eom, f = derived[key]
    q, v, _ = random_states(model, 8, "passive")
    qf, vf = full_coordinates(model, q, v)
    full_tau_p = rd.rnea(model.full, qf, vf, 0 * vf) - rd.rnea(model.full, qf, vf, 0 * vf, friction=False)
    G = np.zeros((model.full.nv, model.nv))
    G[model.independent_v, np.arange(model.nv)] = 1.0
    for joint, source, r, _ in model.mimic:
        G[model.full.idx_v[model.full.body_joint_names.index(joint)], model.joint_names.index(source)] = r
    assert_rel(f["tau_p"](q, v), full_tau_p @ G, TOL, "tau_p = G^T tau_p,full")
    assert_rel(f["M"](q), G.T @ rd.crba(model.full, qf) @ G, TOL, "M = G^T M_full G")


@pytest.mark.parametrize("key", KEYS)
def test_christoffel_symbols_and_skew_symmetry(derived, key):
    """``C`` is linear in ``v`` with the numeric Christoffel symbols as coefficients,
    ``Gamma[:, :, k] = C(q, e_k)``, symmetric in ``j, k``; ``Mdot = C + C^T`` holds exactly in
    the ring (``Mdot - 2C`` skew-symmetric)."""
    model, eom, f = derived[key]
    n, rg = eom.n, eom.ring
    M, C = eom.polynomials["M"], eom.polynomials["C"]
    for i in range(n):
        for j in range(n):
            assert rg.reduce(rg.ddt(M[i][j]) - C[i][j] - C[j][i]) == 0, (i, j)
    q = random_states(model, 4, "christoffel")[0]
    gamma = np.stack([f["C"](q, np.broadcast_to(e, q.shape)) for e in np.eye(n)], axis=-1)
    assert_rel(gamma, rd.christoffel_symbols(model, q), TOL, "Gamma")
    assert_rel(gamma, np.swapaxes(gamma, -1, -2), 1e-12, "Gamma symmetric in j, k")


@pytest.mark.parametrize("key", KEYS)
def test_energies(derived, key):
    """``T = v^T M v / 2`` (armature in ``M``), ``U`` the gravity potential plus the springs of
    every joint of the tree at ``P q + o``."""
    model, eom, f = derived[key]
    q, v, _ = random_states(model, 8, "energies")
    qf, _ = full_coordinates(model, q, v)
    full = model.full
    springs = 0.5 * np.sum(full.stiffness * (qf - full.spring_reference) ** 2, axis=-1)
    assert_rel(f["T"](q, v), 0.5 * np.einsum("bi,bij,bj->b", v, rd.crba(model, q), v), TOL, "T")
    assert_rel(f["U"](q), rd.potential_energy(model, q) + springs, TOL, "U")


@pytest.mark.parametrize("key", ["small", "urdf"])
def test_regressor(key):
    """``Y = G^T Y_full``: the numeric regressor of the coupled model (its 10 columns per body
    of the full tree), and ``Y theta`` the rigid-body joint forces."""
    model = MODELS[key]
    reg = S.regressor(model)
    Y = reg.to_function()
    q, v, a = random_states(model, 6, "regressor")
    assert reg.Y.shape == (model.nv, 10 * model.nbodies)
    assert_rel(Y(q, v, a), rd.regressor(model, q, v, a), TOL, "Y")
    assert_rel(Y(q, v, a) @ model.inertial_parameters(), rd.rnea(model, q, v, a, friction=False, armature=False),
               TOL, "Y theta")


def test_recursive_dynamics_of_a_coupled_model():
    """The straight-line code of the recursions, without the expanded derivation."""
    model = MODELS["multiple-angles"]
    rec = S.recursive_dynamics(model)
    q, v, a = random_states(model, 8, "recursive")
    assert_rel(rec.to_function("M")(q), rd.crba(model, q), TOL, "M")
    assert_rel(rec.to_function("tau")(q, v, a), rd.rnea(model, q, v, a), TOL, "tau")
    rigid = S.recursive_dynamics(model, friction=False)
    assert_rel(rigid.to_function("tau")(q, v, a), rd.rnea(model, q, v, a, friction=False), TOL, "tau, no friction")


def test_numba_and_c_code(derived, tmp_path):
    model, eom, _ = derived["chain-offsets"]
    n = model.nv
    q, v, a = random_states(model, 4, "c")
    M = eom.to_numba("M")
    assert_rel(M(q), rd.crba(model, q), TOL, "M, Numba")
    files = eom.to_c(tmp_path)
    assert f"#define RANDOM6_SEED2_NV {n}" in files["random6_seed2_dynamics.h"]
    lib = compile_c(files, tmp_path, "coupled")
    for qi, vi, ai in zip(q, v, a):
        assert_rel(call_c(lib.random6_seed2_M, n * n, qi).reshape(n, n), rd.crba(model, qi), TOL, "M, C")
        assert_rel(call_c(lib.random6_seed2_C, n * n, qi, vi).reshape(n, n), rd.coriolis_matrix(model, qi, vi),
                   TOL, "C, C")
        assert_rel(call_c(lib.random6_seed2_g, n, qi), rd.gravity(model, qi), TOL, "g, C")
        assert_rel(call_c(lib.random6_seed2_tau, n, qi, vi, ai), rd.rnea(model, qi, vi, ai), TOL, "tau, C")


# -- the URDF ----------------------------------------------------------------------------------
def test_urdf_routes_agree_exactly_and_latex(derived):
    """On the URDF (exact rotations, one offset) the Newton-Euler route gives the Lagrange
    route's terms exactly; the LaTeX document names the mimic joints and their coordinates."""
    model, eom, _ = derived["urdf"]
    assert isinstance(model, rd.CoupledModel) and model.joint_names == ("shoulder", "elbow", "left_finger")
    ne = S.equations_of_motion(model, "newton_euler")
    for term in ("M", "C", "g", "tau", "T", "U"):
        assert eom.equals(ne, term), term
    doc = eom.latex()
    assert r"3 joints: shoulder (revolute), elbow (revolute), left\_finger (revolute)" in doc
    assert r"right\_finger (revolute) at $\frac{1}{10} - q_{3}$" in doc
    assert r"rack (prismatic) at $\frac{q_{2}}{50} + \frac{1}{100}$" in doc
    assert "M_{11}" in eom.latex("M") and r"\tau_{p,3}" in doc


def test_symbolic_multiplier_of_a_prismatic_mimic_joint():
    """A prismatic joint follows with any multiplier, a symbol too: it becomes a parameter of
    the generated functions."""
    rho = sp.Symbol("rho", positive=True)
    model = MODELS["chain-offsets"]
    sm = S.from_model(model.full).replace(mimic=[(j, s, rho if j == "joint3" else r, o)
                                                 for j, s, r, o in TREES["chain-offsets"][2]])
    assert rho in sm.parameters()
    rec = S.recursive_dynamics(sm)
    q, v, a = random_states(model, 4, "symbolic multiplier")
    for value in (2.5, -0.7):
        numeric = rd.CoupledModel(model.full, [(j, s, value if j == "joint3" else r, o)
                                               for j, s, r, o in TREES["chain-offsets"][2]])
        params = np.array([value])
        assert_rel(rec.to_function("M")(q, params), rd.crba(numeric, q), TOL, f"M, rho = {value}")
        assert_rel(rec.to_function("tau")(q, v, a, params), rd.rnea(numeric, q, v, a), TOL, f"tau, rho = {value}")


# -- what is refused ---------------------------------------------------------------------------
def test_couplings_that_are_not_trigonometric_polynomials_are_refused():
    with pytest.raises(rd.ModelError, match=r"mimic joint 'right_finger' \(revolute\) follows 'left_finger' "
                                            r"\(revolute\) with multiplier 0\.5.*integer multiplier.*sin\(0\.5 q\)"
                                            r".*model\.full.*mimic='independent'"):
        S.from_model(rd.load_urdf(urdf("0.5")))
    full = random_model(6, 10, False, 0.4, ONE_DOF)  # RRRPRR
    with pytest.raises(rd.ModelError, match=r"mimic joint 'joint4' \(revolute\) follows 'joint3' \(prismatic\) "
                                            r"with multiplier 2"):
        S.equations_of_motion(rd.CoupledModel(full, [("joint4", "joint3", 2.0, 0.0)]))
    sm = S.from_model(full)
    for mimic, message in (([("joint4", "nope", 1, 0)], "source joint 'nope' is not a joint"),
                           ([("joint4", "joint4", 1, 0)], "mimics itself"),
                           ([("joint4", "joint5", 1, 0), ("joint5", "joint4", 1, 0)], "form a cycle"),
                           ([("joint4", "joint0", sp.nan, 0)], "multiplier must be finite"),
                           ([("joint4", "joint0", 1)], "mimic entries are")):
        with pytest.raises(rd.ModelError, match=message):
            sm.replace(mimic=mimic)


# -- the command line --------------------------------------------------------------------------
def test_cli_derive_on_a_urdf_with_mimic_joints(tmp_path, capsys):
    """``robodyn derive`` takes the coupled model: the summary names the mimic joints, and the
    written C code computes the numeric coupled model's terms."""
    from robodyn.cli import main

    path = tmp_path / "pinch.urdf"
    path.write_text(urdf())
    model = rd.load_urdf(path)
    tex, cdir = tmp_path / "pinch.tex", tmp_path / "c"
    assert main(["derive", str(path), "--latex", str(tex), "--c", str(cdir)]) == 0
    out = capsys.readouterr().out
    assert "'pinch': 3 joints" in out
    assert "mimic joints (not coordinates): rack = 0.02 elbow + 0.01, right_finger = -1 left_finger + 0.1" in out
    assert r"right\_finger (revolute) at $\frac{1}{10} - q_{3}$" in tex.read_text()
    lib = compile_c({"pinch_dynamics.c": None}, cdir, "pinch")
    for q, v, a in zip(*random_states(model, 3, "cli")):
        assert_rel(call_c(lib.pinch_M, 9, q).reshape(3, 3), rd.crba(model, q), TOL, "M")
        assert_rel(call_c(lib.pinch_tau, 3, q, v, a), rd.rnea(model, q, v, a), TOL, "tau")
    bad = tmp_path / "bad.urdf"
    bad.write_text(urdf("0.5"))
    assert main(["derive", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "multiplier 0.5" in err and "mimic='independent'" in err and "Traceback" not in err
    with pytest.warns(rd.RobodynWarning, match="mimic joints loaded as independent joints"):
        assert main(["derive", str(bad), "--mimic", "independent"]) == 0
    assert "'pinch': 5 joints" in capsys.readouterr().out
