"""robodyn.symbolic: closed forms against textbooks, the two derivation routes against each
other, and the generated code (NumPy, Numba, C) against the numeric kernels."""

from __future__ import annotations

import ctypes
import shutil
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import symbolic as S
from robodyn.io.dh import DHLink
from robodyn.models import panda

from helpers import assert_rel, rng_for

# every built-in robot with at most 6 joints
SMALL_ROBOTS = ["pendulum", "double_pendulum", "planar_2r", "elbow_3r", "scara", "puma560", "ur5"]
g, l1, l2, r1, r2 = sp.symbols("g l1 l2 r1 r2", positive=True)


@pytest.fixture(scope="module")
def derived():
    """Each built-in robot derived once per module (Lagrange route) with its NumPy functions."""
    out = {}
    for name in SMALL_ROBOTS:
        model = rd.models.load(name)
        eom = S.equations_of_motion(model)
        out[name] = (model, eom, {t: eom.to_function(t) for t in ("M", "C", "g", "tau", "T", "U")})
    return out


def random_states(model, n=8, *keys):
    rng = rng_for(model.name, *keys)
    return (rng.uniform(-np.pi, np.pi, (n, model.nq)), rng.uniform(-2, 2, (n, model.nv)),
            rng.uniform(-3, 3, (n, model.nv)))


# -- generated functions against the numeric kernels ----------------------------------------
@pytest.mark.parametrize("name", SMALL_ROBOTS)
def test_generated_functions_match_numeric_kernels(derived, name):
    model, eom, f = derived[name]
    q, v, a = random_states(model)
    assert_rel(f["M"](q), rd.crba(model, q), 1e-10, "M")
    assert_rel(f["C"](q, v), rd.coriolis_matrix(model, q, v), 1e-10, "C")
    assert_rel(f["g"](q), rd.gravity(model, q), 1e-10, "g")
    assert_rel(f["tau"](q, v, a), rd.rnea(model, q, v, a), 1e-10, "tau")
    rotor = 0.5 * np.einsum("k,bk,bk->b", model.armature, v, v)
    assert_rel(f["T"](q, v), rd.kinetic_energy(model, q, v) + rotor, 1e-10, "T")
    assert_rel(f["U"](q), rd.potential_energy(model, q), 1e-10, "U")
    # one state in, one state out
    assert_rel(f["M"](q[0]), rd.crba(model, q[0]), 1e-10, "M, one state")


def test_generated_function_checks_shapes(derived):
    model, eom, f = derived["planar_2r"]
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 2\), got \(3,\)"):
        f["M"](np.zeros(3))
    with pytest.raises(ValueError, match=r"v: expected shape \(\.\.\., 2\)"):
        f["C"](np.zeros(2), np.zeros(5))


def test_numba_functions(derived):
    model, eom, _ = derived["elbow_3r"]
    q, v, a = random_states(model, 16, "numba")
    M, C, tau = eom.to_numba("M"), eom.to_numba("C"), eom.to_numba("tau")
    assert_rel(M(q), rd.crba(model, q), 1e-10, "M")
    assert_rel(M(q[3]), rd.crba(model, q[3]), 1e-10, "M, one state")
    assert_rel(C(q, v), rd.coriolis_matrix(model, q, v), 1e-10, "C")
    assert_rel(tau(q.reshape(4, 4, 3), v.reshape(4, 4, 3), a.reshape(4, 4, 3)),
               rd.rnea(model, q, v, a).reshape(4, 4, 3), 1e-10, "tau, 2-d batch")


def compile_c(files: dict, directory, name):
    cc = shutil.which("cc") or shutil.which("gcc")
    assert cc, "a C compiler (cc or gcc) is required to test the generated C code"
    src = [str(directory / k) for k in files if k.endswith(".c")]
    lib = directory / f"lib{name}.so"
    subprocess.run([cc, "-O0", "-shared", "-fPIC", "-o", str(lib), *src, "-lm"], check=True, capture_output=True)
    return ctypes.CDLL(str(lib))


def call_c(fn, out_size, *arrays):
    out = np.zeros(out_size)
    ptr = ctypes.POINTER(ctypes.c_double)
    args = [np.ascontiguousarray(x, dtype=float).ctypes.data_as(ptr) for x in arrays]
    fn(*args, out.ctypes.data_as(ptr))
    return out


@pytest.mark.parametrize("name", ["elbow_3r", "puma560"])
def test_c_code_compiles_and_matches(derived, name, tmp_path):
    model, eom, _ = derived[name]
    files = eom.to_c(tmp_path)
    assert set(files) == {f"{name}_dynamics.h", f"{name}_dynamics.c"}
    header = (tmp_path / f"{name}_dynamics.h").read_text()
    for term in ("M", "C", "g", "tau"):
        assert f"void {name}_{term}(const double *q" in header
    lib = compile_c(files, tmp_path, name)
    n = model.nv
    for q, v, a in zip(*random_states(model, 4, "c")):
        assert_rel(call_c(lib[f"{name}_M"], n * n, q).reshape(n, n), rd.crba(model, q), 1e-10, "M")
        assert_rel(call_c(lib[f"{name}_C"], n * n, q, v).reshape(n, n), rd.coriolis_matrix(model, q, v), 1e-10, "C")
        assert_rel(call_c(lib[f"{name}_g"], n, q), rd.gravity(model, q), 1e-10, "g")
        assert_rel(call_c(lib[f"{name}_tau"], n, q, v, a), rd.rnea(model, q, v, a), 1e-10, "tau")


# -- generated code of the recursions -------------------------------------------------------
ALL_ROBOTS = SMALL_ROBOTS + ["panda"]
RECURSIVE_TERMS = ("M", "C_v", "g", "tau")


@pytest.fixture(scope="module")
def recursive():
    """Each built-in robot's recursions (armature on every joint, so that it is tested too)."""
    out = {}
    for name in ALL_ROBOTS:
        model = rd.models.load(name)
        model = model.replace(armature=rng_for(name, "armature").uniform(0.01, 0.1, model.nv))
        out[name] = (model, S.recursive_dynamics(model))
    return out


def numeric_terms(model, q, v, a):
    """The recursive terms by the numeric kernels: M, C v, g, tau."""
    g = rd.gravity(model, q)
    return {"M": rd.crba(model, q), "C_v": rd.rnea(model, q, v, 0 * v, friction=False) - g, "g": g,
            "tau": rd.rnea(model, q, v, a)}


def inputs(term, q, v, a):
    return {"M": (q,), "C_v": (q, v), "g": (q,), "tau": (q, v, a)}[term]


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_recursive_terms_match_numeric_kernels(recursive, name):
    model, rec = recursive[name]
    q, v, a = random_states(model, 8, "recursive")
    expected = numeric_terms(model, q, v, a)
    for term in RECURSIVE_TERMS:
        f = rec.to_function(term)
        assert_rel(f(*inputs(term, q, v, a)), expected[term], 1e-12, term)
        assert_rel(f(*inputs(term, q[0], v[0], a[0])), expected[term][0], 1e-12, f"{term}, one state")
    # straight-line code: for 6 and 7 joints far fewer assignments than monomials in M
    assert len(rec.program("M").assignments) < 25 * model.nv**2


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_recursive_numba_mass_matrix(recursive, name):
    model, rec = recursive[name]
    q, _, _ = random_states(model, 6, "recursive numba")
    M = rec.to_numba("M")
    expected = rd.crba(model, q)
    for k in range(len(q)):  # the single-state path: 1-D float64 arrays
        assert_rel(M(q[k]), expected[k], 1e-12, "M, one state")
    assert_rel(M(q.reshape(2, 3, -1)), expected.reshape(2, 3, model.nv, model.nv), 1e-12, "M, 2-d batch")


def test_recursive_numba_inputs(recursive):
    model, rec = recursive["scara"]
    q, v, a = random_states(model, 6, "recursive numba")
    expected = numeric_terms(model, q, v, a)
    M = rec.to_numba("M")
    assert_rel(M(q), expected["M"], 1e-12, "M")
    assert_rel(M(list(q[0])), expected["M"][0], 1e-12, "M, a list")
    assert_rel(M(np.asfortranarray(q).T[:, 1]), expected["M"][1], 1e-12, "M, a strided vector")
    assert_rel(M(q[2].astype(np.float32)), rd.crba(model, q[2].astype(np.float32).astype(float)), 1e-12,
               "M, float32")
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 4\), got \(5,\)"):
        M(np.zeros(5))
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 4\), got \(\)"):
        M(1.0)
    tau = rec.to_numba("tau")
    assert_rel(tau(q, v, a), expected["tau"], 1e-12, "tau")
    q0, v0 = np.broadcast_to(q[0], q.shape), np.broadcast_to(v[0], v.shape)
    assert_rel(tau(q[0], v[0], a), rd.rnea(model, q0, v0, a), 1e-12, "tau, broadcast")
    with pytest.raises(ValueError, match=r"a: expected shape \(\.\.\., 4\), got \(3,\)"):
        tau(q[0], v[0], a[0, :3])
    assert_rel(rec.to_numba("C_v")(q[2], v[2]), expected["C_v"][2], 1e-12, "C_v, one state")


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_recursive_c_code(recursive, name, tmp_path):
    model, rec = recursive[name]
    files = rec.to_c(tmp_path)
    header = (tmp_path / f"{name}_dynamics.h").read_text()
    assert "composite-rigid-body recursion" in header
    lib = compile_c(files, tmp_path, name)
    n = model.nv
    q, v, a = random_states(model, 4, "recursive c")
    expected = numeric_terms(model, q, v, a)
    for k in range(len(q)):
        for term in RECURSIVE_TERMS:
            out = call_c(lib[f"{name}_{term}"], expected[term][k].size, *inputs(term, q[k], v[k], a[k]))
            assert_rel(out.reshape(expected[term][k].shape), expected[term][k], 1e-12, term)
    assert n == int(header.split(f"#define {name.upper()}_NV ")[1].split()[0])


def test_recursive_mass_matrix_is_the_expanded_one():
    """The composite-rigid-body recursion on exact polynomials gives exactly the Lagrange M."""
    from robodyn.symbolic import crba, lagrange
    from robodyn.symbolic._ring import TrigRing

    for name in ("scara", "puma560"):
        rg = TrigRing(S.from_model(rd.models.load(name)))
        assert crba.mass_matrix(rg) == lagrange.mass_matrix(rg), name


def test_recursive_forms_with_parameters():
    """Models with free symbols: the recursive and the expanded code take the same params."""
    a1, alpha1, d2, m1 = sp.symbols("a1 alpha1 d2 m1", real=True)
    twisted = [DHLink(a=a1, alpha=alpha1, d=0, mass=m1, com=(0.1, 0, 0), inertia=sp.diag(0.1, 0.2, 0.3)),
               DHLink(a=0.3, alpha=0, d=d2, mass=2, com=(0, 0.1, 0.05), inertia=sp.diag(0.1, 0.2, 0.3)),
               DHLink(a=0, alpha=0, d=0, theta=0.2, joint="prismatic", mass=1, com=(0, 0, 0.1),
                      inertia=sp.diag(0.1, 0.1, 0.1))]
    models = {"planar_2r": planar_2r_symbolic()[0], "scara": scara_symbolic()[0],
              "elbow_3r": S.with_inertia_symbols(rd.models.load("elbow_3r")),
              "twisted": S.from_dh(twisted, convention="modified")}  # cos(alpha1), sin(alpha1) in the code
    for name, model in models.items():
        eom = S.equations_of_motion(model)
        rng = rng_for(name, "forms")
        params = rng.uniform(0.5, 2.0, len(eom.parameters))
        q, v, a = rng.uniform(-3, 3, (3, 5, model.nv))
        for term in RECURSIVE_TERMS:
            fast, full = eom.to_function(term), eom.to_function(term, form="expanded")
            assert "recursion" in eom.program(term).doc and "expanded" in eom.program(term, "expanded").doc
            assert_rel(fast(*inputs(term, q, v, a), params), full(*inputs(term, q, v, a), params), 1e-12, term)
    # the numbers of a numeric model as parameters: the numeric kernels
    numeric = rd.models.load("elbow_3r")
    rec = S.recursive_dynamics(models["elbow_3r"])
    values = dict(zip([s.name for s in models["elbow_3r"].inertial_parameters()], numeric.inertial_parameters()))
    params = np.array([values[s.name] for s in rec.parameters])
    q, v, a = random_states(numeric, 5, "forms")
    assert_rel(rec.to_numba("M")(q, params), rd.crba(numeric, q), 1e-12, "M with parameters")
    assert_rel(rec.to_function("tau")(q, v, a, params), rd.rnea(numeric, q, v, a), 1e-12, "tau with parameters")


def test_recursive_prismatic_joints_on_random_trees():
    for seed in range(3):
        model = rd.random.random_model(4, seed=seed, floating_base=False, branching=0.6)
        rec = S.recursive_dynamics(model)
        q, v, a = random_states(model, 4, seed, "recursive")
        expected = numeric_terms(model, q, v, a)
        for term in RECURSIVE_TERMS:
            assert_rel(rec.to_function(term)(*inputs(term, q, v, a)), expected[term], 1e-12, term)


def test_form_errors(derived):
    model, eom, _ = derived["planar_2r"]
    with pytest.raises(ValueError, match="form must be one of"):
        eom.to_function("M", form="fast")
    with pytest.raises(ValueError, match="form='recursive' is available for"):
        eom.program("C", form="recursive")
    assert eom.program("C").doc.endswith("expanded (lagrange derivation)")
    rec = S.recursive_dynamics(model)
    with pytest.raises(ValueError, match="needs the derived equations"):
        rec.program("M", form="expanded")
    with pytest.raises(ValueError, match="term must be one of"):
        rec.program("C")


# -- the two routes -------------------------------------------------------------------------
def spherical_pendulum():
    """Point mass m on a massless rod of length l; q1 = azimuth phi about the vertical z,
    q2 = polar angle theta from the downward vertical (about the turned y axis)."""
    m, l = sp.symbols("m l", positive=True)
    return S.SymbolicModel(
        parent=(-1, 0), joint_type=("revolute", "revolute"), joint_axis=([0, 0, 1], [0, 1, 0]),
        X_tree_R=(sp.eye(3), sp.eye(3)), X_tree_p=([0, 0, 0], [0, 0, 0]),
        theta=([0] * 10, S.inertial_parameters(m, [0, 0, -l], sp.zeros(3))),
        gravity=[0, 0, -g], name="spherical_pendulum"), m, l


def planar_2r_symbolic():
    """Two-link planar arm in the x-y plane, gravity along -y (Murray-Li-Sastry notation)."""
    m1, m2, Iz1, Iz2 = sp.symbols("m1 m2 Iz1 Iz2", positive=True)
    links = [DHLink(a=l1, alpha=0, d=0, mass=m1, com=(r1 - l1, 0, 0), inertia=sp.diag(0, Iz1, Iz1)),
             DHLink(a=l2, alpha=0, d=0, mass=m2, com=(r2 - l2, 0, 0), inertia=sp.diag(0, Iz2, Iz2))]
    return S.from_dh(links, gravity=(0, -g, 0), name="planar_2r"), (m1, m2, Iz1, Iz2)


def scara_symbolic():
    """Spong's RRPR SCARA with symbolic lengths, masses and inertias (diagonal, at the
    centres of mass; links 3 and 4 centred on the vertical axis)."""
    a1, a2, d1, c3 = sp.symbols("a1 a2 d1 c3", real=True)
    m = sp.symbols("m1:5", positive=True)
    I = [sp.symbols(f"Ix{k} Iy{k} Iz{k}", positive=True) for k in range(1, 5)]
    links = [
        DHLink(a=a1, alpha=0, d=d1, mass=m[0], com=(r1 - a1, 0, 0), inertia=sp.diag(*I[0])),
        DHLink(a=a2, alpha=sp.pi, d=0, mass=m[1], com=(r2 - a2, 0, 0), inertia=sp.diag(*I[1])),
        DHLink(a=0, alpha=0, d=0, theta=0, joint="prismatic", mass=m[2], com=(0, 0, c3), inertia=sp.diag(*I[2])),
        DHLink(a=0, alpha=0, d=0, mass=m[3], inertia=sp.diag(*I[3])),
    ]
    return S.from_dh(links, gravity=(0, 0, -g), name="scara"), (a1, a2, m, I)


def routes_models():
    return {
        "pendulum": S.with_inertia_symbols(rd.models.load("pendulum")),
        "spherical_pendulum": spherical_pendulum()[0],
        "planar_2r": planar_2r_symbolic()[0],
        "elbow_3r": S.with_inertia_symbols(rd.models.load("elbow_3r")),
        "scara": scara_symbolic()[0],
    }


def is_zero(expr) -> bool:
    return all(sp.simplify(e) == 0 for e in sp.Matrix([expr]))


@pytest.mark.parametrize("name", ["pendulum", "spherical_pendulum", "planar_2r", "elbow_3r", "scara"])
def test_lagrange_and_newton_euler_agree(name):
    model = routes_models()[name]
    lag = S.equations_of_motion(model, "lagrange")
    ne = S.equations_of_motion(model, "newton_euler")
    for term in ("M", "C", "C_v", "g", "T", "U", "tau"):
        assert lag.equals(ne, term), term
        assert is_zero(lag.term(term) - ne.term(term)), term
    assert lag.parameters and lag.parameters == ne.parameters


@pytest.mark.parametrize("method", ["lagrange", "newton_euler"])
def test_christoffel_matrix_properties(method):
    eom = S.equations_of_motion(planar_2r_symbolic()[0], method)
    M, C = eom.M, eom.C
    Mdot = sp.zeros(2, 2)
    for k in range(2):
        Mdot += M.diff(eom.q[k]) * eom.v[k]
    N = Mdot - 2 * C
    assert is_zero(N + N.T)
    qd = sp.Matrix(eom.v)
    assert is_zero(C * qd - eom.C_v)
    qdd = sp.Matrix(eom.a)
    assert is_zero(M * qdd + C * qd + eom.g - eom.tau)
    assert is_zero(eom.L - (eom.T - eom.U))
    assert is_zero(eom.T - (qd.T * M * qd)[0] / 2)


# -- textbook closed forms ------------------------------------------------------------------
@pytest.mark.parametrize("method", ["lagrange", "newton_euler"])
def test_spherical_pendulum_equations(method):
    model, m, l = spherical_pendulum()
    eom = S.equations_of_motion(model, method)
    phi, th = eom.q
    phid, thd = eom.v
    phidd, thdd = eom.a
    expected = sp.Matrix([
        m * l**2 * sp.sin(th) ** 2 * phidd + 2 * m * l**2 * sp.sin(th) * sp.cos(th) * thd * phid,
        m * l**2 * thdd - m * l**2 * sp.sin(th) * sp.cos(th) * phid**2 + m * g * l * sp.sin(th),
    ])
    assert is_zero(eom.tau - expected)
    assert is_zero(eom.T - m * l**2 * (thd**2 + sp.sin(th) ** 2 * phid**2) / 2)
    assert is_zero(eom.U + m * g * l * sp.cos(th))


@pytest.mark.parametrize("method", ["lagrange", "newton_euler"])
def test_two_link_planar_arm(method):
    model, (m1, m2, Iz1, Iz2) = planar_2r_symbolic()
    eom = S.equations_of_motion(model, method)
    q1, q2 = eom.q
    qd1, qd2 = eom.v
    alpha = Iz1 + Iz2 + m1 * r1**2 + m2 * (l1**2 + r2**2)
    beta = m2 * l1 * r2
    delta = Iz2 + m2 * r2**2
    c2, s2 = sp.cos(q2), sp.sin(q2)
    M = sp.Matrix([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])
    C = sp.Matrix([[-beta * s2 * qd2, -beta * s2 * (qd1 + qd2)], [beta * s2 * qd1, 0]])
    G = sp.Matrix([(m1 * r1 + m2 * l1) * g * sp.cos(q1) + m2 * r2 * g * sp.cos(q1 + q2),
                   m2 * r2 * g * sp.cos(q1 + q2)])
    assert is_zero(eom.M - M)
    assert is_zero(eom.C - C)
    assert is_zero(eom.g - G)
    # trigonometric rules applied to small terms: the textbook's cos(q1 + q2) appears
    assert eom.g[1] == m2 * r2 * g * sp.cos(q1 + q2)


def test_scara_inertia_matrix():
    model, (a1, a2, m, I) = scara_symbolic()
    eom = S.equations_of_motion(model)
    c2 = sp.cos(eom.q[1])
    Iz = [Ik[2] for Ik in I]
    m1, m2, m3, m4 = m
    d11 = (Iz[0] + m1 * r1**2 + Iz[1] + m2 * (a1**2 + r2**2 + 2 * a1 * r2 * c2)
           + (m3 + m4) * (a1**2 + a2**2 + 2 * a1 * a2 * c2) + Iz[2] + Iz[3])
    d12 = Iz[1] + m2 * (r2**2 + a1 * r2 * c2) + (m3 + m4) * (a2**2 + a1 * a2 * c2) + Iz[2] + Iz[3]
    d22 = Iz[1] + m2 * r2**2 + (m3 + m4) * a2**2 + Iz[2] + Iz[3]
    expected = sp.Matrix([[d11, d12, 0, -Iz[3]], [d12, d22, 0, -Iz[3]], [0, 0, m3 + m4, 0],
                          [-Iz[3], -Iz[3], 0, Iz[3]]])
    assert is_zero(eom.M - expected)
    assert is_zero(eom.g - sp.Matrix([0, 0, -(m3 + m4) * g, 0]))


# -- models -------------------------------------------------------------------------------
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_symbolic_dh_matches_numeric_dh(convention):
    links = panda.links()[:3]
    if convention == "standard":
        links = [DHLink(a=L.a, alpha=L.alpha, d=L.d, offset=0.3, mass=L.mass, com=L.com, inertia=L.inertia)
                 for L in links]
    model = rd.from_dh(links, convention=convention)
    eom = S.equations_of_motion(S.from_dh(links, convention=convention))
    q, v, _ = random_states(model, 6, convention)
    assert_rel(eom.to_function("M")(q), rd.crba(model, q), 1e-10, "M")
    assert_rel(eom.to_function("C")(q, v), rd.coriolis_matrix(model, q, v), 1e-10, "C")
    assert_rel(eom.to_function("g")(q), rd.gravity(model, q), 1e-10, "g")


def test_inertia_symbols_and_parameters():
    model = S.with_inertia_symbols(rd.models.load("planar_2r"))
    names = [s.name for s in model.inertial_parameters()]
    assert names == ["m1", "mx1", "my1", "mz1", "Ixx1", "Ixy1", "Iyy1", "Ixz1", "Iyz1", "Izz1",
                     "m2", "mx2", "my2", "mz2", "Ixx2", "Ixy2", "Iyy2", "Ixz2", "Iyz2", "Izz2"]
    eom = S.equations_of_motion(model)
    assert [s.name for s in eom.parameters] == sorted(names)
    # the generated function takes the parameters; with the model's numbers it is rd.crba
    numeric = rd.models.load("planar_2r")
    values = dict(zip(names, numeric.inertial_parameters()))
    params = np.array([values[s.name] for s in eom.parameters])
    q, v, a = random_states(numeric, 5, "params")
    assert_rel(eom.to_function("M")(q, params), rd.crba(numeric, q), 1e-10, "M with parameters")
    assert_rel(eom.to_function("tau")(q, v, a, params), rd.rnea(numeric, q, v, a), 1e-10, "tau with parameters")


def test_floating_base_is_rejected():
    model = rd.random.random_model(3, seed=1, floating_base=True)
    with pytest.raises(rd.ModelError, match="floating base"):
        S.equations_of_motion(model)
    with pytest.raises(ValueError, match="method must be one of"):
        S.equations_of_motion(rd.models.load("pendulum"), method="kane")


def test_prismatic_joints_on_a_random_tree():
    """A branching tree with revolute and prismatic joints along arbitrary axes."""
    for seed in range(3):
        model = rd.random.random_model(4, seed=seed, floating_base=False, branching=0.6)
        eom = S.equations_of_motion(model, "newton_euler")
        q, v, a = random_states(model, 4, seed)
        assert_rel(eom.to_function("M")(q), rd.crba(model, q), 1e-9, "M")
        assert_rel(eom.to_function("C")(q, v), rd.coriolis_matrix(model, q, v), 1e-9, "C")
        assert_rel(eom.to_function("tau")(q, v, a), rd.rnea(model, q, v, a), 1e-9, "tau")


# -- regressor ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["elbow_3r", "scara"])
def test_regressor(name):
    model = rd.models.load(name)
    reg = S.regressor(model)
    assert [s.name for s in reg.theta[:10]] == ["m1", "mx1", "my1", "mz1", "Ixx1", "Ixy1", "Iyy1", "Ixz1", "Iyz1",
                                                "Izz1"]
    Y = reg.to_function()
    q, v, a = random_states(model, 6, "regressor")
    theta = model.inertial_parameters()
    assert_rel(Y(q, v, a) @ theta, rd.rnea(model, q, v, a, friction=False, armature=False), 1e-10, "Y theta")
    # linear in theta: Y itself does not contain the parameters
    assert not (reg.Y.free_symbols & set(reg.theta))
    assert reg.Y.shape == (model.nv, 10 * model.nbodies)


# -- passive forces: friction and joint springs ---------------------------------------------
PASSIVE_ROBOTS = ["pendulum", "double_pendulum", "planar_2r", "elbow_3r", "scara", "puma560"]


def with_passive_forces(model, smoothing=0.0):
    """``model`` with random damping, Coulomb friction, springs and armature on every joint."""
    rng = rng_for(model.name, "passive", smoothing)
    n = model.nv
    return model.replace(damping=rng.uniform(0.1, 1.0, n), coulomb=rng.uniform(0.1, 1.0, n),
                         stiffness=rng.uniform(0.5, 5.0, n), spring_reference=rng.uniform(-1.0, 1.0, n),
                         armature=rng.uniform(0.01, 0.1, n), coulomb_smoothing=smoothing)


def spring_energy(model, q):
    """``sum_k K_k (q_k - q_ref_k)^2 / 2`` (joints of one dof), written out here."""
    return 0.5 * np.sum(model.stiffness * (q - model.spring_reference) ** 2, axis=-1)


@pytest.mark.parametrize("smoothing", [0.0, 0.05])
@pytest.mark.parametrize("name", PASSIVE_ROBOTS)
def test_passive_forces_match_numeric_rnea(name, smoothing):
    """Damping, Coulomb friction (sign or tanh), springs and armature: ``tau``, ``tau_p`` and
    ``U`` of both routes, as sympy expressions and as generated code of both forms, equal the
    numeric kernels (``rnea`` with friction on, the springs' energy)."""
    model = with_passive_forces(rd.models.load(name), smoothing)
    q, v, a = random_states(model, 6, "passive", smoothing)
    v[0, 0] = 0.0  # sgn(0) = 0, as the numeric kernel
    tau = rd.rnea(model, q, v, a)
    expected = {"tau": tau, "tau_p": tau - rd.rnea(model, q, v, a, friction=False),
                "U": rd.potential_energy(model, q) + spring_energy(model, q)}
    eoms = {method: S.equations_of_motion(model, method) for method in ("lagrange", "newton_euler")}
    for method, eom in eoms.items():
        for form in ("auto", "expanded"):
            assert_rel(eom.to_function("tau", form)(q, v, a), expected["tau"], 1e-10, f"tau ({method}, {form})")
        assert_rel(eom.to_function("tau_p")(q, v), expected["tau_p"], 1e-10, f"tau_p ({method})")
        assert_rel(eom.to_function("U")(q), expected["U"], 1e-10, f"U ({method})")
        assert_rel(eom.to_function("g")(q), rd.gravity(model, q), 1e-10, f"g ({method}): gravity alone")
        for term in ("tau", "tau_p", "U", "L"):
            assert eom.equals(eoms["lagrange"], term), (method, term)
    eom = eoms["lagrange"]
    assert eom.tau_p.has(sp.tanh if smoothing else sp.sign)
    # the sympy expressions themselves (the term sums as printed)
    tau = sp.lambdify([eom.q, eom.v, eom.a], eom.tau, "numpy")
    U = sp.lambdify([eom.q], eom.U, "numpy")
    for k in range(2):
        assert_rel(np.ravel(tau(q[k], v[k], a[k])), expected["tau"][k], 1e-10, "tau, sympy")
        assert_rel(U(q[k]), expected["U"][k], 1e-10, "U, sympy")
    # Numba, and the recursions without the derivation
    assert_rel(eom.to_numba("tau")(q, v, a), expected["tau"], 1e-10, "tau, numba")
    assert_rel(eom.to_numba("tau")(q[0], v[0], a[0]), expected["tau"][0], 1e-10, "tau, numba, one state")
    rec = S.recursive_dynamics(model)
    assert_rel(rec.to_function("tau")(q, v, a), expected["tau"], 1e-10, "tau, recursive_dynamics")
    assert_rel(rec.to_numba("tau_p")(q, v), expected["tau_p"], 1e-10, "tau_p, recursive_dynamics")


def test_friction_switch_as_numeric_rnea():
    """``friction=False`` leaves the passive forces and the springs' energy out, as ``rnea``'s
    switch; the armature stays in ``M``."""
    model = with_passive_forces(rd.models.load("elbow_3r"))
    q, v, a = random_states(model, 5, "switch")
    eom = S.equations_of_motion(model, friction=False)
    assert not eom.friction and "friction=False" in repr(eom)
    assert eom.tau_p == sp.zeros(3, 1)
    assert_rel(eom.to_function("tau")(q, v, a), rd.rnea(model, q, v, a, friction=False), 1e-10, "tau")
    assert_rel(eom.to_function("U")(q), rd.potential_energy(model, q), 1e-10, "U without springs")
    assert_rel(eom.to_function("M")(q), rd.crba(model, q), 1e-10, "M with armature")
    rec = S.recursive_dynamics(model, friction=False)
    assert_rel(rec.to_numba("tau")(q, v, a), rd.rnea(model, q, v, a, friction=False), 1e-10, "tau, recursive")
    assert "friction=False" in rec.program("tau").doc and "friction=False" in rec.to_c()["elbow_3r_dynamics.h"]
    assert S.equations_of_motion(model).tau - eom.tau == S.equations_of_motion(model).tau_p


def test_spring_energy_in_the_potential():
    """``U`` includes ``K (q - q_ref)^2 / 2`` with symbols: ``dU/dq = g + K (q - q_ref)``, and
    along a simulated motion ``U`` is the trajectory's potential energy."""
    K1, K2, r1_, r2_, b1, F2 = sp.symbols("K1 K2 qr1 qr2 b1 F2", positive=True)
    arm, _ = planar_2r_symbolic()
    arm = arm.replace(stiffness=(K1, K2), spring_reference=(r1_, -r2_), damping=(b1, 0), coulomb=(0, F2))
    eom = S.equations_of_motion(arm)
    q1, q2 = eom.q
    qd1, qd2 = eom.v
    assert sp.expand(eom.tau_p[0] - (b1 * qd1 + K1 * (q1 - r1_))) == 0
    assert sp.expand(eom.tau_p[1] - (F2 * sp.sign(qd2) + K2 * (q2 + r2_))) == 0
    springs = K1 * (q1 - r1_) ** 2 / 2 + K2 * (q2 + r2_) ** 2 / 2
    for k, (K, ref) in enumerate(((K1, r1_), (K2, -r2_))):
        assert sp.simplify(sp.diff(eom.U, eom.q[k]) - eom.g[k] - K * (eom.q[k] - ref)) == 0
    assert sp.simplify(eom.U - springs - S.equations_of_motion(arm, friction=False).U) == 0
    assert {K1, K2, r1_, r2_, b1, F2} <= set(eom.parameters)
    # numbers: a sprung, damped arm simulated by robodyn, its potential along the motion
    model = rd.models.load("planar_2r").replace(stiffness=[3.0, 2.0], spring_reference=[0.4, -0.3], damping=[0.5, 0.5])
    traj = rd.simulate(model, np.array([0.2, 0.1]), np.zeros(2), 0.05, 0.01)
    U = S.equations_of_motion(model).to_function("U")
    assert_rel(U(traj.q), traj.potential, 1e-10, "U along a trajectory")


def test_builder_passive_keywords():
    """The symbolic builder takes armature, damping, Coulomb friction and springs per joint
    (symbols or numbers); the generated code with their values as parameters equals the
    numeric builder's model."""
    m1, m2, b, F, K, r = sp.symbols("m1 m2 b F K r", positive=True)
    sb = S.ModelBuilder("arm", gravity=(0, -sp.Rational(981, 100), 0), coulomb_smoothing=sp.Rational(1, 20))
    sb.add_link("link1", mass=m1, com=(0.5, 0, 0), inertia=rd.inertia.rod(m1, 1, "x"))
    sb.add_link("link2", mass=m2, com=(0.4, 0, 0), inertia=rd.inertia.rod(m2, sp.Rational(4, 5), "x"))
    sb.add_joint("joint1", "revolute", "world", "link1", axis=(0, 0, 1), damping=b, coulomb=F, stiffness=K,
                 spring_reference=-r)
    sb.add_joint("joint2", "prismatic", "link1", "link2", xyz=(1, 0, 0), axis=(1, 0, 0), armature=0.02,
                 damping=0.3, stiffness=4, spring_reference=0.1)
    model = sb.build()
    assert model.damping == (b, sp.Rational(3, 10)) and model.coulomb == (F, 0)
    assert model.stiffness == (K, 4) and model.spring_reference == (-r, sp.Rational(1, 10))
    assert model.armature == (0, sp.Rational(1, 50)) and model.coulomb_smoothing == sp.Rational(1, 20)
    eom = S.equations_of_motion(model)
    assert [s.name for s in eom.parameters] == ["F", "K", "b", "m1", "m2", "r"]
    nb = rd.ModelBuilder("arm", gravity=(0, -9.81, 0))
    nb.add_link("link1", mass=2.0, com=(0.5, 0, 0), inertia=rd.inertia.rod(2.0, 1.0, "x"))
    nb.add_link("link2", mass=1.5, com=(0.4, 0, 0), inertia=rd.inertia.rod(1.5, 0.8, "x"))
    nb.add_joint("joint1", "revolute", "world", "link1", axis=(0, 0, 1), damping=0.7, friction=0.4, stiffness=2.5,
                 spring_reference=-0.6)
    nb.add_joint("joint2", "prismatic", "link1", "link2", xyz=(1, 0, 0), axis=(1, 0, 0), armature=0.02, damping=0.3,
                 stiffness=4.0, spring_reference=0.1)
    numeric = nb.build().replace(coulomb_smoothing=0.05)
    params = np.array([0.4, 2.5, 0.7, 2.0, 1.5, 0.6])
    q, v, a = random_states(numeric, 5, "builder")
    for form in ("auto", "expanded"):
        assert_rel(eom.to_function("tau", form)(q, v, a, params), rd.rnea(numeric, q, v, a), 1e-12, f"tau ({form})")
    assert_rel(eom.to_function("U")(q, params),
               rd.potential_energy(numeric, q) + spring_energy(numeric, q), 1e-12, "U")
    # the regressor leaves them out: its parameters are those of the geometry only
    assert not set(S.regressor(model).parameters) & {b, F, K, r}


def test_passive_input_errors():
    """Negative or non-finite friction, stiffness, armature or smoothing, or a negative symbol,
    are refused as the numeric model refuses them, naming the field."""
    from robodyn.errors import ModelError

    with pytest.raises(ModelError, match="stiffness must be finite and non-negative"):
        rd.models.load("planar_2r").replace(stiffness=[-1.0, 0.0])  # the numeric model's check
    arm, _ = planar_2r_symbolic()
    for field, value, match in (("stiffness", (-1, 0), r"stiffness\[0\] must be non-negative"),
                                ("damping", (0, -0.5), r"damping\[1\] must be non-negative"),
                                ("coulomb", (sp.Symbol("c", negative=True), 0), r"coulomb\[0\] must be non-negative"),
                                ("spring_reference", (0, float("inf")), r"spring_reference\[1\]: expected a finite"),
                                ("spring_reference", (sp.oo, 0), r"spring_reference\[0\] must be finite"),
                                ("stiffness", (1, 2, 3), "stiffness: expected 2 entries"),
                                ("coulomb_smoothing", -0.1, "coulomb_smoothing must be non-negative"),
                                ("armature", (0, -1), r"armature\[1\] must be non-negative")):
        with pytest.raises(ModelError, match=match):
            arm.replace(**{field: value})
    arm.replace(spring_reference=(-1, 2), stiffness=(sp.Symbol("k"), 0))  # a negative reference, a free symbol
    b = S.ModelBuilder("bad")
    b.add_link("link", mass=1)
    with pytest.raises(ModelError, match=r"joint 'j': stiffness must be non-negative, got -2"):
        b.add_joint("j", "revolute", "world", "link", axis=(0, 0, 1), stiffness=-2)
    with pytest.raises(ModelError, match=r"joint 'j': damping must be finite"):
        b.add_joint("j", "revolute", "world", "link", axis=(0, 0, 1), damping=sp.oo)
    with pytest.raises(ModelError, match="a fixed joint has no armature, friction or spring"):
        b.add_joint("j", "fixed", "world", "link", stiffness=1)
    with pytest.raises(ModelError, match="coulomb_smoothing must be non-negative"):
        S.ModelBuilder("bad", coulomb_smoothing=-1)


def test_dc_motor_plant_closed_forms():
    """A geared DC motor on every joint (``DCMotor.plant``: armature ``N^2 J_m``, damping
    ``N^2 B_m``, Coulomb ``N F_c``): the closed forms of the plant are its numeric rnea."""
    motor = rd.actuators.DCMotor(torque_constant=0.05, back_emf=0.05, resistance=1.0, inductance=1e-3,
                                 gear_ratio=[50.0, 30.0, 20.0], rotor_inertia=1e-5, viscous=2e-5, coulomb=0.01)
    plant = motor.plant(rd.models.load("elbow_3r"))
    assert np.all(plant.armature > 0) and np.all(plant.damping > 0) and np.all(plant.coulomb > 0)
    eom = S.equations_of_motion(S.from_model(plant))
    q, v, a = random_states(plant, 8, "dc motor")
    for form in ("auto", "expanded"):
        assert_rel(eom.to_function("tau", form)(q, v, a), rd.rnea(plant, q, v, a), 1e-10, f"tau ({form})")
    assert_rel(eom.to_function("M")(q), rd.crba(plant, q), 1e-10, "M")


def test_stribeck_friction_is_reported_not_dropped_silently():
    from robodyn.errors import RobodynWarning

    model = rd.models.load("planar_2r").replace(stribeck=[0.5, 0.0], stribeck_velocity=[0.1, 0.0])
    with pytest.warns(RobodynWarning, match=r"Stribeck friction of dofs \[0\]"):
        S.from_model(model)


def test_passive_latex_and_c_code(tmp_path):
    """The LaTeX document has the passive forces (sign of the velocities, springs) and the
    generated C code of ``tau`` and ``tau_p`` computes them as the numeric rnea."""
    model = with_passive_forces(rd.models.load("planar_2r"))
    eom = S.equations_of_motion(model)
    doc = eom.latex()
    assert "Passive joint forces" in doc and r"\tau_p(q, \dot q) = \tau" in doc
    assert r"\operatorname{sign}{\left(\dot{q}_{1} \right)}" in eom.latex("tau_p")
    assert r"\tau_{p,2} &=" in eom.latex("tau_p")
    assert "Passive joint forces" not in S.equations_of_motion(rd.models.load("planar_2r")).latex()
    for form in ("auto", "expanded"):
        directory = tmp_path / form
        files = eom.to_c(directory, terms=("tau", "tau_p"), form=form)
        assert "tau_p: the joints' friction and springs" in files["planar_2r_dynamics.h"]
        lib = compile_c(files, directory, f"passive_{form}")
        q, v, a = random_states(model, 3, "passive c")
        v[0, 1] = 0.0
        for k in range(3):
            assert_rel(call_c(lib.planar_2r_tau, 2, q[k], v[k], a[k]), rd.rnea(model, q[k], v[k], a[k]), 1e-12,
                       f"tau ({form})")
            assert_rel(call_c(lib.planar_2r_tau_p, 2, q[k], v[k]),
                       rd.rnea(model, q[k], v[k], a[k]) - rd.rnea(model, q[k], v[k], a[k], friction=False), 1e-12,
                       f"tau_p ({form})")


# -- LaTeX, CLI, import ---------------------------------------------------------------------
def test_latex_document(derived):
    _, eom, _ = derived["planar_2r"]
    doc = eom.latex()
    assert doc.startswith(r"\documentclass") and doc.rstrip().endswith(r"\end{document}")
    for section in ("Mass matrix", "Christoffel matrix", "Gravity forces", "Kinetic energy", "Potential energy",
                    "Lagrangian", "Joint forces"):
        assert section in doc
    tex = eom.latex("M")
    assert tex.count("&=") == 3  # M_11, M_12, M_22
    assert r"M_{11} &= 5 c_{2} + 10 " in tex and r"M_{22} &= \frac{5}{3}" in tex
    assert r"\dot{q}_{2}" in eom.latex("C")


def test_cli_derive(tmp_path, capsys):
    from robodyn.cli import main

    tex, cdir = tmp_path / "p2r.tex", tmp_path / "c"
    code = main(["derive", "planar_2r", "--method", "newton_euler", "--latex", str(tex), "--c", str(cdir)])
    out = capsys.readouterr().out
    assert code == 0
    assert "2 joints, newton-euler method" in out
    files = {p.name: p for p in cdir.iterdir()}
    assert set(files) == {"planar_2r_dynamics.h", "planar_2r_dynamics.c"}
    assert all(p.stat().st_size > 0 for p in files.values()) and tex.stat().st_size > 0
    assert r"\begin{document}" in tex.read_text() and r"M_{12}" in tex.read_text()
    # the written C code computes the model's mass matrix and gravity
    model = rd.models.load("planar_2r")
    lib = compile_c({k: None for k in files}, cdir, "p2r")
    q = np.array([0.3, -1.1])
    assert_rel(call_c(lib.planar_2r_M, 4, q).reshape(2, 2), rd.crba(model, q), 1e-12, "M")
    assert_rel(call_c(lib.planar_2r_g, 2, q), rd.gravity(model, q), 1e-12, "g")


def test_cli_derive_expanded_form(tmp_path, capsys):
    """``--form expanded`` writes every term expanded; the code computes the same M and tau."""
    from robodyn.cli import main

    cdirs = {form: tmp_path / form for form in ("auto", "expanded")}
    for form, cdir in cdirs.items():
        assert main(["derive", "elbow_3r", "--c", str(cdir), "--form", form]) == 0
    out = capsys.readouterr().out
    assert "(M, g, tau by the recursions, C expanded)" in out and "(every term expanded)" in out
    sources = {form: (cdir / "elbow_3r_dynamics.c").read_text() for form, cdir in cdirs.items()}
    assert sources["auto"] != sources["expanded"]
    model = rd.models.load("elbow_3r")
    q, qd, qdd = np.array([0.3, -1.1, 0.7]), np.array([0.5, 0.2, -0.4]), np.array([1.0, -2.0, 0.5])
    for form, cdir in cdirs.items():
        lib = compile_c({"elbow_3r_dynamics.c": None, "elbow_3r_dynamics.h": None}, cdir, f"e3r_{form}")
        assert_rel(call_c(lib.elbow_3r_M, 9, q).reshape(3, 3), rd.crba(model, q), 1e-12, f"M ({form})")
        assert_rel(call_c(lib.elbow_3r_tau, 3, q, qd, qdd), rd.rnea(model, q, qd, qdd, friction=False), 1e-12,
                   f"tau ({form})")


def test_cli_derive_with_and_without_friction(tmp_path, capsys):
    """``tau`` of the written C code carries the joints' damping and Coulomb friction, or leaves
    them out with ``--no-friction`` (as ``rnea(friction=False)``)."""
    from robodyn.cli import main

    urdf = tmp_path / "rub.urdf"
    urdf.write_text("""<robot name="rub">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.3 0 0"/><mass value="2"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.4" friction="0.3"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.6 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/><dynamics damping="0.2" friction="0.1"/></joint>
</robot>""")
    model = rd.load_urdf(urdf)
    q, qd, qdd = np.array([0.3, -1.1]), np.array([0.5, -0.2]), np.array([1.0, -2.0])
    for flags, friction in (([], True), (["--no-friction"], False)):
        cdir = tmp_path / f"c{friction}"
        assert main(["derive", str(urdf), "--c", str(cdir), *flags]) == 0
        assert f"{'with' if friction else 'without'} the joints' friction" in capsys.readouterr().out
        lib = compile_c({"rub_dynamics.c": None, "rub_dynamics.h": None}, cdir, f"rub{friction}")
        assert_rel(call_c(lib.rub_tau, 2, q, qd, qdd), rd.rnea(model, q, qd, qdd, friction=friction), 1e-12,
                   f"tau (friction={friction})")
    assert np.abs(rd.rnea(model, q, qd, qdd) - rd.rnea(model, q, qd, qdd, friction=False)).min() > 0.1


def test_cli_derive_errors(capsys):
    from robodyn.cli import main

    assert main(["derive", "no_such_robot"]) == 2
    assert "unknown model" in capsys.readouterr().err


def test_import_robodyn_does_not_import_sympy():
    code = "import sys, robodyn; assert 'sympy' not in sys.modules; robodyn.symbolic; assert 'sympy' in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_numbers_of_numeric_models_read_like_the_book():
    """Decimal model data shows as the fraction it rounds (``5/3``, ``10``) or as a float of
    15 digits, never as ``1.666666666666667`` or ``10.0``; the values are those of the numeric
    kernels."""
    model = rd.models.load("planar_2r")
    eom = S.equations_of_motion(model)
    q2 = sp.Symbol("q2", real=True)
    assert sp.simplify(eom.M - sp.Matrix([[5 * sp.cos(q2) + 10, 5 * sp.cos(q2) / 2 + sp.Rational(5, 3)],
                                          [5 * sp.cos(q2) / 2 + sp.Rational(5, 3), sp.Rational(5, 3)]])) == sp.zeros(2)
    assert not eom.M.atoms(sp.Float)
    elbow = S.equations_of_motion(rd.models.load("elbow_3r"))
    assert elbow.M.atoms(sp.Float) and all(x._prec == sp.Float(1.0, 15)._prec for x in elbow.M.atoms(sp.Float))
    q = np.array([0.3, -0.7, 1.1])
    M = np.array(elbow.M.subs(dict(zip(elbow.q, q))).evalf(), dtype=float)
    assert_rel(M, rd.crba(rd.models.load("elbow_3r"), q, armature=False), 1e-11)
