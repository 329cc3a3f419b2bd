"""MJCF loader: every model of the mujoco, dm_control and gymnasium wheels against MuJoCo itself,
MuJoCo's rules one by one on small models, and bad or hostile input."""

from __future__ import annotations

import importlib.util
import re
import warnings
import zlib
from pathlib import Path

import mujoco
import numpy as np
import pytest

import robodyn as rd
import robodyn.io.mjcf as mjcf_module
from robodyn.interop import mujoco as mi

# ----------------------------------------------------------------------------------------
# the models shipped in the wheels, against MuJoCo
# ----------------------------------------------------------------------------------------


def _package_dir(name: str) -> Path:
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError(f"{name} is a test dependency; pip install {name}")
    return Path(next(iter(spec.submodule_search_locations)))


def _corpus() -> dict[str, Path]:
    out = {}
    for pkg in ("mujoco", "dm_control", "gymnasium"):
        root = _package_dir(pkg)
        for path in sorted(root.rglob("*.xml")):
            out[f"{pkg}/{path.relative_to(root).as_posix()}"] = path
    return out


CORPUS = _corpus()

# Files refused, with the reason: what robodyn does not read yet (inertia from meshes), or files
# that are not models.
REFUSED = {
    "dm_control/mjcf/schema.xml": "root element must be <mujoco>",
    "dm_control/mjcf/test_assets/attribute_test_schema.xml": "root element must be <mujoco>",
    "mujoco/testdata/model.xml": "inertia from a mesh geom",
    "dm_control/suite/dog.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/dog_v2/dog.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/dog_v2/scene.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/fruitfly_v2/fruitfly.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/fruitfly_v2/floor.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/build_fruitfly/fruitfly.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/build_fruitfly/floor.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/build_fruitfly/assets/drosophila.xml": "inertia from a mesh geom",
    "dm_control/locomotion/walkers/assets/build_fruitfly/assets/drosophila_fused.xml": "inertia from a mesh geom",
    "dm_control/third_party/kinova/jaco_arm.xml": "inertia from a mesh geom",
    "dm_control/third_party/kinova/jaco_hand.xml": "inertia from a mesh geom",
}

# Files robodyn loads and MuJoCo refuses: a mesh file is missing that the dynamics does not use.
MUJOCO_REFUSES = {"dm_control/mjcf/test_assets/included_with_invalid_filenames.xml": "invalid_mesh_name.stl"}

# Files MuJoCo refuses too (a missing included file, a massless moving body): robodyn refuses them.
BOTH_REFUSE = {
    "dm_control/mjcf/test_assets/test_model.xml": "missing attribute 'diaginertia'",
    "dm_control/mujoco/testing/assets/model_with_assets.xml": "cannot read MJCF file",
    "dm_control/mjcf/test_assets/model_with_invalid_filenames.xml": "cannot read MJCF file",
}


def test_corpus_is_found():
    assert len(CORPUS) > 70
    for rel in list(REFUSED) + list(BOTH_REFUSE) + ["gymnasium/envs/mujoco/assets/ant.xml",
                                                    "dm_control/suite/humanoid_CMU.xml"]:
        assert rel in CORPUS, rel


def _load_quietly(source) -> rd.Model:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_mjcf(source)


def _random_qpos(mm, rng) -> np.ndarray:
    qpos = mm.qpos0 + 0.5 * rng.normal(size=mm.nq)
    for j in np.flatnonzero(mm.jnt_type == mujoco.mjtJoint.mjJNT_FREE):
        a = mm.jnt_qposadr[j]
        qpos[a + 3:a + 7] /= np.linalg.norm(qpos[a + 3:a + 7])
    for j in np.flatnonzero(mm.jnt_type == mujoco.mjtJoint.mjJNT_BALL):
        a = mm.jnt_qposadr[j]
        qpos[a:a + 4] /= np.linalg.norm(qpos[a:a + 4])
    return qpos


def _full_mass_matrix(mm, d) -> np.ndarray:
    M = np.zeros((mm.nv, mm.nv))
    mujoco.mj_fullM(mm, d, M)
    return M


def loader_label(model: rd.Model, site: str) -> str:
    """The frame ``load_mjcf`` makes of a MuJoCo site (``site:name`` where a body has the name)."""
    return f"site:{site}" if f"site:{site}" in model.frame_names else site


def compare_with_mujoco(model: rd.Model, mm, states: int = 3, seed: int = 0, label=loader_label) -> None:
    """Mass matrix, bias forces, inverse dynamics (joint damping included) and site frames
    (``label(model, site)`` names the frame of a site) of ``model`` against MuJoCo's ``mm`` at
    random states, through the interop conversions."""
    assert (model.nq, model.nv) == (mm.nq, mm.nv)
    moving = mm.body_dofnum[mm.body_weldid] > 0  # bodies welded to the world or mocap: no dynamics
    np.testing.assert_allclose(model.total_mass, mm.body_mass[moving].sum(), rtol=1e-12)
    gravity_off = mm.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY
    np.testing.assert_allclose(model.gravity, 0 * mm.opt.gravity if gravity_off else mm.opt.gravity, rtol=0, atol=0)
    if model.nv:
        np.testing.assert_allclose(model.armature, mm.dof_armature, rtol=0, atol=0)
        np.testing.assert_allclose(model.damping, mm.dof_damping, rtol=0, atol=0)
        np.testing.assert_allclose(model.coulomb, mm.dof_frictionloss, rtol=0, atol=0)
    # not rigid-body dynamics: constraints, fluid forces, and the Euler integrator's implicit
    # damping (which mj_inverse adds as h D qacc); springs of hinges and slides are the
    # model's, those of ball and free joints and of tendons are not modelled (then MuJoCo
    # runs without any)
    mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_EULERDAMP
    ball_free = [j for j in range(mm.njnt)
                 if int(mm.jnt_type[j]) in (int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL))]
    if any(mm.jnt_stiffness[j] != 0 for j in ball_free) or np.any(mm.tendon_stiffness != 0):  # tendons: not modelled
        mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SPRING
        model = model.replace(stiffness=np.zeros(model.nv), spring_reference=np.zeros(model.nv))
    elif model.nv:
        one = [j for j in range(mm.njnt) if j not in ball_free]
        stiffness, reference = np.zeros(mm.nv), np.zeros(mm.nv)
        stiffness[mm.jnt_dofadr[one]] = mm.jnt_stiffness[one]
        reference[mm.jnt_dofadr[one]] = mm.qpos_spring[mm.jnt_qposadr[one]]
        np.testing.assert_allclose(model.stiffness, stiffness, rtol=0, atol=0)
        np.testing.assert_allclose(model.spring_reference, reference, rtol=1e-15, atol=1e-15)
    mm.opt.density = mm.opt.viscosity = 0.0
    # MuJoCo's frictionloss is a constraint. Armature on a free joint multiplies qacc in
    # MuJoCo, d/dt v (body frame) in robodyn: the same mass matrix, but biases apart by
    # armature * (omega x v); so robodyn's inverse dynamics runs without it and MuJoCo's
    # armature * qacc is added (see robodyn.interop.mujoco).
    free_dofs = np.isin(np.arange(mm.nv), [mm.jnt_dofadr[j] + k for j in range(mm.njnt)
                                           if mm.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE for k in range(6)])
    free_armature = np.where(free_dofs, model.armature, 0.0)
    viscous = model.replace(coulomb=np.zeros(model.nv), armature=model.armature - free_armature)
    d = mujoco.MjData(mm)
    rng = np.random.default_rng(seed)
    for _ in range(states):
        qpos, qvel, qacc = _random_qpos(mm, rng), rng.normal(size=mm.nv), rng.normal(size=mm.nv)
        d.qpos[:], d.qvel[:], d.qacc[:] = qpos, qvel, qacc
        mujoco.mj_inverse(mm, d)
        q = mi.qpos_to_q(model, qpos)
        np.testing.assert_array_equal(mi.q_to_qpos(model, q), qpos)
        for k in range(mm.nsite):
            name = mujoco.mj_id2name(mm, mujoco.mjtObj.mjOBJ_SITE, k)
            if name:
                pose = rd.frame_pose(model, q, label(model, name))
                np.testing.assert_allclose(pose[:3, 3], d.site_xpos[k], rtol=1e-12, atol=1e-12)
                np.testing.assert_allclose(pose[:3, :3], d.site_xmat[k].reshape(3, 3), rtol=1e-12, atol=1e-12)
        if not model.nv:
            continue
        T = np.column_stack([mi.qvel_to_v(model, q, e) for e in np.eye(model.nv)])
        M = _full_mass_matrix(mm, d)
        scale = max(1.0, np.abs(M).max())
        np.testing.assert_allclose(T.T @ rd.crba(model, q) @ T, M, rtol=1e-10, atol=1e-10 * scale)
        v, a = mi.qvel_to_v(model, q, qvel), mi.qacc_to_a(model, q, qvel, qacc)
        tau_rd = rd.rnea(viscous, q, v, a)
        tau = mi.force_to_qfrc(model, q, tau_rd) + free_armature * qacc
        expected = d.qfrc_inverse
        np.testing.assert_allclose(tau, expected, rtol=1e-10, atol=1e-10 * max(1.0, np.abs(expected).max()))
        # MuJoCo's bias: qacc = 0 is a = -omega x v on a free joint, so not T^T h(q, v)
        a0 = mi.qacc_to_a(model, q, qvel, np.zeros(mm.nv))
        bias = mi.force_to_qfrc(model, q, rd.rnea(model, q, v, a0, friction=False, armature=False))
        if not free_dofs.any():
            np.testing.assert_allclose(rd.nonlinear_effects(model, q, v), bias, rtol=1e-13, atol=1e-13 * scale)
        np.testing.assert_allclose(bias, d.qfrc_bias, rtol=1e-10, atol=1e-10 * max(1.0, np.abs(d.qfrc_bias).max()))
        np.testing.assert_allclose(mi.qfrc_to_force(model, q, mi.force_to_qfrc(model, q, tau_rd)), tau_rd,
                                   rtol=1e-12, atol=1e-12 * max(1.0, np.abs(tau_rd).max()))


@pytest.mark.parametrize("rel", sorted(CORPUS))
def test_wheel_models_load_and_match_mujoco_or_are_refused(rel):
    path = CORPUS[rel]
    if rel in REFUSED or rel in BOTH_REFUSE:
        with pytest.raises(rd.ModelError, match=re.escape(REFUSED.get(rel) or BOTH_REFUSE[rel])):
            _load_quietly(path)
        if rel in BOTH_REFUSE:
            with pytest.raises(ValueError):
                mujoco.MjModel.from_xml_path(str(path))
        return
    model = _load_quietly(path)
    if rel in MUJOCO_REFUSES:
        with pytest.raises(ValueError, match=MUJOCO_REFUSES[rel]):
            mujoco.MjModel.from_xml_path(str(path))
        return
    mm = mujoco.MjModel.from_xml_path(str(path))
    compare_with_mujoco(model, mm)
    named = [mujoco.mj_id2name(mm, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(mm.njnt)]
    assert [n for n in model.body_joint_names if n in named] == [n for n in named if n]


def test_wheel_model_counts():
    """The README states these numbers."""
    assert len(CORPUS) == 81
    assert len(CORPUS) - len(REFUSED) - len(BOTH_REFUSE) - len(MUJOCO_REFUSES) == 63
    assert sum("mesh" in r for r in REFUSED.values()) == 12


# ----------------------------------------------------------------------------------------
# MuJoCo's rules, one by one, on small models
# ----------------------------------------------------------------------------------------

def _mjcf(body: str, head: str = "", top: str = "") -> str:
    return f'<mujoco model="t">{head}<worldbody>{body}</worldbody>{top}</mujoco>'


_ARM = ('<body name="upper" pos="0.1 0.2 0.3" {orient}><joint name="shoulder" {joint}/>'
        '<geom type="capsule" size="0.05" fromto="0 0 0 0.3 0.1 0"/>'
        '<body name="lower" pos="0.3 0.1 0"><joint name="elbow" axis="0 1 0" pos="0 0 0.05"/>'
        '<geom type="box" size="0.03 0.04 0.15" pos="0 0 -0.15" euler="10 20 30"/>'
        '<site name="tip" pos="0 0.01 -0.3" zaxis="1 1 0"/></body></body>')


def check(xml: str, seed: int = 0) -> rd.Model:
    model = _load_quietly(xml)
    compare_with_mujoco(model, mujoco.MjModel.from_xml_string(xml), seed=seed)
    return model


ORIENTATIONS = ['quat="0.8 0.1 -0.3 0.5"', 'axisangle="1 2 3 40"', 'euler="30 -20 75"', 'xyaxes="1 1 0 -1 2 0.3"',
                'zaxis="0.3 -1 2"', 'zaxis="0 0 -1"', ""]


@pytest.mark.parametrize("orient", ORIENTATIONS)
def test_orientation_forms(orient):
    check(_mjcf(_ARM.format(orient=orient, joint='axis="1 0 0" pos="0.02 0 0"')))


@pytest.mark.parametrize("seq", ["xyz", "XYZ", "zyx", "ZXZ", "xYz"])
def test_euler_sequences(seq):
    check(_mjcf(_ARM.format(orient='euler="30 -20 75"', joint=""), head=f'<compiler eulerseq="{seq}"/>'))


def test_radians():
    head = '<compiler angle="radian"/>'
    model = check(_mjcf(_ARM.format(orient='axisangle="0 0 1 0.7" euler="0.1 0.2 0.3"'.split(" euler")[0],
                                    joint='range="-0.5 1.2" ref="0.3"'), head=head))
    np.testing.assert_allclose([model.lower[0], model.upper[0]], [-0.5, 1.2])


@pytest.mark.parametrize("joint", ['type="slide" axis="0 1 1" ref="0.2"', 'ref="30" pos="0.1 0 0.2" axis="1 1 1"',
                                   'range="-30 60"', 'range="-30 60" limited="false"', 'armature="0.3" damping="2"',
                                   'stiffness="40" springref="25" ref="10"',
                                   'type="slide" axis="0 0 1" stiffness="300" springref="-0.05" damping="1"'])
def test_joint_attributes(joint):
    model = check(_mjcf(_ARM.format(orient="", joint=joint)))
    if joint == 'range="-30 60"':
        np.testing.assert_allclose([model.lower[0], model.upper[0]], np.radians([-30, 60]))
    if "limited" in joint:
        assert model.lower[0] == -np.inf


def test_ref_keeps_qpos():
    """q is MuJoCo's qpos: at qpos = ref the body is where the file puts it."""
    xml = _mjcf('<body name="b" pos="0 0 1"><joint name="j" ref="90" axis="0 0 1" pos="0.1 0 0"/>'
                '<geom size="0.1"/><site name="s" pos="0.5 0 0"/></body>')
    model = check(xml)
    np.testing.assert_allclose(rd.frame_pose(model, [np.pi / 2], "s")[:3, 3], [0.5, 0, 1], atol=1e-15)


def test_several_joints_in_one_body_make_a_chain_of_massless_bodies():
    xml = _mjcf('<body name="hip" pos="0 0 1"><joint name="x" axis="1 0 0" pos="0 0 0.1"/>'
                '<joint name="y" axis="0 1 0" pos="0.05 0 0" ref="10"/><joint name="s" type="slide" axis="0 0 1"/>'
                '<geom type="cylinder" size="0.05 0.2" pos="0 0 -0.2"/><site name="foot" pos="0 0.1 -0.4"/>'
                '<body name="shin" pos="0 0 -0.4"><joint name="knee" axis="0 1 0"/><geom type="ellipsoid" '
                'size="0.05 0.06 0.2" pos="0 0 -0.2"/></body></body>')
    model = check(xml)
    assert model.link_names == ("hip:x", "hip:y", "hip", "shin")
    assert model.body_joint_names == ("x", "y", "s", "knee")
    assert model.theta[0, 0] == model.theta[1, 0] == 0


def test_ball_joints_are_spherical_joints():
    """A ball joint about an anchor, alone and in a chain with hinges, anywhere in the tree."""
    xml = _mjcf('<body name="base" pos="0 0 1"><freejoint/><geom type="box" size="0.2 0.1 0.05"/>'
                '<body name="arm" pos="0.2 0 0" euler="10 20 30"><joint name="shoulder" type="ball" pos="0.01 0.02 0" '
                'damping="0.3" armature="0.05"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>'
                '<body name="hand" pos="0.3 0 0"><joint name="grip" axis="0 1 0" pos="0 0 0.02"/>'
                '<joint name="wrist" type="ball" pos="0.01 0 0"/><geom size="0.04"/><site name="tip" pos="0.05 0 0"/>'
                '</body></body></body>')
    model = check(xml)
    assert model.nq == 7 + 4 + 1 + 4 and model.nv == 6 + 3 + 1 + 3
    assert model.link_names == ("base", "arm", "hand:grip", "hand")
    np.testing.assert_allclose(model.damping[6:9], 0.3)


def test_free_bodies_and_welded_bodies():
    xml = _mjcf('<body name="table" pos="0 0 0.5"><geom type="box" size="0.5 0.5 0.02"/>'
                '<site name="corner" pos="0.5 0.5 0"/></body>'
                '<body name="box" pos="0.1 0 1" euler="0 0 30"><freejoint name="box_free"/>'
                '<geom type="box" size="0.1 0.2 0.3" pos="0.01 0.02 0.03"/>'
                '<body name="lid" pos="0 0 0.3"><geom type="sphere" size="0.05"/></body></body>'
                '<body name="ball" pos="1 0 1"><joint type="free" damping="0.2" armature="0.01"/>'
                '<geom type="sphere" size="0.1" mass="2"/></body>')
    model = check(xml)
    assert model.nq == 14 and model.nv == 12 and model.link_names == ("box", "ball")
    assert {"table", "corner", "lid"} <= set(model.frame_names)


def test_geom_inertia_of_every_shape_mass_density_and_groups():
    geoms = ('<geom type="sphere" size="0.1" density="500"/>'
             '<geom type="capsule" size="0.05 0.2" pos="0.1 0 0" quat="1 1 0 0"/>'
             '<geom type="cylinder" size="0.04 0.1" pos="0 0.2 0" mass="0.7"/>'
             '<geom type="box" size="0.1 0.05 0.02" pos="0 0 0.3" axisangle="1 1 0 45"/>'
             '<geom type="ellipsoid" size="0.1 0.05 0.02" pos="0.2 0.1 0.1" mass="0.3"/>'
             '<geom type="box" fromto="0 0 0 0.3 0.3 0" size="0.02"/>'
             '<geom type="sphere" size="0.3" group="4" density="1"/>'
             '<geom type="sphere" size="0.3" group="2" mass="0"/>')
    xml = _mjcf(f'<body name="b"><joint axis="1 1 0"/>{geoms}</body>')
    check(xml)
    check(_mjcf(f'<body name="b"><joint axis="1 1 0"/>{geoms}</body>', head='<compiler inertiagrouprange="0 3"/>'))


@pytest.mark.parametrize("head", ['<compiler inertiafromgeom="true"/>',
                                  '<compiler boundmass="2" boundinertia="0.5"/>', '<compiler settotalmass="7"/>',
                                  '<compiler balanceinertia="true"/>'])
def test_compiler_inertia_options(head):
    xml = _mjcf('<body name="a"><joint axis="0 1 0"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.02 0.015 0.01" '
                'euler="10 0 0"/><geom type="sphere" size="0.1" pos="0 0 0.2"/>'
                '<body name="b" pos="0 0 0.5"><joint axis="1 0 0"/>'
                '<inertial pos="0 0 0.1" mass="0.5" fullinertia="0.02 0.03 0.04 0.001 -0.002 0.003"/></body>'
                '<body name="c" pos="0 0.3 0"><joint axis="0 0 1"/><geom type="capsule" size="0.02 0.1"/></body></body>',
                head=head)
    if "balance" in head:  # an inertia MuJoCo must balance: 0.1 + 0.01 < 0.2
        xml = xml.replace('diaginertia="0.02 0.015 0.01"', 'diaginertia="0.2 0.01 0.01"')
    check(xml, seed=2)


def test_physical_repair_is_balanceinertia():
    """An MJCF body violating I1 + I2 >= I3 without balanceinertia: refused, and with
    physical="repair" the model that balanceinertia="true" gives (and MuJoCo compiles)."""
    xml = _mjcf('<body name="a"><joint axis="0 1 0"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.2 0.01 0.01" '
                'euler="10 20 0"/></body>')
    with pytest.raises(rd.ModelError, match="body 'a'.*triangle inequality.*physical='repair'"):
        rd.load_mjcf(xml)
    with pytest.warns(rd.RobodynWarning, match=r"\[0.01, 0.01, 0.2\] repaired to \[0.0733333, 0.0733333, 0.0733333\]"):
        repaired = rd.load_mjcf(xml, physical="repair")
    balanced = xml.replace("<worldbody>", '<compiler balanceinertia="true"/><worldbody>', 1)
    np.testing.assert_allclose(repaired.theta, check(balanced).theta, rtol=1e-14, atol=1e-16)


def test_inertia_from_geoms_off():
    """With inertiafromgeom="false" a body with geoms only is massless: robodyn loads it,
    MuJoCo refuses a massless moving body."""
    xml = _mjcf('<body name="a"><joint/><inertial pos="0 0 0.1" mass="2" diaginertia="0.1 0.1 0.1"/>'
                '<geom size="0.5"/><body name="c" pos="0 0.3 0"><joint axis="1 0 0"/><geom size="0.1"/></body></body>',
                head='<compiler inertiafromgeom="false"/>')
    model = _load_quietly(xml)
    np.testing.assert_array_equal(model.theta[:, 0], [2.0, 0.0])
    with pytest.raises(ValueError, match="mass and inertia of moving bodies"):
        mujoco.MjModel.from_xml_string(xml)


def test_defaults_classes_childclass_and_partial_sizes():
    head = ('<default><joint damping="0.5" axis="0 1 0"/><geom type="capsule" size="0.03 0.1" density="800"/>'
            '<default class="leg"><joint range="-45 45" armature="0.02"/><geom size="0.05"/>'
            '<default class="foot"><geom type="sphere" size="0.04"/></default></default>'
            '<default class="arm"><joint axis="1 0 0" damping="0.1"/></default></default>')
    body = ('<body name="torso" childclass="leg"><joint name="a"/><geom/>'
            '<body name="shin" pos="0 0 -0.3"><joint name="b" class="arm"/><geom class="foot" pos="0 0 -0.1"/>'
            '<geom class="main" size="0.02" fromto="0 0 0 0 0 -0.2"/></body>'
            '<frame pos="0.2 0 0" euler="0 0 90" childclass="arm"><body name="hand"><joint name="c"/>'
            '<geom size="0.01 0.05"/><site name="palm" pos="0 0.05 0"/></body></frame></body>')
    model = check(_mjcf(body, head=head))
    np.testing.assert_allclose(model.damping, [0.5, 0.1, 0.1])
    np.testing.assert_allclose(model.armature, [0.02, 0.0, 0.0])  # class arm inherits from main, not leg


def test_gravity_option_and_flag():
    body = _ARM.format(orient="", joint="")
    model = check(_mjcf(body, head='<option gravity="1 -2 -3"/>'))
    np.testing.assert_array_equal(model.gravity, [1, -2, -3])
    model = check(_mjcf(body, head='<option gravity="1 -2 -3"><flag gravity="disable"/></option>'))
    np.testing.assert_array_equal(model.gravity, [0, 0, 0])


def test_include_relative_to_the_main_file(tmp_path):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "arm.xml").write_text(f'<mujoco>{_ARM.format(orient="", joint="")}</mujoco>')
    (tmp_path / "defaults.xml").write_text('<mujoco><default><joint damping="0.25"/></default></mujoco>')
    main = tmp_path / "robot.xml"
    main.write_text('<mujoco model="r"><include file="defaults.xml"/>'
                    '<worldbody><include file="parts/arm.xml"/></worldbody></mujoco>')
    model = _load_quietly(main)
    compare_with_mujoco(model, mujoco.MjModel.from_xml_path(str(main)))
    np.testing.assert_allclose(model.damping, 0.25)


def test_sites_are_frames_and_name_clashes_are_prefixed():
    xml = _mjcf('<body name="b"><joint/><geom size="0.1"/><site name="b" pos="0 0 0.2"/>'
                '<site name="s" pos="0.1 0 0"/><site pos="1 1 1"/></body>')
    model = check(xml)
    assert {"site:b", "s"} <= set(model.frame_names)


def test_ignored_elements_are_listed_in_one_warning():
    xml = _mjcf('<body name="b"><joint name="j" type="ball" stiffness="3" range="0 1"/><geom size="0.1"/>'
                '<camera name="c"/></body>',
                top='<actuator><motor joint="j"/></actuator><tendon/><equality><weld body1="b"/></equality><sensor/>'
                    '<asset/><visual/>')
    with pytest.warns(rd.RobodynWarning) as rec:
        rd.load_mjcf(xml)
    assert len(rec) == 1
    msg = str(rec[0].message)
    for tag in ("actuator", "tendon", "equality/weld", "sensor"):
        assert f"1 <{tag}>" in msg
    assert "springs of ball and free joints (stiffness) not modelled: ['j']" in msg
    assert "cone limits of ball joints (range) not modelled: ['j']" in msg  # autolimits: range given
    assert "asset" not in msg and "visual" not in msg and "camera" not in msg


def test_a_plain_model_loads_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rd.load_mjcf(_mjcf(_ARM.format(orient="", joint="")))


# ----------------------------------------------------------------------------------------
# refusals and hostile input
# ----------------------------------------------------------------------------------------

BAD = [
    (_mjcf('<body><joint type="hinge2"/><geom size="0.1"/></body>'), "unknown joint type 'hinge2'"),
    (_mjcf('<body><joint/><geom type="mesh" mesh="m"/></body>'), "inertia from a mesh geom is not supported"),
    (_mjcf('<body><joint/><geom size="0.1" shellinertia="true"/></body>'), "shell inertia is not supported"),
    (_mjcf('<body><joint/><geom type="sphere" size="0.1" fromto="0 0 0 1 0 0"/></body>'), "fromto needs a capsule"),
    (_mjcf('<body><joint/><geom size="0.1" class="nope"/></body>'), "unknown default class 'nope'"),
    (_mjcf('<body><joint range="10 -10"/><geom size="0.1"/></body>'), "must have min < max"),
    (_mjcf('<body><joint axis="0 0 0"/><geom size="0.1"/></body>'), "joint axis is zero"),
    (_mjcf('<body><joint/><geom size="0.1"/><body><freejoint/><geom size="0.1"/></body></body>'),
     "a free joint must be in a body whose parent is the world"),
    (_mjcf('<body><freejoint/><joint/><geom size="0.1"/></body>'), "a free joint must be the only joint"),
    (_mjcf('<body quat="1 0 0 0" euler="0 0 1"><joint/><geom size="0.1"/></body>'), "several orientations"),
    (_mjcf('<body pos="0 nan 0"><joint/><geom size="0.1"/></body>'), "is not finite"),
    (_mjcf('<body pos="0 0"><joint/><geom size="0.1"/></body>'), "needs 3 number(s)"),
    (_mjcf('<composite type="grid" count="2 2 1"/>'), "<composite> (line 1): <composite> (generated bodies)"),
    (_mjcf('<body><joint/><inertial pos="0 0 0" diaginertia="1 1 1"/></body>'), "missing attribute 'mass'"),
    (_mjcf("", head='<compiler coordinate="global"/>'), "only local coordinates"),
    (_mjcf("", head='<compiler eulerseq="xyw"/>'), "eulerseq='xyw'"),
    (_mjcf("", head='<include file="other.xml"/>'), "<include> in XML text: load the model from its file"),
    ('<robot name="r"/>', "root element must be <mujoco>"),
    ('<!DOCTYPE mujoco [<!ENTITY e "1">]><mujoco/>', "DTDs and entities are not allowed"),
    ("<mujoco><worldbody>", "malformed XML"),
    (_mjcf('<body><joint/><inertial pos="0 0 0" mass="0" diaginertia="1 1 1"/></body>'), "zero mass"),
]


@pytest.mark.parametrize("xml, message", BAD, ids=[m for _, m in BAD])
def test_bad_input_names_the_element(xml, message):
    with pytest.raises(rd.ModelError, match=re.escape(message)) as err:
        _load_quietly(xml)
    assert str(err.value).startswith("<string>")


def test_include_cycles_missing_files_and_limits(tmp_path, monkeypatch):
    (tmp_path / "a.xml").write_text('<mujoco><include file="b.xml"/></mujoco>')
    (tmp_path / "b.xml").write_text('<mujoco>\n<include file="a.xml"/></mujoco>')
    with pytest.raises(rd.ModelError, match=r"b\.xml: <include> \(line 2\): .*a\.xml includes itself"):
        rd.load_mjcf(tmp_path / "a.xml")
    (tmp_path / "c.xml").write_text('<mujoco><include file="missing.xml"/></mujoco>')
    with pytest.raises(rd.ModelError, match=r"missing\.xml: cannot read MJCF file \(no such file\)"):
        rd.load_mjcf(tmp_path / "c.xml")
    (tmp_path / "d.xml").write_text('<mujoco><include file="e.xml"/><include file="e.xml"/></mujoco>')
    (tmp_path / "e.xml").write_text('<mujoco><default/></mujoco>')
    monkeypatch.setattr(mjcf_module, "MAX_INCLUDES", 1)
    with pytest.raises(rd.ModelError, match="more than 1 included files"):
        rd.load_mjcf(tmp_path / "d.xml")
    (tmp_path / "f.xml").write_text('<mujoco><include file="g.xml"/></mujoco>')
    (tmp_path / "g.xml").write_text('<robot/>')
    with pytest.raises(rd.ModelError, match=r"g\.xml: root element of an included file must be <mujoco>"):
        rd.load_mjcf(tmp_path / "f.xml")


def test_file_size_limit(tmp_path, monkeypatch):
    path = tmp_path / "big.xml"
    path.write_text(_mjcf(_ARM.format(orient="", joint="")))
    monkeypatch.setattr(mjcf_module, "MAX_FILE_BYTES", 100)
    with pytest.raises(rd.ModelError, match="exceeds the limit of 100 bytes"):
        rd.load_mjcf(path)


# ----------------------------------------------------------------------------------------
# the interop conversions
# ----------------------------------------------------------------------------------------

def test_free_joint_conversions_are_inverse_and_batched():
    model = _load_quietly(_mjcf('<body name="a" pos="0 0 1"><freejoint/><geom size="0.1"/>'
                                '<body name="b"><joint axis="0 1 0"/><geom size="0.1" pos="0 0 -0.2"/></body></body>'))
    rng = np.random.default_rng(5)
    qpos = rng.normal(size=(4, 3, 8))
    qpos[..., 3:7] /= np.linalg.norm(qpos[..., 3:7], axis=-1, keepdims=True)
    q = mi.qpos_to_q(model, qpos)
    np.testing.assert_array_equal(q[..., 3:7], qpos[..., [4, 5, 6, 3]])
    np.testing.assert_array_equal(mi.q_to_qpos(model, q), qpos)
    qvel = rng.normal(size=(4, 3, 7))
    v = mi.qvel_to_v(model, q, qvel)
    np.testing.assert_allclose(mi.v_to_qvel(model, q, v), qvel, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(v[..., :3], axis=-1), np.linalg.norm(qvel[..., :3], axis=-1))
    np.testing.assert_array_equal(v[..., 3:], qvel[..., 3:])
    # kinetic energy is the same in both coordinates: power of the converted force equals MuJoCo's
    tau = rng.normal(size=(4, 3, 7))
    np.testing.assert_allclose(np.sum(mi.force_to_qfrc(model, q, tau) * qvel, -1), np.sum(tau * v, -1), rtol=1e-12)
    np.testing.assert_allclose(mi.qfrc_to_force(model, q, mi.force_to_qfrc(model, q, tau)), tau, rtol=1e-13, atol=1e-14)
    with pytest.raises(ValueError, match=r"qpos must have 8 entries on its last axis, got shape \(7,\)"):
        mi.qpos_to_q(model, np.zeros(7))


# ----------------------------------------------------------------------------------------
# mutated real models: a Model or a ModelError, never anything else
# ----------------------------------------------------------------------------------------

_NUMBER = re.compile(r'"(-?[0-9.]+(?:[eE]-?\d+)?)(?=[\s"])')


def _mutations(text: str, rng: np.random.Generator):
    """Damaged copies of ``text``: numbers made NaN, huge or garbage, attributes and elements
    deleted, truncation, deep nesting, entities and a DTD."""
    numbers = [m.start(1) for m in _NUMBER.finditer(text)]
    tags = [m.start() for m in re.finditer(r"<(body|joint|geom|inertial|default|site|frame)\b", text)]
    for _ in range(40):
        kind = rng.integers(8)
        if kind == 0 and numbers:
            k = numbers[rng.integers(len(numbers))]
            yield text[:k] + rng.choice(["nan", "1e400", "-inf", "x1", "", "--3"]) + text[k:]
        elif kind == 1:
            yield text[: rng.integers(len(text))]
        elif kind == 2 and tags:
            k = tags[rng.integers(len(tags))]
            yield text[:k] + "<frame>" * 70 + "</frame>" * 70 + text[k:]
        elif kind == 3:
            yield '<!DOCTYPE mujoco [<!ENTITY e "1">]>' + text.replace('"0 0 1"', '"&e; 0 1"', 1)
        elif kind == 4 and tags:
            k = tags[rng.integers(len(tags))]
            end = text.find(">", k)
            yield text[:k + 1] + text[k + 1:end].split(" ")[0] + text[end:]
        elif kind == 5:
            yield re.sub(r'type="hinge"|(?<=<joint )', 'type="ball" ' if rng.integers(2) else "", text, count=1)
        elif kind == 6 and numbers:
            k = numbers[rng.integers(len(numbers))]
            yield text[:k] + "-" + text[k:]
        elif kind == 7:
            yield text.replace("<geom", '<geom mass="-1"', 1)


@pytest.mark.parametrize("rel", ["gymnasium/envs/mujoco/assets/ant.xml", "gymnasium/envs/mujoco/assets/humanoid.xml",
                                 "dm_control/suite/cheetah.xml", "dm_control/suite/manipulator.xml"])
def test_mutated_models_load_or_raise_model_error(rel):
    text = CORPUS[rel].read_text()
    rng = np.random.default_rng(zlib.crc32(rel.encode()))
    outcomes = set()
    for bad in _mutations(text, rng):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", rd.RobodynWarning)
                rd.load_mjcf(bad)
            outcomes.add("model")
        except rd.ModelError:
            outcomes.add("error")
    assert "error" in outcomes


# -- the geoms the viewer draws (robodyn.viewer.mjcf_visuals) -------------------------------------
_DRAWN = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}  # mjtGeom -> VisualShape kind
# MuJoCo's geom quaternions given in a default class differ from the file's (normalised) by up to 3e-7
_CLASS_QUATERNIONS = {"dm_control/mjcf/test_assets/robot_arm.xml", "dm_control/mujoco/testing/assets/arm.xml"}


@pytest.mark.parametrize("rel", sorted(set(CORPUS) - set(REFUSED) - set(BOTH_REFUSE) - set(MUJOCO_REFUSES)))
def test_drawn_geoms_are_mujocos(rel):
    """Every geom MuJoCo shows by default (groups 0-2, not a plane) is drawn, in MuJoCo's
    order, with its world pose at a random state (a mesh: its vertices in the world), size
    and colour."""
    _assert_drawn_as_mujoco(CORPUS[rel], zlib.crc32(rel.encode()), 1e-6 if rel in _CLASS_QUATERNIONS else 1e-9)


_GREY = (0.5, 0.5, 0.5, 1.0)  # MuJoCo's geom colour when the file gives none (robodyn: rgba None)


def _mujoco_scene_colours(mm, d) -> dict:
    """``{geom id: rgba}`` of the geoms MuJoCo's own visualiser puts in a scene (default
    options: groups 0-2, transparent geoms left out, colours after the materials)."""
    scene = mujoco.MjvScene(mm, maxgeom=max(1000, 2 * mm.ngeom))
    mujoco.mjv_updateScene(mm, d, mujoco.MjvOption(), None, mujoco.MjvCamera(), mujoco.mjtCatBit.mjCAT_ALL, scene)
    return {g.objid: np.array(g.rgba, dtype=float) for g in scene.geoms[:scene.ngeom]
            if g.objtype == mujoco.mjtObj.mjOBJ_GEOM}


def _assert_drawn_as_mujoco(path, seed: int, turn: float = 1e-9):
    from scipy.spatial import cKDTree

    from robodyn.io.mjcf import read_mjcf_visuals
    from robodyn.viewer.geometry import mjcf_visuals, shape_mesh, visual_poses

    mm, model = mujoco.MjModel.from_xml_path(str(path)), _load_quietly(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        geoms, shapes = read_mjcf_visuals(path), mjcf_visuals(path, model)
    d = mujoco.MjData(mm)
    d.qpos[:] = _random_qpos(mm, np.random.default_rng(seed))
    mujoco.mj_kinematics(mm, d)
    colours = _mujoco_scene_colours(mm, d)
    expected = [i for i in colours if int(mm.geom_type[i]) in _DRAWN]
    assert [g.index for g in geoms] == expected and [s.name for s in shapes] == [g.name for g in geoms]
    assert len({g.name for g in geoms}) == len(geoms)
    poses = visual_poses(model, shapes, rd.interop.mujoco.qpos_to_q(model, d.qpos))
    for g, s, T in zip(geoms, shapes, poses):
        i, R = g.index, d.geom_xmat[g.index].reshape(3, 3)
        assert s.kind == _DRAWN[int(mm.geom_type[i])]
        np.testing.assert_allclose(_GREY if g.rgba is None else g.rgba, colours[i], rtol=1e-7, err_msg=g.name)
        if s.kind == "mesh":  # MuJoCo moves a mesh's vertices to its inertia frame, and the geom frame with them
            k = mm.geom_dataid[i]
            theirs = mm.mesh_vert[mm.mesh_vertadr[k]:mm.mesh_vertadr[k] + mm.mesh_vertnum[k]] @ R.T + d.geom_xpos[i]
            ours = shape_mesh(s).vertices @ T[:3, :3].T + T[:3, 3]
            scale = np.ptp(theirs, axis=0).max()
            assert cKDTree(ours).query(theirs)[0].max() < 1e-6 * scale, g.name
            assert cKDTree(theirs).query(ours)[0].max() < 1e-6 * scale, g.name
            continue
        size = mm.geom_size[i]
        np.testing.assert_allclose(s.size, {"sphere": size[:1], "capsule": [size[0], 2 * size[1]],
                                            "cylinder": [size[0], 2 * size[1]], "box": 2 * size,
                                            "ellipsoid": size}[s.kind], rtol=1e-12)
        np.testing.assert_allclose(T[:3, 3], d.geom_xpos[i], rtol=0, atol=1e-9 * max(1.0, np.abs(d.geom_xpos[i]).max()))
        if s.kind != "sphere":
            np.testing.assert_allclose(T[:3, :3], R, rtol=0, atol=turn)



SCENE = """<mujoco model="scene">
  <compiler meshdir="shapes" angle="radian"/>
  <asset>
    <mesh name="wedge" file="wedge.obj" scale="2 1 0.5"/>
    <mesh file="block.obj"/>
    <material name="steel" rgba="0.3 0.4 0.5 1"/>
    <hfield name="ground" nrow="2" ncol="2" size="0.1 0.1 0.05 0.01"/>
  </asset>
  <default>
    <default class="collision"><geom group="3" rgba="1 0 0 1"/></default>
    <default class="visual"><geom group="2" material="steel" contype="0" conaffinity="0"/></default>
  </default>
  <worldbody>
    <geom type="plane" size="2 2 0.1"/>
    <geom name="post" type="box" size="0.1 0.2 0.3" pos="1 0 0.3" euler="0.1 0.2 0.3" group="-1"/>
    <body name="arm" pos="0 0 1">
      <joint type="hinge" axis="0 1 0"/>
      <inertial pos="0.25 0 0" mass="1" diaginertia="0.01 0.02 0.025"/>
      <geom class="collision" type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
      <geom class="visual" type="mesh" mesh="wedge" pos="0.2 0 0" quat="0.9 0.1 0.3 0.2"/>
      <geom type="ellipsoid" size="0.1 0.2 0.3"/>
      <geom type="hfield" hfield="ground"/>
      <frame pos="0.5 0 0" euler="0 0.5 0">
        <geom name="tip" type="box" fromto="0 0 0 0 0 0.2" size="0.03" rgba="0 1 0 1"/>
        <geom type="mesh" mesh="block"/>
      </frame>
      <body name="hand" pos="0.5 0 0">
        <joint type="slide" axis="1 0 0"/>
        <geom type="cylinder" size="0.04 0.1" zaxis="1 1 0" mass="0.2"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

WEDGE = "v 0 0 0\nv 0.3 0 0\nv 0 0.2 0\nv 0.05 0.05 0.4\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"


ORDERED = """<mujoco>
  <compiler meshdir="a"/>
  <compiler assetdir="b" strippath="true"/>
  <asset>
    <mesh name="wedge" file="some/where/wedge.obj"/>
    <material name="plain"/>
    <material name="red" rgba="1 0 0 1"/>
  </asset>
  <worldbody>
    <geom name="arm_0" size="0.1" pos="2 0 0"/>
    <body name="arm">
      <joint type="hinge"/>
      <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      <geom type="mesh" mesh="wedge" material="red"/>
      <geom name="arm_2" size="0.1" material="plain"/>
      <geom size="0.1" material="red" rgba="0 0 1 1"/>
      <geom size="0.1" material="red" rgba="0.5 0.5 0.5 1"/>
      <geom size="0.1" rgba="0 1 0 0"/>
      <geom type="box" mesh="wedge"/>
      <geom size="0.1"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_drawn_geoms_follow_mujocos_compiler_order_colours_and_names(tmp_path):
    """The last ``<compiler>`` directory wins (``assetdir`` after ``meshdir``) and
    ``strippath`` drops the file's folders; colours as MuJoCo's own scene (a material's unless
    the geom's rgba is not the default; a material without rgba white; a transparent geom not
    drawn); a primitive fitted to a mesh left out with a warning; generated names never take
    a name the file uses."""
    from robodyn.io.mjcf import read_mjcf_visuals

    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
    (tmp_path / "b" / "wedge.obj").write_text(WEDGE)
    path = tmp_path / "ordered.xml"
    path.write_text(ORDERED)
    with pytest.warns(rd.RobodynWarning, match=r"geoms not drawn: .*line 19\): a box fitted to mesh 'wedge'"):
        geoms = read_mjcf_visuals(path)
    assert geoms[1].filename == str(tmp_path / "b" / "wedge.obj")
    assert [g.name for g in geoms] == ["arm_0", "arm_0_1", "arm_2", "arm_2_1", "arm_3", "arm_4"]
    mm = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(mm)
    mujoco.mj_kinematics(mm, d)
    colours = _mujoco_scene_colours(mm, d)
    fitted = 6
    assert [g.index for g in geoms] == [i for i in colours if i != fitted]
    for g in geoms:
        np.testing.assert_allclose(_GREY if g.rgba is None else g.rgba, colours[g.index], err_msg=g.name)
    assert [tuple(g.rgba) for g in geoms[1:5]] == [(1, 0, 0, 1), (1, 1, 1, 1), (0, 0, 1, 1), (1, 0, 0, 1)]


def test_drawn_geoms_of_a_scene_with_classes_frames_and_scaled_meshes(tmp_path):
    """Groups from default classes (the collision class hidden), a material's colour, a mesh
    scaled and found in ``meshdir`` (and one named after its file), a ``fromto`` box in a
    ``<frame>``, world geoms: as MuJoCo places them; the plane left out silently, the height
    field with a warning."""
    from robodyn.io.mjcf import read_mjcf_visuals

    (tmp_path / "shapes").mkdir()
    for name in ("wedge", "block"):
        (tmp_path / "shapes" / f"{name}.obj").write_text(WEDGE)
    path = tmp_path / "scene.xml"
    path.write_text(SCENE)
    with pytest.warns(rd.RobodynWarning, match=r"geoms not drawn: .*<geom> \(line 22\): type 'hfield'") as caught:
        geoms = read_mjcf_visuals(path)
    assert len(caught) == 1 and "plane" not in str(caught[0].message)
    assert [(g.link, g.name, g.kind) for g in geoms] == [
        ("world", "post", "box"), ("arm", "arm_0", "mesh"), ("arm", "arm_1", "ellipsoid"), ("arm", "tip", "box"),
        ("arm", "arm_3", "mesh"), ("hand", "hand_0", "cylinder")]
    np.testing.assert_array_equal(geoms[1].rgba, [0.3, 0.4, 0.5, 1])
    np.testing.assert_array_equal(geoms[1].scale, [2, 1, 0.5])
    np.testing.assert_array_equal(geoms[4].scale, [1, 1, 1])
    assert geoms[1].filename == str(tmp_path / "shapes" / "wedge.obj")
    _assert_drawn_as_mujoco(path, 7)
    path.write_text(SCENE.replace('scale="2 1 0.5"', 'scale="2 x 0.5"'))  # drawing is forgiving: the rest is drawn
    with pytest.warns(rd.RobodynWarning, match=r"scale='2 x 0.5' is not a list of numbers; .*mesh 'wedge' is not "):
        assert [g.name for g in read_mjcf_visuals(path)] == ["post", "arm_0", "tip", "arm_2", "hand_0"]
