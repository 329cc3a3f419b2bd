"""Derivatives of the constrained forward dynamics (robodyn.constrained_dynamics_derivatives):
against Richardson differences of robodyn's own constrained_dynamics (q moved along the tangent
directions of integrate) for every constraint kind, with and without Baumgarte gains, friction
and armature, on the Panda, Solo12 standing on four feet and seeded random trees; against
Pinocchio's computeConstraintDynamicsDerivatives (3D contacts and 6D contacts in
LOCAL_WORLD_ALIGNED); identities of the KKT system; batches and bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
from helpers import FD_TOL, assert_rel, richardson, rng_for, states
from robodyn import joints as J
from robodyn.algorithms.constrained import constraint_jacobian
from robodyn.random import random_model

BAUMGARTE = [(0.0, 0.0), (3.0, 7.0)]
FIELDS = ("da_dq", "da_dv", "da_dtau", "dlambda_dq", "dlambda_dv", "dlambda_dtau")


def _panda():
    return rd.models.load("panda")


def _solo12():
    with warnings.catch_warnings():  # the URDF's <contact> elements, ignored
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_urdf(rd.models.example_robot_urdf("solo12"), floating_base=True)


def _off(T, point, offset):
    """The world position of ``point`` of the frame at pose ``T``, moved by ``offset`` (the
    constraint then starts violated, so that the Baumgarte position term acts)."""
    return T[:3, 3] + T[:3, :3] @ np.asarray(point) + np.asarray(offset)


def _weld_target(T, rotvec=(0.2, -0.1, 0.3), shift=(0.02, -0.01, 0.03)):
    out = T.copy()
    out[:3, :3] = T[:3, :3] @ Rotation.from_rotvec(rotvec).as_matrix()
    out[:3, 3] += shift
    return out


def _leaf(model) -> int:
    """The last body without children."""
    return max(set(range(model.nbodies)) - set(int(p) for p in model.parent))


def _differences(model, q, v, tau, constraints, baumgarte, **kw):
    """The six derivatives by Richardson differences of ``constrained_dynamics``."""
    def solve(qq, vv, tt):
        res = rd.constrained_dynamics(model, qq, vv, tt, constraints, baumgarte, **kw)
        return np.concatenate([res.a, *res.forces])

    nv = model.nv
    d_q = richardson(lambda d: solve(rd.integrate(model, q, d), v, tau), nv)
    d_v = richardson(lambda d: solve(q, v + d, tau), nv)
    d_tau = richardson(lambda d: solve(q, v, tau + d), nv)
    return d_q[:nv], d_v[:nv], d_tau[:nv], d_q[nv:], d_v[nv:], d_tau[nv:]


def check_differences(model, q, v, tau, constraints, baumgarte, tol=FD_TOL, **kw):
    got = rd.constrained_dynamics_derivatives(model, q, v, tau, constraints, baumgarte, **kw)
    m = sum(c.dim for c in constraints)
    assert [x.shape for x in got] == [(model.nv, model.nv)] * 3 + [(m, model.nv)] * 3
    for name, x, fd in zip(FIELDS, got, _differences(model, q, v, tau, constraints, baumgarte, **kw)):
        assert_rel(x, fd, tol, f"{name} ({[type(c).__name__ for c in constraints]}, baumgarte {baumgarte})")
    return got


# -- against finite differences --------------------------------------------------------------
@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_panda_point_and_weld(baumgarte):
    model = _panda()
    q, v, tau = states(model, "panda")
    hand = model.link_names[-1]
    T = rd.frame_pose(model, q, hand)
    point = (0.05, 0.02, 0.1)
    check_differences(model, q, v, tau, [rd.PointConstraint(hand, point, _off(T, point, (0.01, -0.02, 0.01)))],
                      baumgarte)
    check_differences(model, q, v, tau, [rd.WeldConstraint(hand, _weld_target(T))], baumgarte)
    # a second arm point held by a rod to a world anchor, with the point at the hand
    rod = rd.DistanceConstraint(model.link_names[3], (0.0, 0.05, 0.1), None, (0.3, 0.3, 0.8), length=0.6)
    check_differences(model, q, v, tau, [rd.PointConstraint(hand, point, _off(T, point, 0.0)), rod], baumgarte)


@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_solo12_on_four_feet(baumgarte):
    model = _solo12()
    q, v, tau = states(model, "solo12")
    feet = [rd.PointConstraint(f, np.zeros(3), _off(rd.frame_pose(model, q, f), np.zeros(3), (0.01, 0.0, -0.02)))
            for f in model.frame_names if f.endswith("_FOOT")]
    assert len(feet) == 4
    check_differences(model, q, v, tau, feet, baumgarte)


TREES = [random_model(10, seed=33, branching=0.3),  # seeds whose constraint rows are independent
         random_model(10, seed=22, floating_base=True, branching=0.3),
         random_model(9, seed=23, floating_base=True, branching=0.4,
                      joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL, J.HELICAL, J.PLANAR))]
TREE_IDS = ["fixed", "floating", "floating-mixed"]


def _depth(model, i: int) -> int:
    return 0 if i < 0 else 1 + _depth(model, int(model.parent[i]))


def _every_kind(model, q):
    """One constraint of each kind on a random tree of 10 bodies or more, in two sets of
    independent rows: a point on a leaf, a closed loop between two bodies, a rod to the world
    and a gear (8 rows); a weld of the deepest body and the gear (7 rows)."""
    names = model.link_names
    leaf = names[_leaf(model)]
    deepest = names[max(range(model.nbodies), key=lambda i: (_depth(model, i), i))]
    point = np.array([0.1, -0.2, 0.05])
    one_dof = [model.body_joint_names[i] for i in range(model.nbodies) if J.NV[model.joint_type[i]] == 1]
    gear = rd.CouplingConstraint(one_dof[-1], one_dof[-2], ratio=-1.5, offset=0.2)
    return [
        [rd.PointConstraint(leaf, point, _off(rd.frame_pose(model, q, leaf), point, (0.02, 0.0, -0.01))),
         rd.LoopConstraint(names[4], (0.1, 0.0, 0.0), names[7], (0.0, 0.2, 0.1)),
         rd.DistanceConstraint(names[3], (0.0, 0.1, 0.0), None, (0.5, 0.5, 0.5), length=1.3), gear],
        [rd.WeldConstraint(deepest, _weld_target(rd.frame_pose(model, q, deepest))), gear],
    ]


@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_random_trees_every_constraint_kind(model, baumgarte):
    q, v, tau = states(model, "every-kind")
    loops, weld = _every_kind(model, q)
    check_differences(model, q, v, tau, loops[:1], baumgarte)  # a point on a leaf body, alone
    check_differences(model, q, v, tau, loops, baumgarte)
    check_differences(model, q, v, tau, weld, baumgarte)


@pytest.mark.parametrize("model", TREES[1:2], ids=TREE_IDS[1:2])
def test_with_friction_and_armature(model):
    rng = rng_for(model.name, "friction")
    m = model.replace(damping=rng.uniform(0.1, 1.0, model.nv), coulomb=rng.uniform(0.1, 1.0, model.nv),
                      armature=rng.uniform(0.01, 0.1, model.nv), coulomb_smoothing=0.3)
    q, v, tau = states(m, "friction")
    for cons in _every_kind(m, q):
        check_differences(m, q, v, tau, cons, (1.0, 2.0))
    check_differences(m, q, v, tau, cons, (1.0, 2.0), friction=False, armature=False)


# -- identities ------------------------------------------------------------------------------
@pytest.mark.parametrize("model", TREES, ids=TREE_IDS)
def test_kkt_identities(model):
    """``da_dtau`` and ``dlambda_dtau`` are the blocks of the inverse KKT matrix: ``da_dtau =
    M^-1 - M^-1 J^T S^-1 J M^-1``, ``dlambda_dtau = -S^-1 J M^-1`` (``S = J M^-1 J^T``), so
    ``J da_dx = -dc/dx`` holds for tau (``J da_dtau = 0``); without constraints the derivatives
    are those of ``aba``."""
    q, v, tau = states(model, "identities")
    cons = _every_kind(model, q)[0]
    d = rd.constrained_dynamics_derivatives(model, q, v, tau, cons)
    Jc = constraint_jacobian(model, q, v, cons)[0][0]
    Minv = np.linalg.inv(rd.crba(model, q))
    Sinv = np.linalg.inv(Jc @ Minv @ Jc.T)
    assert_rel(d.da_dtau, Minv - Minv @ Jc.T @ Sinv @ Jc @ Minv, 1e-9, "da_dtau")
    assert_rel(d.dlambda_dtau, -Sinv @ Jc @ Minv, 1e-9, "dlambda_dtau")
    assert_rel(Jc @ d.da_dtau, np.zeros_like(Jc), 1e-9, "J da_dtau")
    free = rd.constrained_dynamics_derivatives(model, q, v, tau, [])
    for x, y in zip(free[:3], rd.aba_derivatives(model, q, v, tau)):
        assert_rel(x, y, 1e-9, "no constraints: aba_derivatives")
    assert [x.shape for x in free[3:]] == [(0, model.nv)] * 3


# -- against Pinocchio (a test dependency) -----------------------------------------------------


def _pinocchio(model, q, v, tau, contacts, baumgarte=(0.0, 0.0)):
    """Pinocchio's ``(a, lambda, derivatives)`` for ``contacts``: ``(type, body, placement of the
    contact on the body (SE3), target placement in the world (SE3))``, all in
    LOCAL_WORLD_ALIGNED, Baumgarte ``Kp = beta^2``, ``Kd = 2 alpha``."""
    pm = rd.interop.to_pinocchio(model)
    data = pm.createData()
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for kind, body, placement, target in contacts:
        cm = pin.RigidConstraintModel(kind, pm, body + 1, placement, 0, target, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        gains = cm.m_baumgarte_parameters
        gains.Kp, gains.Kd = baumgarte[1] ** 2, 2.0 * baumgarte[0]
        cm.setBaumgarteCorrectorParameters(gains)
        models.append(cm)
        datas.append(cm.createData())
    pin.initConstraintDynamics(pm, data, models, datas)
    a = pin.constraintDynamics(pm, data, q, v, tau, models, datas).copy()
    lam = data.lambda_c.copy()
    derivatives = [np.array(x, copy=True) for x in pin.computeConstraintDynamicsDerivatives(pm, data, models, datas)]
    return a, lam, derivatives


def check_pinocchio(model, q, v, tau, constraints, contacts, baumgarte):
    """Accelerations, forces (the same in both: world axes, applied to the body) and the six
    derivatives to 1e-9 relative; friction off (Pinocchio's dynamics has none)."""
    a, lam, expected = _pinocchio(model, q, v, tau, contacts, baumgarte)
    res = rd.constrained_dynamics(model, q, v, tau, constraints, baumgarte, friction=False)
    assert_rel(res.a, a, 1e-9, "a")
    assert_rel(np.concatenate(res.forces), lam, 1e-9, "lambda")
    got = rd.constrained_dynamics_derivatives(model, q, v, tau, constraints, baumgarte, friction=False)
    for name, x, y in zip(FIELDS, got, expected):
        assert_rel(x, y, 1e-9, f"{name} vs Pinocchio")


@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_panda_point_contact_agrees_with_pinocchio(baumgarte):
    """A PointConstraint is Pinocchio's CONTACT_3D in LOCAL_WORLD_ALIGNED: the same classical
    acceleration of the point, position error and force in world axes."""
    model = _panda()
    q, v, tau = states(model, "pinocchio-point")
    b = model.nbodies - 1
    point = np.array([0.05, 0.02, 0.1])
    target = _off(rd.frame_pose(model, q, model.link_names[b]), point, (0.01, -0.02, 0.01))
    check_pinocchio(model, q, v, tau, [rd.PointConstraint(b, point, target)],
                    [(pin.ContactType.CONTACT_3D, b, pin.SE3(np.eye(3), point), pin.SE3(np.eye(3), target))],
                    baumgarte)


@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_panda_weld_agrees_with_pinocchio_at_rest(baumgarte):
    """A WeldConstraint is Pinocchio's CONTACT_6D in LOCAL_WORLD_ALIGNED (force in world axes,
    torque about the frame origin) where the welded frame is at rest (``J v = 0``): Pinocchio
    constrains the spatial acceleration of the frame, robodyn the classical one of its origin,
    which differ by ``w x v_p`` (zero, with its first derivatives, at rest). The target is the
    frame's pose, where the two position errors (robodyn's ``[p - p*; log(R R*^T)]``,
    Pinocchio's ``log6``) and their derivatives coincide."""
    model = _panda()
    q, v, tau = states(model, "pinocchio-weld")
    b = model.nbodies - 1
    Jb = rd.jacobian(model, q, b)
    v = v - np.linalg.pinv(Jb) @ (Jb @ v)
    T = rd.frame_pose(model, q, model.link_names[b])
    check_pinocchio(model, q, v, tau, [rd.WeldConstraint(b, T)],
                    [(pin.ContactType.CONTACT_6D, b, pin.SE3.Identity(), pin.SE3(T[:3, :3], T[:3, 3]))], baumgarte)


@pytest.mark.parametrize("baumgarte", BAUMGARTE)
def test_solo12_on_four_feet_agrees_with_pinocchio(baumgarte):
    model = _solo12()
    q, v, tau = states(model, "pinocchio-solo12")
    constraints, contacts = [], []
    for foot in (f for f in model.frame_names if f.endswith("_FOOT")):
        b, R, p = model.frame_index(foot)
        target = _off(rd.frame_pose(model, q, foot), np.zeros(3), (0.01, 0.0, -0.02))
        constraints.append(rd.PointConstraint(foot, np.zeros(3), target))
        contacts.append((pin.ContactType.CONTACT_3D, b, pin.SE3(R, p), pin.SE3(np.eye(3), target)))
    check_pinocchio(model, q, v, tau, constraints, contacts, baumgarte)


# -- batches and bad input --------------------------------------------------------------------
def test_batch_and_broadcast():
    model = TREES[1]
    q, v, tau = rd.random.random_state(model, rng_for("batch"), (2, 3))
    cons = _every_kind(model, q[0, 0])[0]
    d = rd.constrained_dynamics_derivatives(model, q, v, tau, cons, (1.0, 2.0))
    assert [x.shape for x in d] == [(2, 3, model.nv, model.nv)] * 3 + [(2, 3, 8, model.nv)] * 3
    for i in np.ndindex(2, 3):
        one = rd.constrained_dynamics_derivatives(model, q[i], v[i], tau[i], cons, (1.0, 2.0))
        for name, x, y in zip(FIELDS, d, one):
            assert_rel(x[i], y, 1e-11, f"{name}[{i}]")
    wide = rd.constrained_dynamics_derivatives(model, q[0, 0], v[0], tau[0, 1], cons)  # q and tau broadcast
    assert wide.da_dq.shape == (3, model.nv, model.nv)
    assert_rel(wide.dlambda_dv[2], rd.constrained_dynamics_derivatives(model, q[0, 0], v[0, 2], tau[0, 1],
                                                                       cons).dlambda_dv, 1e-11)


def test_bad_input():
    model = _panda()
    q, v, tau = states(model, "bad")
    hand = model.link_names[-1]
    point = rd.PointConstraint(hand, np.zeros(3), np.zeros(3))
    call = rd.constrained_dynamics_derivatives
    with pytest.raises(ValueError, match=r"q: expected shape \(\.\.\., 7\), got \(6,\)"):
        call(model, q[:-1], v, tau, [point])
    with pytest.raises(ValueError, match=r"tau: expected shape \(\.\.\., 7\), got \(2, 3\)"):
        call(model, q, v, np.zeros((2, 3)), [point])
    with pytest.raises(ValueError, match="do not broadcast"):
        call(model, np.stack([q] * 2), np.stack([v] * 3), tau, [point])
    for name in ("q", "v", "tau"):
        args = {"q": q.copy(), "v": v.copy(), "tau": tau.copy()}
        args[name][1] = np.nan
        with pytest.raises(ValueError, match=rf"constrained_dynamics_derivatives: {name} contains NaN or Inf"):
            call(model, args["q"], args["v"], args["tau"], [point])
    with pytest.raises(ValueError, match=r"constraints\[1\]: expected one of "
                                         r"\['PointConstraint', 'WeldConstraint', .*got str"):
        call(model, q, v, tau, [point, "contact"])
    with pytest.raises(ValueError, match="constraints: expected a sequence of constraints, got int"):
        call(model, q, v, tau, 3)
    for bad in ((1.0,), (-1.0, 0.0), (np.nan, 1.0)):
        with pytest.raises(ValueError, match="baumgarte: expected"):
            call(model, q, v, tau, [point], bad)
    with pytest.raises(ValueError, match="unknown 1-dof joint 'nope'"):
        call(model, q, v, tau, [rd.CouplingConstraint("nope", model.joint_names[0])])
    # the same point held twice: 6 rows of rank 3, forces not unique
    with pytest.raises(ValueError, match=r"the constraints are redundant \(rank 3 < 6 rows\)"):
        call(model, q, v, tau, [point, point])
    assert call(model, q, v, tau, point).dlambda_dq.shape == (3, 7)  # a single constraint, not in a list
