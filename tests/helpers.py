"""Helpers shared by the core-dynamics tests (test_rnea.py, test_aba.py, ...).

* seeded random trees (``RANDOM_MODELS``, decorator ``random_models``) and their states;
* ``assert_rel``: the relative-error criterion of the tests;
* motion on the configuration manifold: ``integrate`` (exact for 1-dof joints, exponential
  map in the base frame for the free joint) and ``configuration_rate`` (``dq/dt`` for ODE
  integration), ``directional_derivative`` (central differences along ``v``);
* the textbook pendulum and two-link planar arm built with ``rd.ModelBuilder``;
* ``check_batch`` and ``check_input_validation``: batch and bad-input behaviour of any
  public function, so that every test file checks its own functions the same way;
* ``richardson`` and ``tangent_differences``: derivatives by Richardson-extrapolated central
  differences (``FD_STEP``, ``FD_TOL``), along the tangent directions of ``rd.integrate``.
"""

from __future__ import annotations

import re
import zlib

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
from robodyn import joints as J
from robodyn.random import random_model, random_state

G = 9.81

# (bodies, seed, floating base, branching, joint types): chains, branches, 1..15 bodies, both
# base types; revolute and prismatic joints, and spherical, helical and planar joints mixed in
# (ids "-mixed")
ONE_DOF = (J.REVOLUTE, J.PRISMATIC)
MIXED = (J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL, J.PLANAR)
RANDOM_CASES = [
    (1, 0, False, 0.3, ONE_DOF), (1, 1, True, 0.3, ONE_DOF), (2, 2, False, 0.5, ONE_DOF), (3, 3, True, 0.9, ONE_DOF),
    (5, 4, False, 0.7, ONE_DOF), (7, 5, True, 0.3, ONE_DOF), (10, 6, False, 0.0, ONE_DOF), (12, 7, True, 0.5, ONE_DOF),
    (15, 8, False, 0.9, ONE_DOF), (15, 9, True, 0.3, ONE_DOF), (6, 13, False, 0.4, MIXED), (8, 12, True, 0.5, MIXED),
]
RANDOM_MODELS = [random_model(n, seed=s, floating_base=fb, branching=b, joint_types=jt)
                 for n, s, fb, b, jt in RANDOM_CASES]
RANDOM_IDS = [f"n{n}-seed{s}-{'floating' if fb else 'fixed'}-br{b}{'-mixed' if J.SPHERICAL in jt else ''}"
              for n, s, fb, b, jt in RANDOM_CASES]
# Models whose velocity is the derivative of the configuration (no free, spherical or planar
# joint, whose velocities are quasi-velocities): identities in coordinates hold on them.
FIXED_BASE_MODELS = [m for m in RANDOM_MODELS if np.all(J.NQ[m.joint_type] == 1)]
FIXED_BASE_IDS = [i for m, i in zip(RANDOM_MODELS, RANDOM_IDS) if np.all(J.NQ[m.joint_type] == 1)]

random_models = pytest.mark.parametrize("model", RANDOM_MODELS, ids=RANDOM_IDS)
fixed_base_models = pytest.mark.parametrize("model", FIXED_BASE_MODELS, ids=FIXED_BASE_IDS)

F_EXT_FRAMES = ("local", "world", "local_world_aligned")


def rng_for(*keys) -> np.random.Generator:
    """A generator seeded by the test's own keys (model name, frame, ...): reproducible and
    independent of test order."""
    return np.random.default_rng(zlib.crc32(repr(keys).encode()))


def states(model: rd.Model, *keys, size=()):
    """Random ``(q, v, a)`` for ``model`` seeded by its name and ``keys``."""
    return random_state(model, rng_for(model.name, *keys), size)


def with_friction_and_armature(model: rd.Model, rng: np.random.Generator, smoothing: float = 0.0) -> rd.Model:
    """The model with random viscous and Coulomb friction and armature on every dof."""
    return model.replace(damping=rng.uniform(0.1, 1.0, model.nv), coulomb=rng.uniform(0.1, 1.0, model.nv),
                         armature=rng.uniform(0.01, 0.1, model.nv), coulomb_smoothing=smoothing)


def rel_error(actual, expected) -> float:
    """``max |actual - expected| / max(1, max |expected|)``: the largest entry error, relative
    to the largest expected entry once that exceeds 1 (absolute below it); 0 for empty arrays.

    The metric is written here, not taken from robodyn, so that the package under test cannot
    change the criterion it is judged by."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, f"shape {actual.shape} != expected {expected.shape}"
    if expected.size == 0:
        return 0.0
    scale = max(1.0, float(np.max(np.abs(expected))))
    return float(np.max(np.abs(actual - expected))) / scale


def assert_rel(actual, expected, tol: float = 1e-9, what: str = "") -> None:
    """Relative error (see :func:`rel_error`) at most ``tol``."""
    err = rel_error(actual, expected)
    assert err <= tol, f"{what}: relative error {err:.3g} > {tol:g}\nactual={actual}\nexpected={expected}"


def unit(n: int, j: int) -> np.ndarray:
    e = np.zeros(n)
    e[j] = 1.0
    return e


# -- quaternions (x, y, z, w), as in q ----------------------------------------------------
def quat_mul(a, b) -> np.ndarray:
    """Hamilton product ``a b`` of quaternions ``(x, y, z, w)``."""
    av, aw, bv, bw = np.asarray(a[:3]), a[3], np.asarray(b[:3]), b[3]
    return np.concatenate([aw * bv + bw * av + np.cross(av, bv), [aw * bw - av @ bv]])


def quat_exp(w) -> np.ndarray:
    """Unit quaternion of the rotation vector ``w``."""
    angle = np.linalg.norm(w)
    if angle == 0.0:
        return np.array([0.0, 0.0, 0.0, 1.0])
    return np.concatenate([np.sin(angle / 2) * np.asarray(w) / angle, [np.cos(angle / 2)]])


def quat_to_matrix(quat) -> np.ndarray:
    """Rotation matrix of a quaternion (x, y, z, w), normalised first (as robodyn does)."""
    return Rotation.from_quat(quat).as_matrix()


def _rotation_joints(model: rd.Model):
    """``(q index, v index, free)`` of the free and spherical joints (quaternions)."""
    for i in np.flatnonzero((model.joint_type == J.FREE) | (model.joint_type == J.SPHERICAL)):
        yield int(model.idx_q[i]), int(model.idx_v[i]), bool(model.joint_type[i] == J.FREE)


def _scalar_joints(model: rd.Model) -> tuple[np.ndarray, np.ndarray]:
    one = J.NQ[model.joint_type] == 1
    return model.idx_q[one], model.idx_v[one]


def _planar_joints(model: rd.Model):
    for i in np.flatnonzero(model.joint_type == J.PLANAR):
        yield int(model.idx_q[i]), int(model.idx_v[i])


def integrate(model: rd.Model, q, v, dt: float) -> np.ndarray:
    """``q`` moved for ``dt`` along ``v``: 1-dof joints by ``v dt``; a free joint's position by
    ``R v_lin dt`` and its orientation (a spherical joint's too) by ``R exp(omega dt)`` (``v``
    in the child frame), so that the curve leaves ``q`` with velocity ``v``."""
    q = np.array(q, dtype=float)
    out = q.copy()
    iq, iv = _scalar_joints(model)
    out[iq] += v[iv] * dt
    for kq, kv, free in _rotation_joints(model):
        k, o = (kq + 3, kv + 3) if free else (kq, kv)
        if free:
            out[kq:kq + 3] += quat_to_matrix(q[k:k + 4]) @ v[kv:kv + 3] * dt
        out[k:k + 4] = quat_mul(q[k:k + 4], quat_exp(v[o:o + 3] * dt))
    for kq, kv in _planar_joints(model):  # constant body velocity (vx, vy, w): an arc in the plane
        t0, w = np.arctan2(q[kq + 3], q[kq + 2]), v[kv + 2]
        a, b = (np.sin(w * dt) / w, (1 - np.cos(w * dt)) / w) if w != 0 else (dt, 0.0)
        lx, ly = a * v[kv] - b * v[kv + 1], b * v[kv] + a * v[kv + 1]  # in the body frame at t = 0
        out[kq] += np.cos(t0) * lx - np.sin(t0) * ly
        out[kq + 1] += np.sin(t0) * lx + np.cos(t0) * ly
        out[kq + 2], out[kq + 3] = np.cos(t0 + w * dt), np.sin(t0 + w * dt)
    return out


def configuration_rate(model: rd.Model, q, v) -> np.ndarray:
    """``dq/dt`` for velocity ``v`` (free joint: ``R v_lin`` and ``quat (omega, 0) / 2``; a
    spherical joint: ``quat (omega, 0) / 2``)."""
    qd = np.zeros(model.nq)
    iq, iv = _scalar_joints(model)
    qd[iq] = v[iv]
    for kq, kv, free in _rotation_joints(model):
        k, o = (kq + 3, kv + 3) if free else (kq, kv)
        if free:
            qd[kq:kq + 3] = quat_to_matrix(q[k:k + 4]) @ v[kv:kv + 3]
        qd[k:k + 4] = 0.5 * quat_mul(q[k:k + 4], np.append(v[o:o + 3], 0.0))
    for kq, kv in _planar_joints(model):  # (x, y)' = Rz(t) (vx, vy); (c, s)' = w (-s, c)
        c, s = q[kq + 2], q[kq + 3]
        qd[kq], qd[kq + 1] = c * v[kv] - s * v[kv + 1], s * v[kv] + c * v[kv + 1]
        qd[kq + 2], qd[kq + 3] = -s * v[kv + 2], c * v[kv + 2]
    return qd


def directional_derivative(f, model: rd.Model, q, v, h: float = 1e-5) -> np.ndarray:
    """``d/dt f(q(t))`` at ``t = 0`` along the curve of :func:`integrate`, central differences."""
    return (np.asarray(f(integrate(model, q, v, h))) - np.asarray(f(integrate(model, q, v, -h)))) / (2 * h)


def columns_by_differences(f, model: rd.Model, q, h: float = 1e-5) -> np.ndarray:
    """``[d f / d e_j]_j``: the derivative of ``f`` along each unit velocity, stacked last."""
    return np.stack([directional_derivative(f, model, q, unit(model.nv, j), h) for j in range(model.nv)], axis=-1)


def rk4(f, x0: np.ndarray, t_end: float, steps: int) -> np.ndarray:
    """Classic Runge-Kutta integration of ``x' = f(x)`` over ``[0, t_end]``."""
    x, dt = np.array(x0, dtype=float), t_end / steps
    for _ in range(steps):
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


# -- closed-form models ---------------------------------------------------------------------
def pendulum(m: float = 2.0, L: float = 0.7) -> rd.Model:
    """Point mass ``m`` at distance ``L`` along +z of a link rotating about +y; ``theta = 0``
    upright, so ``m L^2 qdd = tau + m g L sin(theta)``."""
    b = rd.ModelBuilder("pendulum-test")
    b.add_link("base")
    b.add_link("bob", mass=m, com=(0.0, 0.0, L))
    b.add_joint("hinge", "revolute", "base", "bob", axis=(0, 1, 0))
    return b.build()


PLANAR_2R = dict(m1=3.0, m2=2.0, l1=0.8, l2=0.6)


def planar_2r(m1: float, m2: float, l1: float, l2: float) -> rd.Model:
    """Two thin uniform rods along x, joints about z, gravity along -y (Spong, ch. 7)."""
    b = rd.ModelBuilder("planar-2r-test", gravity=(0.0, -G, 0.0))
    b.add_link("base")
    b.add_link("rod1", mass=m1, com=(l1 / 2, 0, 0), inertia=np.diag([0.0, m1 * l1 ** 2 / 12, m1 * l1 ** 2 / 12]))
    b.add_link("rod2", mass=m2, com=(l2 / 2, 0, 0), inertia=np.diag([0.0, m2 * l2 ** 2 / 12, m2 * l2 ** 2 / 12]))
    b.add_joint("shoulder", "revolute", "base", "rod1", axis=(0, 0, 1))
    b.add_joint("elbow", "revolute", "rod1", "rod2", xyz=(l1, 0, 0), axis=(0, 0, 1))
    return b.build()


def planar_2r_terms(q, qd, m1, m2, l1, l2):
    """Textbook ``M``, ``C`` and ``g`` of the two-link planar arm (Spong, Hutchinson and
    Vidyasagar, Robot Modeling and Control, 2006, section 7.4)."""
    r1, r2 = l1 / 2, l2 / 2
    Iz1, Iz2 = m1 * l1 ** 2 / 12, m2 * l2 ** 2 / 12
    alpha = Iz1 + Iz2 + m1 * r1 ** 2 + m2 * (l1 ** 2 + r2 ** 2)
    beta = m2 * l1 * r2
    delta = Iz2 + m2 * r2 ** 2
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    M = np.array([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])
    C = np.array([[-beta * s2 * qd[1], -beta * s2 * (qd[0] + qd[1])], [beta * s2 * qd[0], 0.0]])
    g = np.array([(m1 * r1 + m2 * l1) * G * np.cos(q[0]) + m2 * r2 * G * np.cos(q[0] + q[1]),
                  m2 * r2 * G * np.cos(q[0] + q[1])])
    return M, C, g


# -- batch and bad-input checks of any public function ----------------------------------------
def check_batch(call, model: rd.Model, names, tol: float = 1e-12) -> None:
    """``call(model, **arrays)`` on a (2, 3) batch equals the individual calls, and a single
    ``q`` (nq,) broadcasts against the other arrays of shape (4, n)."""
    rng = rng_for(model.name, "batch", tuple(names))
    q, v, a = random_state(model, rng, (2, 3))
    pool = {"q": q, "v": v, "a": a, "tau": a}
    arrays = {name: pool[name] for name in names}
    batch = np.asarray(call(model, **arrays))
    assert batch.shape[:2] == (2, 3)
    for i in np.ndindex(2, 3):
        assert_rel(batch[i], call(model, **{k: x[i] for k, x in arrays.items()}), tol, f"batch element {i}")
    if len(names) > 1:
        wide = {k: (x[0, 0] if k == "q" else np.concatenate([x[0], x[1, :1]])) for k, x in arrays.items()}
        out = np.asarray(call(model, **wide))
        assert out.shape[0] == 4
        for i in range(4):
            assert_rel(out[i], call(model, **{k: (x if k == "q" else x[i]) for k, x in wide.items()}), tol,
                       f"broadcast element {i}")


def _floating_model() -> rd.Model:
    return random_model(4, seed=3, floating_base=True)


INPUT_CHECKS = ("shapes", "nonfinite", "unchecked_nonfinite", "quaternion")


def check_input_validation(call, names, aspect: str) -> None:
    """Bad input to ``call(model, check_finite=..., **arrays)`` (arrays named by ``names``),
    one ``aspect`` of :data:`INPUT_CHECKS` at a time, single states and batches:

    * ``shapes``: wrong last dimension, a scalar, or batches that do not broadcast: ValueError
      naming the argument, the expected and the received shape;
    * ``nonfinite``: NaN or Inf: ValueError naming the argument;
    * ``unchecked_nonfinite``: no exception with ``check_finite=False``;
    * ``quaternion``: one far from unit norm (or zero): ValueError; near-unit: normalised.
    """
    assert aspect in INPUT_CHECKS
    model = _floating_model()
    q, v, a = states(model, "bad-input")
    good = {k: {"q": q, "v": v, "a": a, "tau": a}[k] for k in names}
    size = {k: model.nq if k == "q" else model.nv for k in names}

    def variants(name, value, index):
        """The state with ``name[index] = value``, alone and as element 1 of a batch of 3."""
        one = good[name].copy()
        one[index] = value
        yield {**good, name: one}
        yield {**{k: np.stack([x] * 3) for k, x in good.items()}, name: np.stack([good[name], one, good[name]])}

    def unperturbed(arrays):
        return call(model, **{k: np.broadcast_to(good[k], x.shape) for k, x in arrays.items()})

    if aspect == "quaternion":
        if "q" not in names:
            return
        for factor in (1.5, 0.5, 0.0):
            for arrays in variants("q", q[3:7] * factor, slice(3, 7)):
                with pytest.raises(ValueError, match=r"\bq\b.* quaternion of free joint 'root_joint'"):
                    call(model, **arrays)
        for factor in (1 + 5e-4, 1 - 5e-4):
            for arrays in variants("q", q[3:7] * factor, slice(3, 7)):
                assert_rel(call(model, **arrays), unperturbed(arrays), 1e-12, f"quaternion scaled by {factor}")
        return
    for name in names:
        n = size[name]
        if aspect == "shapes":
            for bad in (np.zeros(n + 1), np.zeros((3, n - 1)), np.float64(1.0)):
                with pytest.raises(ValueError) as err:
                    call(model, **{**good, name: bad})
                msg = str(err.value)
                assert re.match(rf"{name}\b", msg), msg
                assert f"(..., {n})" in msg and str(np.shape(bad)) in msg, msg
            if len(names) > 1:
                other = next(k for k in names if k != name)
                with pytest.raises(ValueError, match="broadcast") as err:
                    call(model, **{**good, name: np.stack([good[name]] * 2), other: np.stack([good[other]] * 3)})
                assert str((2, size[name])) in str(err.value) and str((3, size[other])) in str(err.value)
            continue
        for value in (np.nan, np.inf, -np.inf):
            for arrays in variants(name, value, -1):
                if aspect == "nonfinite":
                    with pytest.raises(ValueError, match=rf"\b{name}\b.* NaN or Inf"):
                        call(model, **arrays)
                else:
                    out = np.asarray(call(model, **arrays, check_finite=False))
                    assert out.shape == np.shape(unperturbed(arrays))


input_checks = pytest.mark.parametrize("aspect", INPUT_CHECKS)


def massless_leaf_model(floating_base: bool = False) -> rd.Model:
    """An arm with a massless leaf ``finger`` on joint ``knuckle``: its articulated inertia,
    and so ``M(q)``, is singular."""
    b = rd.ModelBuilder("leafy")
    b.add_link("base", mass=1.0, inertia=np.eye(3) * 0.1)
    b.add_link("arm", mass=1.0, com=(0.2, 0, 0), inertia=np.eye(3) * 0.01)
    b.add_link("finger")  # no inertial: massless
    b.add_joint("shoulder", "revolute", "base", "arm", axis=(0, 0, 1))
    b.add_joint("knuckle", "revolute", "arm", "finger", xyz=(0.4, 0, 0), axis=(0, 1, 0))
    return b.build(floating_base=floating_base)


# -- derivatives by differences ----------------------------------------------------------------
# Central differences with steps h and h/2 combined (Richardson): the error is O(h^4) times the
# fifth derivative (about 1e-12 at h = 1e-3 for the random trees) plus rounding of order
# eps |f| / h (about 1e-13 |f|); the tolerance leaves a factor of 100 above both.
FD_STEP = 1e-3
FD_TOL = 1e-8


def richardson(f, n: int, step: float = FD_STEP) -> np.ndarray:
    """Columns ``k`` of the derivative of ``f(eps e_k)`` at 0 (``f`` maps a (n,) step to an array)."""
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        d = [(f(h * e) - f(-h * e)) / (2 * h) for h in (step, step / 2)]
        cols.append((4 * d[1] - d[0]) / 3)
    return np.stack(cols, axis=-1)


def tangent_differences(fun, model, q, v, x, **kw):
    """``(d fun / dq, d fun / dv)`` of ``fun(model, q, v, x, **kw)`` by :func:`richardson`, ``q``
    moved along ``rd.integrate``."""
    dq = richardson(lambda d: fun(model, rd.integrate(model, q, d), v, x, **kw), model.nv)
    dv = richardson(lambda d: fun(model, q, v + d, x, **kw), model.nv)
    return dq, dv



def check_wrench_batches(fn, model: rd.Model, frame: str, size: int, tol: float) -> None:
    """``fn(model, Q, V, A, f_ext, frame)`` (a tuple of arrays) with wrenches per state
    (B, nb, 6), one for all (nb, 6) or (1, nb, 6) equals its single-state calls."""
    Q, V, A = states(model, "wrench-batch", size=size)
    F = rng_for("wrench-batch", frame).standard_normal((size, model.nbodies, 6))
    for wrenches, one in ((F, lambda s: F[s]), (F[0], lambda s: F[0]), (F[:1], lambda s: F[0])):
        out = fn(model, Q, V, A, wrenches, frame)
        for s in range(size):
            for x, y in zip(out, fn(model, Q[s], V[s], A[s], one(s), frame)):
                assert_rel(x[s], y, tol)
