"""Mimic couplings through the other tools' models: MuJoCo's joint equalities and Pinocchio's
mimic joints, both ways.

* MJCF: ``rd.load_mjcf`` reads a linear ``<equality><joint>`` as a mimic coupling (with the
  joints' ``ref``, in degrees and radians, and default classes): MuJoCo's own equality residual
  (``efc_pos``) is zero on every configuration of the coupled model and equals the coupling's
  violation elsewhere; MuJoCo's mass matrix is the full tree's. What it cannot hold (inactive,
  polynomial, locking equalities; the other kinds) is listed in the loader's warning, bad
  references are errors naming the element. ``rd.write_mjcf`` writes the couplings as joint
  equalities that MuJoCo compiles to the same residuals and ``load_mjcf`` reads back.
* Pinocchio: ``from_pinocchio`` of ``buildModelFromUrdf(..., mimic=True)`` is the coupled model
  ``rd.load_urdf`` reads from the file (couplings, rnea, crba); ``to_pinocchio`` of a coupled
  model gives Pinocchio mimic joints with the same rnea and crba (and aba the solve of those) (example-robot-data
  files, random chains of revolute, prismatic and helical joints, fixed and floating);
  Pinocchio's order rule and what its mimic joints cannot hold are reported.
"""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pinocchio as pin
import pytest

import robodyn as rd
from helpers import assert_rel, rng_for, states
from robodyn import joints as J
from robodyn.coupling import expand_q
from robodyn.interop import configuration_from_pinocchio, from_pinocchio, to_pinocchio
from robodyn.interop.mujoco import q_to_qpos
from robodyn.random import random_model
from test_mimic import PINOCCHIO_MIMIC, _path

TOL = 1e-9


def quietly(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return fn(*args, **kw)


def equality_residuals(model, xml, q_full) -> np.ndarray:
    """MuJoCo's residuals of the equality constraints of ``xml`` at the full tree's ``q_full``
    (``efc_pos`` of their rows); MuJoCo's joints are in depth-first order: mapped by name."""
    mm = mujoco.MjModel.from_xml_string(xml)
    tree = quietly(rd.load_mjcf, xml, mimic="independent")  # MuJoCo's order
    q = np.zeros(tree.nq)
    for i, name in enumerate(tree.body_joint_names):
        k = model.full.body_joint_names.index(name)
        n = J.NQ[tree.joint_type[i]]
        q[tree.idx_q[i]:tree.idx_q[i] + n] = q_full[model.full.idx_q[k]:model.full.idx_q[k] + n]
    d = mujoco.MjData(mm)
    d.qpos[:] = q_to_qpos(tree, q)
    mujoco.mj_forward(mm, d)
    rows = d.efc_type[:d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    return d.efc_pos[:d.nefc][rows]


def check_equalities(model: rd.CoupledModel, xml: str, key) -> None:
    """MuJoCo's residuals vanish on the coupled model's configurations and are the couplings'
    violations (q_mimic - r q_source - o, in the model's order) off them."""
    rng = rng_for("equalities", key)
    assert mujoco.MjModel.from_xml_string(xml).neq == len(model.mimic)
    body = {name: i for i, name in enumerate(model.full.body_joint_names)}
    for _ in range(3):
        q = rd.random.random_configuration(model, rng)
        qf = expand_q(model, q)
        np.testing.assert_allclose(equality_residuals(model, xml, qf), 0.0, atol=1e-12)
        qf = qf + rng.uniform(-0.1, 0.1, qf.shape) * np.isin(np.arange(qf.size), model.full.idx_q[
            [body[j] for j, *_ in model.mimic]])
        violation = [qf[model.full.idx_q[body[j]]] - r * qf[model.full.idx_q[body[s]]] - o for j, s, r, o in model.mimic]
        np.testing.assert_allclose(equality_residuals(model, xml, qf), violation, atol=1e-12)


def without_equalities(mm):
    mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_EQUALITY
    return mm


# -- MJCF ---------------------------------------------------------------------------------
GRIPPER = """<mujoco model="gripper">
  <compiler angle="{angle}"/>
  <default><equality solref="0.01 1"/><default class="loose"><equality active="false"/></default></default>
  <worldbody>
    <body name="palm"><joint name="wrist" axis="0 0 1" ref="{ref}"/><geom size="0.05"/>
      <body name="left" pos="0 0.05 0"><joint name="left" type="slide" axis="0 1 0" ref="0.01"/>
        <geom type="box" size="0.01 0.01 0.03"/></body>
      <body name="right" pos="0 -0.05 0"><joint name="right" type="slide" axis="0 -1 0"/>
        <geom type="box" size="0.01 0.01 0.03"/></body>
      <body name="flap" pos="0.1 0 0"><joint name="flap" axis="0 1 0" ref="{ref}"/>
        <geom type="capsule" size="0.01" fromto="0 0 0 0.1 0 0"/>
        <body name="tip" pos="0.1 0 0"><joint name="tip" axis="0 1 0"/><geom size="0.02"/></body>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint joint1="right" joint2="left" polycoef="0.002 -1.5 0 0 0"/>
    <joint joint1="tip" joint2="flap" polycoef="0.1 2 0 0 0"/>
    {extra}
  </equality>
</mujoco>"""


@pytest.mark.parametrize("angle, ref", [("radian", "0.3"), ("degree", "20")])
def test_mjcf_joint_equalities_are_mimic_couplings(angle, ref):
    xml = GRIPPER.format(angle=angle, ref=ref, extra="")
    model = rd.load_mjcf(xml)
    assert isinstance(model, rd.CoupledModel)
    assert model.joint_names == ("wrist", "left", "flap")
    y0 = float(ref) * (np.pi / 180 if angle == "degree" else 1.0)
    # q_y = a1 q_x + (y0 + a0 - a1 x0): right has no ref, left's is 0.01; tip none, flap y0
    assert model.mimic == (("right", "left", -1.5, 0.002 + 1.5 * 0.01), ("tip", "flap", 2.0, pytest.approx(0.1 - 2 * y0)))
    check_equalities(model, xml, angle)
    from test_mjcf import compare_with_mujoco

    compare_with_mujoco(model.full, without_equalities(mujoco.MjModel.from_xml_string(xml)))  # MuJoCo's tree


def test_mjcf_equalities_loaded_as_independent_joints_on_request():
    xml = GRIPPER.format(angle="radian", ref="0", extra="")
    with pytest.warns(rd.RobodynWarning, match=r"joint equalities loaded as independent joints.*\['right', 'tip'\]"):
        model = rd.load_mjcf(xml, mimic="independent")
    assert isinstance(model, rd.Model) and model.nv == 5
    with pytest.raises(ValueError, match="mimic must be 'couple' or 'independent'"):
        rd.load_mjcf(xml, mimic="yes")


def test_mjcf_equalities_that_are_not_couplings_are_listed():
    extra = ('<joint joint1="wrist" joint2="left" class="loose"/><joint joint1="flap" joint2="wrist" active="false"/>'
             '<joint joint1="wrist" polycoef="0.1 0 0 0 0" active="false"/>'
             '<joint joint1="flap" joint2="wrist" polycoef="0 1 0.5 0 0"/><joint joint1="wrist"/>'
             '<weld body1="tip"/><connect body1="tip" anchor="0 0 0"/>')
    with pytest.warns(rd.RobodynWarning) as rec:
        model = rd.load_mjcf(GRIPPER.format(angle="radian", ref="0", extra=extra))
    assert len(rec) == 1
    msg = str(rec[0].message)
    for listed in ("3 <equality/joint (inactive)>", "1 <equality/joint (polynomial)>",
                   "1 <equality/joint (a locked joint)>", "1 <equality/weld>", "1 <equality/connect>"):
        assert listed in msg, listed
    assert [m[0] for m in model.mimic] == ["right", "tip"]


@pytest.mark.parametrize("equality, message", [
    ('<joint joint1="nope" joint2="left"/>', r"<joint> \(line \d+\): joint1='nope' is not a named hinge or slide"),
    ('<joint joint1="left" joint2="ball"/>', r"joint2='ball' is not a named hinge or slide joint"),
    ('<joint joint2="left"/>', "missing attribute 'joint1'"),
    ('<joint joint1="right" joint2="left" polycoef="0 1"/>', r"polycoef='0 1' needs 5 number"),
    ('<joint joint1="right" joint2="left" class="nope"/>', "unknown default class 'nope'"),
    ('<joint joint1="left" joint2="left"/>', "joint 'left' mimics itself"),
    ('<joint joint1="right" joint2="left"/><joint joint1="left" joint2="right"/>', "mimic joints form a cycle"),
])
def test_mjcf_bad_equalities(equality, message):
    xml = ('<mujoco><worldbody><body name="b"><joint name="ball" type="ball"/><geom size="0.1"/>'
           '<body name="l"><joint name="left" type="slide"/><geom size="0.1"/></body>'
           '<body name="r"><joint name="right" type="slide"/><geom size="0.1"/></body></body></worldbody>'
           f'<equality>{equality}</equality></mujoco>')
    with pytest.raises(rd.ModelError, match=message):
        rd.load_mjcf(xml)


def mjcf_coupled_model(seed: int, floating_base: bool) -> rd.CoupledModel:
    """A random tree of revolute, prismatic and ball joints with friction, armature, springs
    and limits on its 1-dof joints and three mimic joints (one a chain) following them, its
    bodies in MuJoCo's order (so that a written file comes back in the same order)."""
    full = random_model(9, seed=seed, floating_base=floating_base, branching=0.4,
                        joint_types=(J.REVOLUTE, J.PRISMATIC, J.SPHERICAL))
    rng = rng_for("mjcf-coupled", seed)
    one = np.concatenate([np.full(J.NV[t], t in (J.REVOLUTE, J.PRISMATIC)) for t in full.joint_type])
    per_joint = np.concatenate([np.full(J.NV[t], rng.uniform(0.1, 1.0)) for t in full.joint_type]) * one
    full = full.replace(damping=per_joint, armature=0.1 * per_joint, coulomb=0.5 * per_joint, lower=np.where(one, -2.0, -np.inf),
                        upper=np.where(one, 2.0, np.inf), stiffness=20 * per_joint, spring_reference=0.3 * one)
    full = quietly(rd.load_mjcf, quietly(rd.write_mjcf, full))  # in MuJoCo's (depth-first) order
    names = [n for n, t in zip(full.body_joint_names, full.joint_type) if t in (J.REVOLUTE, J.PRISMATIC)]
    assert len(names) >= 4
    return rd.CoupledModel(full, [(names[-1], names[0], -1.5, 0.2), (names[-2], names[-1], 0.5, -0.1),
                                  (names[2], names[1], 1.0, 0.0)])


@pytest.mark.parametrize("seed, floating_base", [(3, False), (5, True)])
def test_write_mjcf_of_a_coupled_model(seed, floating_base, tmp_path):
    model = mjcf_coupled_model(seed, floating_base)
    path = tmp_path / "coupled.xml"
    text = quietly(rd.write_mjcf, model, path)
    assert text.count("<joint joint1=") == 3 and path.read_text() == text
    check_equalities(model, text, seed)
    back = quietly(rd.load_mjcf, text)
    assert isinstance(back, rd.CoupledModel) and back.mimic == model.mimic
    assert back.joint_names == model.joint_names
    q, v, a = states(model, "write-mjcf", size=2)
    assert_rel(rd.rnea(back, q, v, a), rd.rnea(model, q, v, a), 1e-11)
    assert_rel(rd.crba(back, q), rd.crba(model, q), 1e-11)


def test_write_mjcf_refuses_a_coupling_mjcf_cannot_hold():
    full = random_model(4, seed=1, floating_base=False, branching=0.0, joint_types=(J.REVOLUTE,))
    names = full.body_joint_names
    screw = full.replace(joint_type=np.array([J.REVOLUTE, J.REVOLUTE, J.REVOLUTE, J.HELICAL]),
                         joint_pitch=np.array([0, 0, 0, 0.1]))
    with pytest.raises(ValueError, match=rf"mimic couplings of \['{names[3]}'\] involve a joint that is not a hinge"):
        rd.write_mjcf(rd.CoupledModel(screw, [(names[3], names[0], 1.0, 0.0)]))


def test_command_line_on_an_mjcf_with_joint_equalities(tmp_path, capsys):
    from robodyn.cli import main

    path = tmp_path / "gripper.xml"
    path.write_text(GRIPPER.format(angle="radian", ref="0", extra=""))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "CoupledModel" in out and "right = -1.5 left" in out
    with pytest.warns(rd.RobodynWarning, match="joint equalities loaded as independent joints"):
        assert main(["info", str(path), "--mimic", "independent"]) == 0
    assert "nq=5, nv=5" in capsys.readouterr().out


# -- Pinocchio ------------------------------------------------------------------------------
def assert_same_dynamics(model, pm, key) -> None:
    """rnea, crba of robodyn and Pinocchio at seeded states, and aba against Pinocchio's
    ``M^-1 (tau - h)``; Pinocchio's q from robodyn's by joint name (continuous joints are
    (cos, sin) in Pinocchio)."""
    rng = rng_for("pinocchio-mimic", key)
    data = pm.createData()
    for _ in range(3):
        q = rd.random.random_configuration(model, rng)
        v, a, tau = rng.standard_normal((3, model.nv))
        qp = pin.neutral(pm)
        pin_q = {pm.names[j]: pm.joints[j] for j in range(1, pm.njoints) if pm.joints[j].nq}
        for name, jm in pin_q.items():  # the independent joints, in both orders
            i = model.full.body_joint_names.index(name)
            k = model.independent_q.tolist().index(model.full.idx_q[i])
            x = q[k:k + J.NQ[model.full.joint_type[i]]]
            qp[jm.idx_q:jm.idx_q + jm.nq] = [np.cos(x[0]), np.sin(x[0])] if jm.nq == 2 and jm.nv == 1 else x
        assert_rel(rd.rnea(model, q, v, a, friction=False), pin.rnea(pm, data, qp, v, a), TOL, "rnea")
        M = pin.crba(pm, pm.createData(), qp)  # (4.1, mimic joints: a reused Data keeps stale entries)
        M = np.triu(M) + np.triu(M, 1).T
        assert_rel(rd.crba(model, q), M, TOL, "crba")
        # Pinocchio's aba does not take mimic joints: its M and h
        h = pin.rnea(pm, data, qp, v, np.zeros(model.nv))
        assert_rel(rd.aba(model, q, v, tau, friction=False), np.linalg.solve(M, tau - h), TOL, "aba")
        np.testing.assert_allclose(configuration_from_pinocchio(pm, qp), q, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("rel", PINOCCHIO_MIMIC)
def test_from_pinocchio_mimic_joints_are_the_files_couplings(rel):
    path = _path(rel)
    pm = pin.buildModelFromUrdf(str(path), mimic=True)
    model = quietly(from_pinocchio, pm)
    expected = quietly(rd.load_urdf, path)
    assert isinstance(model, rd.CoupledModel)
    assert sorted(model.mimic) == sorted(expected.mimic) and model.joint_names == expected.joint_names
    assert (model.nq, model.nv) == (expected.nq, expected.nv)
    assert_same_dynamics(model, pm, rel)
    assert_same_dynamics(model, quietly(to_pinocchio, model), rel + "back")


def test_to_pinocchio_of_a_floating_coupled_file():
    path = _path(PINOCCHIO_MIMIC[0])
    model = quietly(rd.load_urdf, path, floating_base=True)
    with pytest.warns(rd.RobodynWarning, match="not converted for 'l_gripper_r_finger_joint' \\(damping 0.7\\)"):
        pm = to_pinocchio(model)
    assert (pm.nq, pm.nv) == (model.nq, model.nv)
    assert_same_dynamics(model, pm, "floating")


@pytest.mark.parametrize("seed, floating_base", [(11, False), (12, True), (13, False)])
def test_random_coupled_chains_both_ways(seed, floating_base):
    """A chain (depth-first, as Pinocchio needs) of revolute, prismatic and helical joints about
    random axes, with revolute and prismatic mimic joints following earlier joints of every
    kind (a helical mimic joint is refused: see the next test)."""
    full = random_model(8, seed=seed, floating_base=floating_base, branching=0.0,
                        joint_types=(J.REVOLUTE, J.PRISMATIC, J.HELICAL))
    names = [n for n, t in zip(full.body_joint_names, full.joint_type) if J.NV[t] == 1]
    kind = dict(zip(full.body_joint_names, full.joint_type))
    rng = rng_for("pin-chain", seed)
    mimic = [(names[k], names[k - 2], float(rng.choice([-1, 1]) * rng.uniform(0.5, 2)), float(rng.uniform(-0.5, 0.5)))
             for k in range(2, len(names)) if kind[names[k]] != J.HELICAL][-3:]
    assert len(mimic) == 3
    model = rd.CoupledModel(full, mimic)
    pm = to_pinocchio(model)
    assert (pm.nq, pm.nv) == (model.nq, model.nv)
    assert [pm.names[j] for j in pm.mimicking_joints] == [m[0] for m in mimic]
    assert_same_dynamics(model, pm, seed)
    back = from_pinocchio(pm)
    assert back.mimic == model.mimic
    np.testing.assert_array_equal(back.full.joint_type, full.joint_type)
    np.testing.assert_allclose(back.full.joint_axis, full.joint_axis, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(back.full.joint_pitch, full.joint_pitch, rtol=1e-13, atol=1e-15)
    q, v, a = states(model, "pin-chain", size=2)
    assert_rel(rd.rnea(back, q, v, a, friction=False), rd.rnea(model, q, v, a, friction=False), 1e-12)


def test_to_pinocchio_reports_what_its_mimic_joints_cannot_hold():
    full = random_model(4, seed=2, floating_base=False, branching=0.0, joint_types=(J.REVOLUTE,))
    names = full.body_joint_names
    damped = rd.CoupledModel(full.replace(damping=np.full(4, 0.5)), [(names[3], names[1], 2.0, 0.0)])
    with pytest.warns(rd.RobodynWarning, match=rf"no damping.*not converted for '{names[3]}' \(damping 0.5\)"):
        to_pinocchio(damped)
    with pytest.raises(ValueError, match=rf"mimic joint '{names[1]}' comes before its source '{names[3]}'"):
        to_pinocchio(rd.CoupledModel(full, [(names[1], names[3], 2.0, 0.0)]))
    screw = full.replace(joint_type=np.array([J.REVOLUTE, J.REVOLUTE, J.REVOLUTE, J.HELICAL]),
                         joint_pitch=np.array([0, 0, 0, 0.1]))
    with pytest.raises(ValueError, match=rf"mimic joint '{names[3]}' is helical; Pinocchio's mimic of a helical"):
        to_pinocchio(rd.CoupledModel(screw, [(names[3], names[1], 2.0, 0.0)]))
