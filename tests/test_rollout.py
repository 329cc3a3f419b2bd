"""Batched rollouts (rd.rollout): each rollout equals the single simulation from its initial
state, to the last bit with contacts (the same compiled step), with or without a compiled
controller; subsampling keeps exactly the samples it names; bad input is refused and a
failing rollout is named."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.contact import Box, Contacts, Plane
from robodyn.control import JointPD, PDGravity
from robodyn.random import random_model, random_state

from test_contact import BOX, SIZE, SOLO_FEET, STANCE, solo12


def box_states(B, seed=0):
    rng = np.random.default_rng(seed)
    q0 = np.zeros((B, 7))
    q0[:, 2] = rng.uniform(0.1, 0.3, B)
    quat = rng.standard_normal((B, 4))
    q0[:, 3:] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    return q0, rng.standard_normal((B, 6))


BOX_CONTACTS = Contacts([Box("body", SIZE)], surfaces=[Plane(normal=(0.1, 0.0, 1.0), friction=0.4, restitution=0.3)])


def test_each_rollout_is_the_simulation_from_its_state():
    q0, v0 = box_states(5)
    R = rd.rollout(BOX, q0, v0, 0.4, 1e-3, contacts=BOX_CONTACTS)
    assert R.q.shape == (5, 401, 7) and R.contact_force.shape == (5, 401, 8, 3) and R.t[-1] == pytest.approx(0.4)
    assert R.contact_names == BOX_CONTACTS.pack(BOX)[3]
    for b in range(5):
        traj = rd.simulate(BOX, q0[b], v0[b], 0.4, 1e-3, contacts=BOX_CONTACTS)
        for key in ("q", "v", "a", "tau", "contact_force", "contact_distance", "solver_residual", "solver_iterations"):
            np.testing.assert_array_equal(getattr(R, key)[b], getattr(traj, key), err_msg=key)
    assert np.count_nonzero(R.contact_force[..., 2]) > 100


def test_a_contact_simulation_in_pieces_is_the_simulation_in_one(capfd):
    """With the progress bar, a simulation with contacts runs in pieces of about 1 % (the
    rollouts' worker, one piece per call): the controller's time and the solver's warm start
    carry over, to the last bit."""
    from robodyn.contact import Sphere
    from robodyn.control import ComputedTorque, quintic

    model = rd.models.load("panda")
    q0 = np.array([0.0, 0.3, 0.0, -1.8, 0.0, 2.0, 0.8])
    q1 = q0 + 0.2 * (np.arange(7) == 1)  # the hand pressed down into the table and dragged
    height = rd.frame_pose(model, q0, "link7")[2, 3] - 0.06
    hand = Contacts([Sphere("link7", 0.05)], surfaces=[Plane(height=height, friction=0.5)])  # touching at once
    law = ComputedTorque(model, quintic(q0, q1, 0.2, t0=0.05), 100.0, 20.0)
    one = rd.simulate(model, q0, np.zeros(7), 0.3, 1e-3, law, contacts=hand)
    pieces = rd.simulate(model, q0, np.zeros(7), 0.3, 1e-3, law, contacts=hand, progress=True)
    assert "100%" in capfd.readouterr().err
    for key in ("q", "v", "a", "tau", "contact_force", "solver_residual", "solver_iterations"):
        np.testing.assert_array_equal(getattr(pieces, key), getattr(one, key), err_msg=key)
    assert np.count_nonzero(one.contact_force[:, 0, 2]) > 150 and np.abs(one.contact_force[:, 0, :2]).max() > 100


def test_every_keeps_the_named_samples():
    q0, v0 = box_states(3, seed=1)
    full = rd.rollout(BOX, q0, v0, 0.3, 1e-3, contacts=BOX_CONTACTS)
    some = rd.rollout(BOX, q0, v0, 0.3, 1e-3, contacts=BOX_CONTACTS, every=50)
    np.testing.assert_array_equal(some.t, full.t[::50])
    for key in ("q", "v", "a", "tau", "contact_force", "contact_distance", "solver_residual"):
        np.testing.assert_array_equal(getattr(some, key), getattr(full, key)[:, ::50], err_msg=key)


def test_a_quadruped_under_joint_pd_from_several_heights():
    model = solo12()
    q0 = np.concatenate([[0, 0, 0.45], [0, 0, 0, 1], STANCE])
    Q0 = np.tile(q0, (3, 1))
    Q0[:, 2] += [0.0, 0.03, 0.06]
    ctrl = JointPD(model, q0, 8.0, 0.3)
    contacts = Contacts([rd.contact.Sphere(f, 0.0175) for f in SOLO_FEET])
    R = rd.rollout(model, Q0, np.zeros(model.nv), 1.0, 1e-3, ctrl, contacts=contacts, every=100)
    traj = rd.simulate(model, Q0[2], np.zeros(model.nv), 1.0, 1e-3, ctrl, contacts=contacts)
    np.testing.assert_array_equal(R.q[2], traj.q[::100])
    np.testing.assert_allclose(R.contact_force[:, -1, :, 2].sum(axis=1), model.total_mass * 9.81, rtol=1e-6)


def test_without_contacts_the_step_is_semi_implicit_euler():
    model = random_model(5, seed=4)
    rng = np.random.default_rng(4)
    q0 = np.stack([random_state(model, rng)[0] for _ in range(3)])
    ctrl = PDGravity(model, q0[0], kp=20.0, kd=3.0)
    R = rd.rollout(model, q0, np.zeros(model.nv), 0.2, 1e-3, ctrl)
    assert R.contact_force is None and R.contact_names == ()
    for b in range(3):
        traj = rd.simulate(model, q0[b], np.zeros(model.nv), 0.2, 1e-3, ctrl, "semi_implicit_euler")
        np.testing.assert_allclose(R.q[b], traj.q, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(R.tau[b], traj.tau, rtol=1e-7, atol=1e-7)


def test_each_rollout_may_carry_its_own_masses():
    """Monte Carlo over the plant's inertial parameters: each rollout equals the simulation of
    the model with its parameters; unphysical ones are refused, naming the rollout and body."""
    q0, v0 = box_states(1, seed=3)
    scale = np.array([0.5, 1.0, 2.0])
    theta = scale[:, None, None] * BOX.theta[None]
    R = rd.rollout(BOX, q0[0], v0[0], 0.3, 1e-3, contacts=BOX_CONTACTS, theta=theta)
    assert R.q.shape[0] == 3
    for b in range(3):
        traj = rd.simulate(BOX.replace(theta=theta[b]), q0[0], v0[0], 0.3, 1e-3, contacts=BOX_CONTACTS)
        np.testing.assert_array_equal(R.q[b], traj.q)
        np.testing.assert_array_equal(R.contact_force[b], traj.contact_force)
    assert not np.allclose(R.contact_force[0], R.contact_force[2])
    bad = theta.copy()
    bad[1, 0, 4] = -1.0  # Ixx < 0
    with pytest.raises(ValueError, match=r"theta: rollout 1, body 0 \('body'\)"):
        rd.rollout(BOX, q0[0], v0[0], 0.1, 1e-3, theta=bad)
    with pytest.raises(ValueError, match=r"theta: expected shape \(3, 1, 10\)"):
        rd.rollout(BOX, np.tile(q0[0], (3, 1)), v0[0], 0.1, 1e-3, theta=theta[:2])


def test_one_state_broadcasts():
    q0, v0 = box_states(4, seed=2)
    R = rd.rollout(BOX, q0[0], v0, 0.05, 1e-3, contacts=BOX_CONTACTS)
    assert R.q.shape[0] == 4
    np.testing.assert_array_equal(R.q[:, 0], np.broadcast_to(q0[0], (4, 7)))


def test_bad_input_is_refused_and_a_failing_rollout_named():
    q0, v0 = box_states(2)
    with pytest.raises(ValueError, match="controller: rollout runs compiled control laws only"):
        rd.rollout(BOX, q0, v0, 0.1, 1e-3, lambda t, q, v: np.zeros(6))
    with pytest.raises(ValueError, match="every: expected an integer >= 1 dividing the 100 steps"):
        rd.rollout(BOX, q0, v0, 0.1, 1e-3, every=3)
    with pytest.raises(ValueError, match=r"q0: expected shape \(B, 7\)"):
        rd.rollout(BOX, np.zeros((2, 6)), v0, 0.1, 1e-3)
    with pytest.raises(ValueError, match="do not broadcast"):
        rd.rollout(BOX, q0, np.zeros((3, 6)), 0.1, 1e-3)
    with pytest.raises(ValueError, match="v0: contains NaN"):
        rd.rollout(BOX, q0, np.full(6, np.nan), 0.1, 1e-3)
    bad = q0.copy()
    bad[1, 3:] *= 2.0
    with pytest.raises(ValueError, match=r"q0: quaternion q0\[1, 3:7\] has norm 2, not 1"):
        rd.rollout(BOX, bad, v0, 0.1, 1e-3)
    with pytest.raises(ValueError, match="contacts: expected a robodyn.contact.Contacts"):
        rd.rollout(BOX, q0, v0, 0.1, 1e-3, contacts=Plane())
    fast = v0.copy()
    fast[1, 3:] = 1e200  # only rollout 1 spins so fast that its gyroscopic torque overflows
    with pytest.raises(ValueError, match=r"rollout 1: simulate at t = 0: the result is not finite"):
        rd.rollout(BOX, q0, fast, 0.1, 1e-3, contacts=BOX_CONTACTS)


# -- models with mimic couplings -------------------------------------------------------------
def _coupled_law(kind, model, q0):
    """A built-in controller of ``model`` (None, JointPD, PDGravity or ComputedTorque)."""
    from robodyn.control import ComputedTorque, PointToPoint

    return {None: lambda: None, "JointPD": lambda: JointPD(model, q0[0], 5.0, 1.0),
            "PDGravity": lambda: PDGravity(model, q0[0], kp=10.0, kd=2.0),
            "ComputedTorque": lambda: ComputedTorque(model, PointToPoint(q0[0], q0[1], 0.1), kp=20.0, kd=5.0)}[kind]()


def _coupled_runs(laws_only: bool = False):
    from test_mimic import MODELS

    from robodyn.contact import Sphere

    for index in (0, 1, 3):  # fixed base; floating base; floating with a spherical joint
        model = MODELS[index]
        rng = np.random.default_rng(index)
        q0 = np.stack([rd.random.random_configuration(model, rng) for _ in range(2)])
        contacts = Contacts([Sphere(i, 0.05) for i in range(1, model.nbodies)], surfaces=[Plane(height=-0.4)])
        kinds = [None] if index == 3 else [None, "JointPD"]
        if index == 0:
            kinds += ["PDGravity", "ComputedTorque"]
        for kind in kinds:
            if kind is not None or not laws_only:
                yield pytest.param(model, q0, contacts, kind, id=f"{model.name}-{kind}")


@pytest.mark.parametrize("model,q0,contacts,kind", list(_coupled_runs()))
def test_rollouts_of_a_coupled_model_are_its_simulations(model, q0, contacts, kind):
    """A :class:`rd.CoupledModel` rolls out as ``simulate`` steps it with contacts (its full
    tree on the coupling, the compiled controller in the independent coordinates, equal to its
    Python call)."""
    law = _coupled_law(kind, model, q0)
    v0 = np.random.default_rng(5).standard_normal(model.nv)
    R = rd.rollout(model, q0, v0, 0.15, 2e-3, law, contacts=contacts)
    assert R.q.shape == (2, 76, model.nq) and R.tau.shape == (2, 76, model.nv)
    for b in range(2):
        traj = rd.simulate(model, q0[b], v0, 0.15, 2e-3, law, contacts=contacts, progress=False)
        for key in ("q", "v", "a", "tau", "contact_force", "contact_distance"):
            np.testing.assert_array_equal(getattr(R, key)[b], getattr(traj, key), err_msg=key)
    if law is not None:  # the compiled law is the controller's own call
        t = 0.06
        k = int(round(t / 2e-3))
        q, v = R.q[0, k], R.v[0, k]
        np.testing.assert_allclose(R.tau[0, k], law(t, q, v), rtol=1e-12, atol=1e-12)
    assert np.count_nonzero(R.contact_force[..., 2]) > 0, "the spheres touch the plane"
    without = rd.rollout(model, q0, v0, 0.15, 2e-3, law, every=15)
    assert without.contact_force is None and without.q.shape == (2, 6, model.nq)
    far = Contacts(contacts.shapes, surfaces=[Plane(height=-100.0)])  # the same steps, out of reach
    traj = rd.simulate(model, q0[1], v0, 0.15, 2e-3, law, contacts=far, progress=False)
    np.testing.assert_allclose(without.q[1], traj.q[::15], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("model,q0,contacts,kind", list(_coupled_runs(laws_only=True)))
def test_a_coupled_rollout_is_the_python_driven_step(model, q0, contacts, kind):
    """The compiled coupled run (law and step in one kernel) against the step driven from
    Python (``CCK.step_kernel``, the controller called from Python): the same trajectory, with
    finite effort limits that clip the command and differ between each source joint and its
    mimic (the command is clipped to the independent joint's own limit)."""
    full = model.full
    v0 = np.random.default_rng(6).standard_normal(model.nv)
    free = rd.rollout(model, q0, v0, 0.15, 2e-3, _coupled_law(kind, model, q0), contacts=contacts)
    limit = np.full(full.nv, 1e-3)  # a mimic dof's limit: never its source's
    limit[model.independent_v] = np.maximum(np.percentile(np.abs(free.tau), 70, axis=(0, 1)), 1e-2)
    limited = rd.CoupledModel(full.replace(effort_limit=limit), model.mimic)
    law = _coupled_law(kind, limited, q0)
    R = rd.rollout(limited, q0, v0, 0.15, 2e-3, law, contacts=contacts)
    for b in range(2):
        traj = rd.simulate(limited, q0[b], v0, 0.15, 2e-3, lambda t, q, v: law(t, q, v), contacts=contacts,
                           progress=False)
        for key in ("q", "v", "tau", "contact_force"):
            np.testing.assert_allclose(getattr(R, key)[b], getattr(traj, key), rtol=1e-9, atol=1e-9, err_msg=key)
    assert np.all(np.abs(R.tau) <= limited.effort_limit + 1e-15)
    clipped = np.isclose(np.abs(R.tau), limited.effort_limit, rtol=0.0, atol=1e-12)
    assert clipped.any() and not clipped.all(), "the limits clip some of the commands"


def test_a_coupled_model_rolls_out_with_its_own_masses():
    from test_mimic import MODELS

    model = MODELS[1]
    q0 = rd.random.random_configuration(model, np.random.default_rng(7))
    theta = np.stack([model.full.theta, 2.0 * model.full.theta])
    R = rd.rollout(model, q0, np.zeros(model.nv), 0.05, 1e-3, theta=theta)
    far = Contacts([rd.contact.Sphere(1, 0.05)], surfaces=[Plane(height=-100.0)])  # the steps without contacts
    for b in range(2):
        heavy = rd.CoupledModel(model.full.replace(theta=theta[b]), model.mimic)
        traj = rd.simulate(heavy, q0, np.zeros(model.nv), 0.05, 1e-3, contacts=far, progress=False)
        np.testing.assert_allclose(R.q[b], traj.q, rtol=1e-9, atol=1e-12)
    assert not np.allclose(R.q[0], R.q[1])


def test_a_massless_model_with_contacts_is_named():
    """A mass matrix that is not positive definite (massless bodies, no armature) stops a
    contact simulation or rollout with an error that says so, for a tree and a coupled model,
    compiled or driven from Python."""
    from test_mimic import MODELS

    model = MODELS[0]
    full = model.full.replace(theta=np.zeros_like(model.full.theta), armature=np.zeros(model.full.nv))
    coupled = rd.CoupledModel(full, model.mimic)
    contacts = Contacts([rd.contact.Sphere(1, 0.05)], surfaces=[Plane(height=-0.4)])
    for m, where in ((full, "mass matrix of .* is not"), (coupled, "mass matrix of .* in its independent coordinates")):
        q0 = rd.random.random_configuration(m, np.random.default_rng(1))
        for controller in (None, lambda t, q, v: np.zeros(m.nv)):
            with pytest.raises(ValueError, match=f"simulate at t = 0: the {where}.*positive definite"):
                rd.simulate(m, q0, np.zeros(m.nv), 0.01, 1e-3, controller, contacts=contacts, progress=False)
        with pytest.raises(ValueError, match=f"rollout 0: simulate at t = 0: the {where}.*positive definite"):
            rd.rollout(m, q0[None], np.zeros(m.nv), 0.01, 1e-3, contacts=contacts)


def test_the_coupled_kernels_compile_no_tree_step():
    """The coupling arguments choose the step when a kernel compiles: Numba prunes ``cmap is
    None`` for a tree, not for an array, so the coupled kernels cut the tree's step by
    ``tree_marker``'s None (``_contact_runs.run_steps``' pattern, here with two helpers that
    record being compiled)."""
    from numba import njit

    from robodyn.simulation._contact_runs import tree_marker

    @njit
    def tree_only(x):
        return x + 1.0

    @njit
    def coupled_only(x, cmap):
        return x + cmap[0]

    @njit
    def run(x, cmap):
        tree = tree_marker(cmap)
        return steps(x, cmap, tree)

    @njit
    def steps(x, cmap, tree):
        if cmap is None:
            if tree is None:
                return 0.0
            return tree_only(x)
        return coupled_only(x, cmap)

    assert run(1.0, np.array([5.0])) == 6.0
    assert (len(tree_only.signatures), len(coupled_only.signatures)) == (0, 1)  # the coupled kernel
    assert run(1.0, None) == 2.0
    assert (len(tree_only.signatures), len(coupled_only.signatures)) == (1, 1)  # and the tree's


def test_without_the_marker_numba_compiles_both_steps():
    """The control of the test above: with the test on ``cmap`` alone, the coupled call
    compiles the tree's helper too."""
    from numba import njit

    @njit
    def tree_only(x):
        return x + 1.0

    @njit
    def steps(x, cmap):
        if cmap is None:
            return tree_only(x)
        return x + cmap[0]

    assert steps(1.0, np.array([5.0])) == 6.0
    assert len(tree_only.signatures) == 1  # compiled though never run
