"""Agreement with Pinocchio on every URDF of example-robot-data, fixed and floating base.

For each robot Pinocchio loads, three random states: forward kinematics, rnea and aba (without
external wrenches and with wrenches in each of the three frames), crba, the derivatives of rnea
and aba (with and without external wrenches) and of gravity, gravity, nonlinear effects, the
Coriolis matrix, the centre of mass and both energies; the Jacobian of every body in the three
frames, and the pose and the Jacobians of every link (Pinocchio's frame of the same name,
links merged by fixed joints included). Each to a relative error (max abs difference /
max(1, max abs of Pinocchio's value)) below 1e-9.

Where aba is undefined (a body whose articulated inertia D = S^T IA S is singular), Pinocchio
decides: its ABA leaves a non-finite D^-1 there and its mass matrix is singular, and robodyn
must refuse, naming that body.

Joints are matched by name (robodyn keeps Pinocchio's order, which is asserted). Pinocchio
stores a continuous joint as ``(cos, sin)``; robodyn as one angle. Mimic joints are read as
independent joints on both sides (Pinocchio's default; test_mimic.py compares the couplings).
URDF ``<dynamics>`` friction is ignored by Pinocchio's algorithms, so robodyn runs with
``friction=False``; the armature is zero on both sides.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from conftest import erd_id, example_robot_urdfs
from helpers import F_EXT_FRAMES, assert_rel, random_state, rng_for
from test_urdf import PINOCCHIO_REFUSES

URDFS = example_robot_urdfs()
# the files both libraries load (those Pinocchio refuses are checked in test_agrees_with_pinocchio)
BOTH_LOAD = [p for p in URDFS if erd_id(p) not in PINOCCHIO_REFUSES]

TOL = 1e-9
JACOBIAN_FRAMES = {"world": pin.ReferenceFrame.WORLD, "local": pin.ReferenceFrame.LOCAL,
                   "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED}


class Pair:
    """A robodyn model and the Pinocchio model of the same URDF, with the state conversion."""

    def __init__(self, model: rd.Model, pm: pin.Model):
        self.model, self.pm, self.data = model, pm, pm.createData()
        assert model.nv == pm.nv and model.nbodies == pm.njoints - 1
        assert list(model.body_joint_names) == list(pm.names[1:])  # same joint order
        self.blocks = []  # (robodyn q slice, Pinocchio q slice, is continuous)
        for j in range(1, pm.njoints):
            i = model.body_joint_names.index(pm.names[j])
            joint = pm.joints[j]
            assert i == j - 1 and model.idx_v[i] == joint.idx_v and model.parent[i] == pm.parents[j] - 1
            nq = 1 if joint.nq == 2 else joint.nq
            self.blocks.append((slice(model.idx_q[i], model.idx_q[i] + nq),
                                slice(joint.idx_q, joint.idx_q + joint.nq), joint.nq == 2 and joint.nv == 1))
        assert np.all(pm.armature == 0) and np.all(model.armature == 0)

    def pin_q(self, q: np.ndarray) -> np.ndarray:
        qp = np.zeros(self.pm.nq)
        for rs, ps, continuous in self.blocks:
            qp[ps] = [np.cos(q[rs][0]), np.sin(q[rs][0])] if continuous else q[rs]
        return qp


@functools.lru_cache(maxsize=None)
def _pair(path, floating_base: bool):
    """The Pair, or the exception Pinocchio raised."""
    try:
        pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating_base \
            else pin.buildModelFromUrdf(str(path))
    except Exception as e:  # noqa: BLE001 - Pinocchio raises ValueError or RuntimeError
        return e
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        model = rd.load_urdf(path, floating_base=floating_base, physical="warn", mimic="independent")
    return Pair(model, pm)


def _symmetric(upper: np.ndarray) -> np.ndarray:
    return np.triu(upper) + np.triu(upper, 1).T


def _pin_forces(pm, f_ext, data=None, frame: str = "local"):
    """robodyn's wrenches [force, torque] (nb, 6) given in ``frame`` as Pinocchio's per-joint
    forces, which are in the joint frames (robodyn's body frames): a "world" wrench (world axes,
    torque about the world origin) moved by ``oMi^-1``, a "local_world_aligned" one (world
    axes, torque about the body origin) rotated by ``R^T``; ``data.oMi`` from
    ``pin.forwardKinematics`` at the state."""
    assert frame in F_EXT_FRAMES
    forces = pin.StdVec_Force()
    forces.append(pin.Force.Zero())
    for j, w in enumerate(f_ext, start=1):
        f = pin.Force(w[:3], w[3:])
        if frame == "world":
            f = data.oMi[j].actInv(f)
        elif frame == "local_world_aligned":
            f = pin.SE3(data.oMi[j].rotation, np.zeros(3)).actInv(f)
        forces.append(f)
    return forces


def _pin_singular_body(pair: Pair, qp, v, tau):
    """Pinocchio's verdict on the forward dynamics at ``qp``: the link of the last joint whose
    ``D = S^T IA S`` its ABA could not invert (a non-finite ``D^-1``; a backward pass from the
    leaves meets it first), or None. Its mass matrix must agree: singular exactly then."""
    pm, data = pair.pm, pair.data
    qdd = pin.aba(pm, data, qp, v, tau)
    bad = [j for j in range(1, pm.njoints) if not np.all(np.isfinite(data.joints[j].Dinv))]
    eig = np.linalg.eigvalsh(_symmetric(pin.crba(pm, data, qp))) if pm.nv else np.ones(1)
    assert bool(bad) == (eig[0] <= 1e-12 * eig[-1]) == (not np.all(np.isfinite(qdd))), (bad, eig[[0, -1]])
    return pair.model.link_names[bad[-1] - 1] if bad else None


def _compare(pair: Pair, q, v, a, f_ext):
    """Every algorithm at one state."""
    model, pm, data = pair.model, pair.pm, pair.data
    qp = pair.pin_q(q)
    def check(what, mine, theirs):
        assert_rel(mine, theirs, TOL, what)

    pin.forwardKinematics(pm, data, qp)
    T = rd.forward_kinematics(model, q)
    for j in range(1, pm.njoints):
        check(f"oMi[{pm.names[j]}]", T[j - 1], data.oMi[j].homogeneous)
    forces = {frame: _pin_forces(pm, f_ext, data, frame) for frame in F_EXT_FRAMES}
    check("rnea", rd.rnea(model, q, v, a, friction=False), pin.rnea(pm, data, qp, v, a))
    for frame in F_EXT_FRAMES:
        check(f"rnea f_ext {frame}", rd.rnea(model, q, v, a, f_ext, frame, friction=False),
              pin.rnea(pm, data, qp, v, a, forces[frame]))
    check("crba", rd.crba(model, q), _symmetric(pin.crba(pm, data, qp)))
    check("gravity", rd.gravity(model, q), pin.computeGeneralizedGravity(pm, data, qp))
    check("nonlinear_effects", rd.nonlinear_effects(model, q, v), pin.nonLinearEffects(pm, data, qp, v))
    check("coriolis_matrix", rd.coriolis_matrix(model, q, v), pin.computeCoriolisMatrix(pm, data, qp, v))
    check("kinetic_energy", rd.kinetic_energy(model, q, v), pin.computeKineticEnergy(pm, data, qp, v))
    check("potential_energy", rd.potential_energy(model, q), pin.computePotentialEnergy(pm, data, qp))
    if model.total_mass > 0:
        check("center_of_mass", rd.center_of_mass(model, q), pin.centerOfMass(pm, data, qp))
    else:
        with pytest.raises(ValueError, match="no mass"):
            rd.center_of_mass(model, q)
    for name, wrenches in (("", ()), (" f_ext", (forces["local"],))):
        mine = rd.rnea_derivatives(model, q, v, a, *(f_ext for _ in wrenches), friction=False)
        dq, dv, da = pin.computeRNEADerivatives(pm, data, qp, v, a, *wrenches)
        for what, x, y in (("dtau_dq", mine[0], dq), ("dtau_dv", mine[1], dv), ("dtau_da", mine[2], _symmetric(da))):
            check(what + name, x, y)
    check("gravity_derivatives", rd.gravity_derivatives(model, q),
          pin.computeGeneralizedGravityDerivatives(pm, data, qp))
    tau = rd.rnea(model, q, v, a, friction=False)
    singular = _pin_singular_body(pair, qp, v, tau)
    if singular is None:
        check("aba", rd.aba(model, q, v, tau, friction=False), pin.aba(pm, data, qp, v, tau))
        check("aba round trip", rd.aba(model, q, v, tau, friction=False), a)
        for frame in F_EXT_FRAMES:
            check(f"aba f_ext {frame}", rd.aba(model, q, v, tau, f_ext, frame, friction=False),
                  pin.aba(pm, data, qp, v, tau, forces[frame]))
        # Both sides solve with M: each carries rounding errors up to about eps cond(M) (iCub's M
        # has cond ~1e8); robodyn's own residual M dqdd_dq + dtau_dq = 0 is held to TOL.
        M = rd.crba(model, q)
        tol = max(TOL, 10 * np.finfo(float).eps * np.linalg.cond(M)) if model.nv else TOL
        for name, wrenches in (("", ()), (" f_ext", (forces["local"],))):
            wrench_args = [f_ext for _ in wrenches]
            mine = rd.aba_derivatives(model, q, v, tau, *wrench_args, friction=False)
            dq, dv, dtau = pin.computeABADerivatives(pm, data, qp, v, tau, *wrenches)
            for what, x, y in (("dqdd_dq", mine[0], dq), ("dqdd_dv", mine[1], dv),
                               ("dqdd_dtau", mine[2], _symmetric(dtau))):
                assert_rel(x, y, tol, what + name)
            qdd = rd.aba(model, q, v, tau, *wrench_args, friction=False)
            for what, x, y in zip(("dqdd_dq", "dqdd_dv"), mine, rd.rnea_derivatives(model, q, v, qdd, *wrench_args,
                                                                                  friction=False)):
                check(f"M {what} + dtau{what[4:]}{name}", M @ x, -y)
    else:
        with pytest.raises(ValueError, match=rf"body \d+ \({singular!r}, joint .*\) is singular"):
            rd.aba(model, q, v, tau, friction=False)


@pytest.mark.parametrize("floating_base", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("path", URDFS, ids=erd_id)
def test_agrees_with_pinocchio(path, floating_base):
    pair = _pair(path, floating_base)
    if isinstance(pair, Exception):  # Pinocchio refuses the file (ur3.urdf: no <link>); so does robodyn
        with pytest.raises(ValueError):
            rd.load_urdf(path)
        return
    model = pair.model
    rng = rng_for(erd_id(path), floating_base)
    for _ in range(3):
        q, v, a = random_state(model, rng)
        f_ext = rng.standard_normal((model.nbodies, 6))
        _compare(pair, q, v, a, f_ext)


@pytest.mark.parametrize("floating_base", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("path", BOTH_LOAD, ids=erd_id)
def test_every_body_and_link_agrees_with_pinocchio(path, floating_base):
    """At three states: the Jacobian of every body in the three frames against Pinocchio's
    joint Jacobians; the pose of every link, bodies and links merged by fixed joints alike,
    against Pinocchio's frame of that name, and its Jacobians against Pinocchio's frame
    Jacobians (a link fixed to the world has none: robodyn refuses, Pinocchio's is zero). The
    two libraries have the same links. (Single-state calls: a batch of three costs more in
    thread start-up than it saves.)"""
    pair = _pair(path, floating_base)
    assert not isinstance(pair, Exception), f"Pinocchio refuses {erd_id(path)}: {pair}"
    model, pm, data = pair.model, pair.pm, pair.data
    names = list(model.link_names) + list(model.frame_names)
    assert sorted(names) == sorted(f.name for f in pm.frames if f.type == pin.FrameType.BODY)
    fid = {name: pm.getFrameId(name, pin.FrameType.BODY) for name in names}
    world_fixed = {name for name in names if model.frame_index(name)[0] < 0}
    for q in random_state(model, rng_for(erd_id(path), floating_base, "every body"), (3,))[0]:
        qp = pair.pin_q(q)
        pin.computeJointJacobians(pm, data, qp)  # and the joint placements
        pin.updateFramePlacements(pm, data)
        for name in names:
            assert_rel(rd.frame_pose(model, q, name), data.oMf[fid[name]].homogeneous, TOL, f"frame_pose {name!r}")
        if not pm.nv:
            continue  # (and Pinocchio's Jacobians crash when nv = 0)
        for frame, rf in JACOBIAN_FRAMES.items():
            for b in range(model.nbodies):
                assert_rel(rd.jacobian(model, q, b, frame=frame), pin.getJointJacobian(pm, data, b + 1, rf), TOL,
                           f"jacobian of body {b} ({model.link_names[b]!r}) {frame}")
            for name in names:
                expected = pin.getFrameJacobian(pm, data, fid[name], rf)
                if name in world_fixed:
                    assert not expected.any()
                    with pytest.raises(ValueError, match="fixed to the world"):
                        rd.jacobian(model, q, name, frame=frame)
                else:
                    assert_rel(rd.jacobian(model, q, name, frame=frame), expected, TOL, f"jacobian of {name!r} {frame}")


def test_icub_neck_is_singular_at_zero():
    """iCub's neck_roll and neck_yaw axes are collinear at q = 0 and neck_2 is a point mass on
    them: M(0) is singular (Pinocchio agrees) and aba names neck_2; elsewhere it is regular."""
    path = next(p for p in URDFS if erd_id(p) == "icub_description/robots/icub.urdf")
    pair = _pair(path, False)
    model, pm = pair.model, pair.pm
    q = np.zeros(model.nq)
    M = _symmetric(pin.crba(pm, pair.data, pair.pin_q(q)))
    assert np.linalg.eigvalsh(M)[0] < 1e-15 * np.linalg.eigvalsh(M)[-1]
    with pytest.raises(ValueError, match=r"body 23 \('neck_2', joint 'neck_roll'\) is singular"):
        rd.aba(model, q, np.zeros(model.nv), np.zeros(model.nv))
