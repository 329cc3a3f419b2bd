"""Task-space dynamics (robodyn.task_space_inertia, dynamically_consistent_inverse,
task_space_dynamics): the formulas from crba and jacobian on random trees, the task-space
equation of motion against aba, a point mass in closed form, Pinocchio on URDFs, batches,
singular configurations and bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import G, PLANAR_2R, RANDOM_IDS, RANDOM_MODELS, assert_rel, planar_2r, rng_for, states
from robodyn import joints as JT
from test_pinocchio import JACOBIAN_FRAMES
from urdf_subset import load_pair, pairs

FRAMES = ("world", "local", "local_world_aligned")
ROWS = {"all": slice(0, 6), "linear": slice(0, 3), "angular": slice(3, 6)}


def _ancestor_dofs(model, body):
    """Number of dofs of the joints from the root to ``body`` (its own joint included)."""
    n = 0
    while body >= 0:
        n += int(JT.NV[model.joint_type[body]])
        body = int(model.parent[body])
    return n


def _task_jacobian(model, q, body, frame, rows):
    return rd.jacobian(model, q, body, frame)[ROWS[rows]]


def _task_body(model, q, frame, rows, rcond=1e-3):
    """The body with the most dofs among its ancestors (the last of equals) whose task Jacobian
    at ``q`` has full row rank with a margin (smallest singular value at least ``rcond`` times
    the largest); None when no body has one (fewer joints, or rotation axes, than task rows)."""
    best = None
    for body in range(model.nbodies):
        J = _task_jacobian(model, q, body, frame, rows)
        s = np.linalg.svd(J, compute_uv=False)  # min(m, nv) values, largest first
        regular = s.size == J.shape[0] and s[-1] > 0 and s[-1] >= rcond * s[0]
        if regular and (best is None or _ancestor_dofs(model, body) >= _ancestor_dofs(model, best)):
            best = body
    return best


def _formula_cases():
    """``(model, frame, rows, body)`` for every random tree, frame and rows that some body can
    move in every task direction at the state of :func:`test_against_the_formulas`, and
    ``(model, rows)`` of the trees where no body can, in any frame."""
    cases, refused = [], []
    for model, name in zip(RANDOM_MODELS, RANDOM_IDS):
        for rows in ROWS:
            bodies = {frame: _task_body(model, states(model, "task", frame, rows)[0], frame, rows) for frame in FRAMES}
            for frame, body in bodies.items():
                if body is not None:
                    cases.append(pytest.param(model, frame, rows, body, id=f"{name}-{frame}-{rows}-body{body}"))
            if all(body is None for body in bodies.values()):
                refused.append(pytest.param(model, rows, id=f"{name}-{rows}"))
    return cases, refused


FORMULA_CASES, REFUSED_TASKS = _formula_cases()


def _reference(model, q, v, body, frame, rows):
    """Lambda, mu, p and Jbar from crba, nonlinear_effects, gravity and the Jacobians."""
    M = rd.crba(model, q)
    J = rd.jacobian(model, q, body, frame)[ROWS[rows]]
    Minv = np.linalg.inv(M)
    Lam = np.linalg.inv(J @ Minv @ J.T)
    Jbar = Minv @ J.T @ Lam
    g = rd.gravity(model, q)
    Cv = rd.nonlinear_effects(model, q, v) - g
    mu = Jbar.T @ Cv - Lam @ rd.jacobian_dot_times_v(model, q, v, body, frame)[ROWS[rows]]
    return Lam, mu, Jbar.T @ g, Jbar, J


@pytest.mark.parametrize("model, frame, rows, body", FORMULA_CASES)
def test_against_the_formulas(model, frame, rows, body):
    """Lambda, Jbar, mu, p and J of a body chosen by :func:`_task_body`, so that every case
    compares values (the refusals are :func:`test_tasks_with_too_few_joints_are_refused`)."""
    q, v, _ = states(model, "task", frame, rows)
    Lam, mu, p, Jbar, J = _reference(model, q, v, body, frame, rows)
    assert_rel(rd.task_space_inertia(model, q, body, frame, rows), Lam, 1e-8, "Lambda")
    assert_rel(rd.dynamically_consistent_inverse(model, q, body, frame, rows), Jbar, 1e-8, "Jbar")
    ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
    for name, mine, ref in (("Lambda", ts.Lambda, Lam), ("mu", ts.mu, mu), ("p", ts.p, p), ("Jbar", ts.Jbar, Jbar),
                            ("J", ts.J, J)):
        assert_rel(mine, ref, 1e-8, name)


def test_formula_cases_cover_every_tree():
    """The tasks left out of :func:`test_against_the_formulas` are exactly those of trees with
    too few joints or rotation axes: 1 and 2 dofs (every rows), and the fixed-base trees with
    at most five dofs above any body, some prismatic (all and angular rows); every other
    (tree, rows) is compared in the three frames."""
    assert sorted(c.id for c in REFUSED_TASKS) == sorted(
        [f"{n}-{r}" for n in ("n1-seed0-fixed-br0.3", "n2-seed2-fixed-br0.5") for r in ROWS]
        + [f"{n}-{r}" for n in ("n5-seed4-fixed-br0.7", "n15-seed8-fixed-br0.9") for r in ("all", "angular")])
    assert len(FORMULA_CASES) == 3 * (3 * len(RANDOM_MODELS) - len(REFUSED_TASKS))


@pytest.mark.parametrize("model, rows", REFUSED_TASKS)
def test_tasks_with_too_few_joints_are_refused(model, rows):
    """No body of the tree can move in every direction of ``rows`` (its task Jacobian has
    rank below the number of rows, checked here): every task-space function raises a
    ValueError naming the function, the body, the rows and the frame."""
    q, v, _ = states(model, "task-refused", rows)
    m = 6 if rows == "all" else 3
    deepest = max(range(model.nbodies), key=lambda b: (_ancestor_dofs(model, b), b))
    for frame in FRAMES:
        for body in range(model.nbodies):
            assert np.linalg.matrix_rank(_task_jacobian(model, q, body, frame, rows)) < m
            with pytest.raises(ValueError) as err:
                rd.task_space_inertia(model, q, body, frame, rows)
            assert str(err.value).startswith(f"task_space_inertia: J M^-1 J^T of {body} ({rows} rows, "
                                             f"frame '{frame}') is singular: eigenvalues "), str(err.value)
            assert "fewer joints than task rows" in str(err.value)
        for name, call in (("dynamically_consistent_inverse",
                            lambda: rd.dynamically_consistent_inverse(model, q, deepest, frame, rows)),
                           ("task_space_dynamics", lambda: rd.task_space_dynamics(model, q, v, deepest, frame, rows))):
            with pytest.raises(ValueError, match=rf"^{name}: J M\^-1 J\^T of {deepest} \({rows} rows, "
                                                 rf"frame '{frame}'\) is singular"):
                call()


@pytest.mark.parametrize("model", [m for m in RANDOM_MODELS if m.nv >= 6], ids=lambda m: m.name)
@pytest.mark.parametrize("frame", FRAMES)
def test_task_space_equation_of_motion(model, frame):
    """Joint forces tau = J^T F give the frame x'' = J a + Jdot v with Lambda x'' + mu + p = F;
    Jbar is a right inverse of J and Jbar^T M Jbar = Lambda."""
    q, v, _ = states(model, "eom")
    rows = "all" if _task_body(model, q, frame, "all") is not None else "linear"
    body = _task_body(model, q, frame, rows)
    assert body is not None
    ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
    m = ts.J.shape[0]
    F = rng_for(model.name, "F").standard_normal(m)
    a = rd.aba(model, q, v, ts.J.T @ F, friction=False)
    xdd = ts.J @ a + rd.jacobian_dot_times_v(model, q, v, body, frame)[ROWS[rows]]
    assert_rel(ts.Lambda @ xdd + ts.mu + ts.p, F, 1e-8)
    assert_rel(ts.J @ ts.Jbar, np.eye(m), 1e-9)
    assert_rel(ts.Jbar.T @ rd.crba(model, q) @ ts.Jbar, ts.Lambda, 1e-8)


def test_point_mass_closed_form():
    """A point mass on three prismatic joints: Lambda = m 1, mu = 0, p = -m g_vec."""
    b = rd.ModelBuilder("xyz")
    b.add_link("world")
    b.add_link("sx")
    b.add_link("sy")
    b.add_link("ball", mass=1.5)
    b.add_joint("x", "prismatic", "world", "sx", axis=(1, 0, 0))
    b.add_joint("y", "prismatic", "sx", "sy", axis=(0, 1, 0))
    b.add_joint("z", "prismatic", "sy", "ball", axis=(0, 0, 1))
    model = b.build()
    ts = rd.task_space_dynamics(model, [0.1, 0.2, 0.3], [1.0, -2.0, 0.5], "ball", rows="linear")
    assert_rel(ts.Lambda, 1.5 * np.eye(3), 1e-12)
    assert_rel(ts.mu, np.zeros(3), 1e-12)
    assert_rel(ts.p, [0.0, 0.0, 1.5 * G], 1e-12)
    assert_rel(ts.Jbar, np.eye(3), 1e-12)


@pytest.mark.parametrize("path, floating_base", pairs())
def test_urdf_against_pinocchio(path, floating_base):
    """Lambda, Jbar, mu and p of the last joint's frame from Pinocchio's computeMinverse,
    getJointJacobian, getJointJacobianTimeVariation, nonLinearEffects and gravity."""
    pair = load_pair(path, floating_base)
    model, pm, data = pair.model, pair.pm, pair.data
    q, v, _ = states(model, "urdf-task")
    qp, body = pair.pin_q(q), model.nbodies - 1
    Minv = pin.computeMinverse(pm, data, qp)
    Minv = np.triu(Minv) + np.triu(Minv, 1).T
    pin.computeJointJacobians(pm, data, qp)
    pin.computeJointJacobiansTimeVariation(pm, data, qp, v)
    g = pin.computeGeneralizedGravity(pm, data, qp)
    Cv = pin.nonLinearEffects(pm, data, qp, v) - g
    for frame, rf in JACOBIAN_FRAMES.items():
        J = pin.getJointJacobian(pm, data, pm.njoints - 1, rf)
        rows = "all" if np.linalg.matrix_rank(J) == 6 else "linear"
        J = J[ROWS[rows]]
        if np.linalg.matrix_rank(J) < J.shape[0]:  # a short chain (the double pendulum)
            with pytest.raises(ValueError, match="is singular"):
                rd.task_space_dynamics(model, q, v, body, frame, rows)
            continue
        dJv = (pin.getJointJacobianTimeVariation(pm, data, pm.njoints - 1, rf) @ v)[ROWS[rows]]
        Lam = np.linalg.inv(J @ Minv @ J.T)
        Jbar = Minv @ J.T @ Lam
        ts = rd.task_space_dynamics(model, q, v, body, frame, rows)
        assert_rel(ts.Lambda, Lam, 1e-8, f"Lambda {frame}")
        assert_rel(ts.Jbar, Jbar, 1e-8, f"Jbar {frame}")
        assert_rel(ts.mu, Jbar.T @ Cv - Lam @ dJv, 1e-8, f"mu {frame}")
        assert_rel(ts.p, Jbar.T @ g, 1e-8, f"p {frame}")


def test_short_chain_is_refused():
    """Two joints cannot move a point in three directions: no task-space inertia."""
    pair = load_pair("double_pendulum_description/urdf/double_pendulum_continuous.urdf", False)
    with pytest.raises(ValueError, match=r"task_space_inertia: J M\^-1 J\^T of 1 \(linear rows"):
        rd.task_space_inertia(pair.model, np.zeros(pair.model.nq), 1, rows="linear")


def test_batch_matches_single_states():
    model = rd.random.random_model(8, seed=5, floating_base=True)
    q, v, _ = rd.random.random_state(model, rng_for("task-batch"), (2, 3))
    ts = rd.task_space_dynamics(model, q, v, "body8")
    assert ts.Lambda.shape == (2, 3, 6, 6) and ts.Jbar.shape == (2, 3, model.nv, 6) and ts.mu.shape == (2, 3, 6)
    assert rd.task_space_inertia(model, q, "body8").shape == (2, 3, 6, 6)
    assert rd.dynamically_consistent_inverse(model, q, "body8", rows="angular").shape == (2, 3, model.nv, 3)
    for i in np.ndindex(2, 3):
        one = rd.task_space_dynamics(model, q[i], v[i], "body8")
        for a, b in zip(one, ts):
            assert_rel(b[i], a, 1e-12)


def test_singular_configurations():
    arm = planar_2r(**PLANAR_2R)
    with pytest.raises(ValueError, match=r"task_space_inertia: J M\^-1 J\^T of 'rod2' \(all rows, frame "
                                         r"'local_world_aligned'\) is singular: eigenvalues .*kinematic singularity"):
        rd.task_space_inertia(arm, np.array([0.3, 0.4]), "rod2")
    # a 6-dof chain at a wrist singularity (two wrist axes aligned)
    b = rd.ModelBuilder("chain6")
    b.add_link("l0")
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0)]
    for i, ax in enumerate(axes, start=1):
        b.add_link(f"l{i}", mass=1.0, com=(0.1, 0, 0), inertia=np.eye(3) * 0.01)
        b.add_joint(f"j{i}", "revolute", f"l{i - 1}", f"l{i}", xyz=(0.3 if i > 1 else 0, 0, 0), axis=ax)
    chain = b.build()
    q = np.array([0.1, 0.5, -0.7, 0.3, 0.0, 0.2])  # j4 and j6 aligned when j5 = 0
    with pytest.raises(ValueError, match=r"'l6' \(all rows.* is singular"):
        rd.task_space_dynamics(chain, q, np.zeros(6), "l6")
    with pytest.raises(ValueError, match=r"batch element \(1,\)"):
        rd.task_space_inertia(chain, np.stack([q + 0.3, q]), "l6")
    q[4] = 0.5
    assert np.all(np.isfinite(rd.task_space_inertia(chain, q, "l6")))


def test_bad_input():
    model = rd.random.random_model(8, seed=5, floating_base=True)
    q, v, _ = states(model, "task-bad")
    with pytest.raises(ValueError, match=r"frame must be one of"):
        rd.task_space_inertia(model, q, "body8", frame="base")
    with pytest.raises(ValueError,
                       match=r"rows must be one of \('all', 'linear', 'angular'\) or a list of row indices 0-5, got 'xy'"):
        rd.dynamically_consistent_inverse(model, q, "body8", rows="xy")
    with pytest.raises(ValueError, match=r"unknown link or frame 'nope'"):
        rd.task_space_inertia(model, q, "nope")
    with pytest.raises(ValueError, match=rf"q: expected shape \(\.\.\., {model.nq}\), got \(3,\)"):
        rd.task_space_inertia(model, q[:3], "body8")
    with pytest.raises(ValueError, match=r"task_space_dynamics: v contains NaN or Inf"):
        rd.task_space_dynamics(model, q, np.full(model.nv, np.nan), "body8")
    with pytest.raises(ValueError, match=r"q contains NaN or Inf"):
        rd.task_space_inertia(model, np.full(model.nq, np.nan), "body8")


def test_any_subset_of_rows():
    """rows may list row indices: the x and z of a planar arm's tip (it moves in the x-z
    plane), where rows="linear" is singular and says to choose fewer rows."""
    model = rd.models.load("planar_2r")
    q, v = np.array([0.3, 0.5]), np.array([0.4, -0.2])
    J = rd.jacobian(model, q, "frame2", "local_world_aligned")[[0, 2]]
    Minv = np.linalg.inv(rd.crba(model, q))
    Lam = np.linalg.inv(J @ Minv @ J.T)
    assert_rel(rd.task_space_inertia(model, q, "frame2", rows=[0, 2]), Lam, 1e-12)
    assert_rel(rd.task_space_inertia(model, q, "frame2", rows=np.array([0, 2])), Lam, 1e-12)
    assert_rel(rd.dynamically_consistent_inverse(model, q, "frame2", rows=(0, 2)), Minv @ J.T @ Lam, 1e-12)
    terms = rd.task_space_dynamics(model, q, v, "frame2", rows=[0, 2])
    assert_rel(terms.J, J, 1e-15)
    Jdv = rd.jacobian_dot_times_v(model, q, v, "frame2", "local_world_aligned")[[0, 2]]
    assert_rel(terms.mu, terms.Jbar.T @ (rd.nonlinear_effects(model, q, v) - rd.gravity(model, q)) - Lam @ Jdv, 1e-12)
    with pytest.raises(ValueError, match=r"\(linear rows, frame 'local_world_aligned'\) is singular.*choose fewer rows"):
        rd.task_space_inertia(model, q, "frame2", rows="linear")
    for bad in ([0, 0], [6], [], ["a"], [0.5]):
        with pytest.raises(ValueError, match="a list of distinct row indices 0-5"):
            rd.task_space_inertia(model, q, "frame2", rows=bad)
