"""URDF loader: example-robot-data against Pinocchio, bad input, and URDF semantics by hand."""

from __future__ import annotations

import functools
import pathlib
import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd
import robodyn.io.urdf as urdf_module
from robodyn import joints
from helpers import assert_rel
from conftest import assert_names_line, erd_id, example_robot_urdfs, marked_lines, rot

# ----------------------------------------------------------------------------------------
# example-robot-data, compared with Pinocchio
# ----------------------------------------------------------------------------------------

# Whether a URDF's moving bodies are rigid bodies, from its own <inertial> values (the
# reference UNPHYSICAL below is derived with).


def _numbers(element, attribute: str, default) -> np.ndarray:
    text = element.get(attribute) if element is not None else None
    return np.array([float(x) for x in text.split()] if text else default, dtype=float)


def _origin(element) -> tuple[np.ndarray, np.ndarray]:
    """``(R, p)`` of the <origin> child of ``element`` (URDF rpy: extrinsic x, y, z)."""
    origin = element.find("origin") if element is not None else None
    return (Rotation.from_euler("xyz", _numbers(origin, "rpy", [0.0, 0.0, 0.0])).as_matrix(),
            _numbers(origin, "xyz", [0.0, 0.0, 0.0]))


def _link_inertial(link) -> tuple[float, np.ndarray, np.ndarray]:
    """``(m, c, I_c)`` of a <link> in its own frame (zeros without <inertial>)."""
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    R, c = _origin(inertial)
    mass = inertial.find("mass")
    m = float(mass.get("value")) if mass is not None else 0.0
    el = inertial.find("inertia")
    g = {k: float(el.get(k, 0.0)) if el is not None else 0.0 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    Ic = np.array([[g["ixx"], g["ixy"], g["ixz"]], [g["ixy"], g["iyy"], g["iyz"]], [g["ixz"], g["iyz"], g["izz"]]])
    return m, c, R @ Ic @ R.T


# A violation counts beyond 1e-6 of the largest principal moment plus 1e-12 kg m^2 (the
# rounding of published values: iCub's point masses carry moments of 1e-35 and
# near-violations of 1e-18 kg m^2); the bodies found violate by 1e-3 or more of it.
_INERTIA_RTOL, _INERTIA_ATOL = 1e-6, 1e-12


def _is_rigid_body(m: float, h: np.ndarray, Io: np.ndarray) -> bool:
    """Mass ``m``, first moment ``h`` and inertia ``Io`` about the body origin of a rigid body?"""
    if m < 0:
        return False
    if m == 0:
        return not np.any(h) and not np.any(Io)
    c = h / m
    lam = np.linalg.eigvalsh(Io - m * (c @ c * np.eye(3) - np.outer(c, c)))
    tol = _INERTIA_RTOL * np.abs(lam).max() + _INERTIA_ATOL
    return lam[0] >= -tol and lam[0] + lam[1] >= lam[2] - tol


def unphysical_bodies(source, floating_base: bool = False) -> list[tuple[str, list[str]]]:
    """``[(body, links)]`` of the moving bodies of a URDF (file or text) that are no rigid
    body, in depth-first order (children ordered by joint name, as urdfdom orders them). A body
    is the child link of a moving joint (or the root link, on a floating base) with every link
    fixed joints attach to it, their inertials summed about the body origin (parallel-axis
    theorem). Written from the URDF specification with ElementTree, independently of robodyn."""
    text = pathlib.Path(source).read_text() if isinstance(source, pathlib.Path) else source
    root = ET.fromstring(text)
    links = {link.get("name"): _link_inertial(link) for link in root.findall("link")}
    children: dict[str, list] = {name: [] for name in links}
    has_parent = set()
    for joint in sorted(root.findall("joint"), key=lambda j: j.get("name")):
        children[joint.find("parent").get("link")].append(joint)
        has_parent.add(joint.find("child").get("link"))
    roots = [name for name in links if name not in has_parent]
    if len(roots) != 1:
        return []
    bodies: dict[str, list] = {}  # body -> [m, h, Io, links], in depth-first order
    stack = [(roots[0], roots[0] if floating_base else None, np.eye(3), np.zeros(3))]
    while stack:
        link, body, R, p = stack.pop()
        if body is not None:
            m, c, Ic = links[link]
            cb = p + R @ c
            acc = bodies.setdefault(body, [0.0, np.zeros(3), np.zeros((3, 3)), []])
            acc[0] += m
            acc[1] += m * cb
            acc[2] += R @ Ic @ R.T + m * (cb @ cb * np.eye(3) - np.outer(cb, cb))
            acc[3].append(link)
        for joint in reversed(children[link]):
            child = joint.find("child").get("link")
            Rj, pj = _origin(joint)
            if joint.get("type") == "fixed":
                stack.append((child, body, R @ Rj, p + R @ pj))
            else:
                stack.append((child, child, np.eye(3), np.zeros(3)))
    return [(b, acc[3]) for b, acc in bodies.items() if not _is_rigid_body(*acc[:3])]


# Files with placeholder links (a massless base or foot with an inertia, a sensor mount) that
# are not rigid bodies alone, but merge by fixed joints into consistent bodies: they load.
PLACEHOLDERS = {
    "alex_description/urdf/alex_psyonic_hands.urdf": "LeftPsyonicAbilityBaseLink",
    "allegro_hand_description/urdf/allegro_left_hand.urdf": "link_11.0",
    "allegro_hand_description/urdf/allegro_right_hand.urdf": "link_3.0",
    "anymal_b_simple_description/robots/anymal-kinova.urdf": "base",
    "anymal_b_simple_description/robots/anymal.urdf": "base",
    "anymal_c_simple_description/urdf/anymal.urdf": "depth_camera_front_camera",
    "b1_description/urdf/b1-z1.urdf": "base",
    "b1_description/urdf/b1.urdf": "base",
    "bolt_description/robots/bolt.urdf": "FL_FOOT",
    "go1_description/urdf/go1.urdf": "base",
    "hyq_description/robots/hyq_no_sensors.urdf": "base_link",
    "pr2_description/urdf/pr2.urdf": "sensor_mount_link",
    "tiago_description/robots/tiago.urdf": "base_antenna_left_link",
    "tiago_description/robots/tiago_dual.urdf": "base_antenna_left_link",
    "tiago_description/robots/tiago_no_hand.urdf": "base_antenna_left_link",
}

# Files Pinocchio (urdfdom) refuses, with the reason; robodyn refuses them too.
PINOCCHIO_REFUSES = {
    "ur_description/urdf/ur3.urdf": "no <link> element",  # a <robot> holding only a comment
}

ALL_URDFS = example_robot_urdfs()
PIN_URDFS = [p for p in ALL_URDFS if erd_id(p) not in PINOCCHIO_REFUSES]


@functools.lru_cache(maxsize=None)
def _unphysical(path: pathlib.Path, floating_base: bool) -> list[tuple[str, list[str]]]:
    return unphysical_bodies(path, floating_base)


# Published URDFs with a moving body no rigid body can be, even after fixed joints merge its
# links (inertia about the centre of mass not positive semi-definite, principal moments
# violating I1 + I2 >= I3, or an inertia without mass). robodyn refuses them by default, naming
# the first such body and its links with their numbers, and loads them with physical="warn".
# file -> [(body, its links)] on a fixed base, in depth-first order, by unphysical_bodies.
UNPHYSICAL = {erd_id(p): bodies for p in PIN_URDFS if (bodies := _unphysical(p, False))}


def test_example_robot_data_is_found():
    assert len(ALL_URDFS) >= 60
    known = {erd_id(p) for p in ALL_URDFS}
    assert set(PLACEHOLDERS) <= known and set(PINOCCHIO_REFUSES) <= known
    assert UNPHYSICAL and not set(UNPHYSICAL) & set(PLACEHOLDERS)  # some files to test, placeholders load


@pytest.mark.parametrize("name, body", [("triangle_inequality.urdf", "arm"), ("inertia_not_psd.urdf", "arm"),
                                        ("zero_mass_with_inertia.urdf", "arm"), ("negative_mass.urdf", "arm")])
def test_unphysical_bodies_finds_the_bad_fixtures(fixture_path, name, body):
    """The criterion behind UNPHYSICAL flags the body of each bad-inertia fixture."""
    assert unphysical_bodies(fixture_path(name)) == [(body, [body])]


def test_unphysical_bodies_merges_fixed_links():
    """Links joined by a fixed joint are judged together: two point masses make a thin rod
    (moments 0, 0.5, 0.5: I1 + I2 = I3 exactly); a massless link with an inertia is fine merged,
    not as a body of its own; a light point mass does not repair a flat inertia (0.1, 0.1, 0.5)."""
    def robot(arm, tip, tip_joint="fixed"):
        return (f'<robot name="r"><link name="base"/>{arm}{tip}'
                '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/></joint>'
                f'<joint name="f" type="{tip_joint}"><parent link="arm"/><child link="tip"/>'
                '<origin xyz="1 0 0"/></joint></robot>')

    def link(name, m, ixx=0.0, iyy=0.0, izz=0.0):
        return (f'<link name="{name}"><inertial><mass value="{m}"/>'
                f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial></link>')

    assert unphysical_bodies(robot(link("arm", 1), link("tip", 1))) == []
    massless = link("tip", 0, 1e-3, 1e-3, 1e-3)
    assert unphysical_bodies(robot(link("arm", 1, 0.1, 0.1, 0.1), massless)) == []
    assert unphysical_bodies(robot(link("arm", 1, 0.1, 0.1, 0.1), massless, "revolute")) == [("tip", ["tip"])]
    flat = robot(link("arm", 1, 0.1, 0.1, 0.5), link("tip", 1e-3))
    assert unphysical_bodies(flat) == [("arm", ["arm", "tip"])]
    assert unphysical_bodies(flat, floating_base=True) == [("arm", ["arm", "tip"])]  # the massless base is fine


@functools.lru_cache(maxsize=None)
def _pin_model(path: str, floating_base: bool) -> pin.Model:
    if floating_base:
        return pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(path)


def _load_quietly(path, **kw) -> rd.Model:
    """Load, ignoring the RobodynWarnings about <gazebo>, <transmission>, ... and unphysical
    links (their presence is asserted in the tests that are about them); mimic joints as
    independent joints, as Pinocchio's ``buildModelFromUrdf`` reads them by default."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        return rd.load_urdf(path, **{"mimic": "independent", **kw})


def _physical(path, floating_base: bool = False) -> str:
    return "warn" if _unphysical(path, floating_base) else "error"


def _theta_from_pinocchio(inertia: pin.Inertia) -> np.ndarray:
    """10 parameters about the joint frame origin (DESIGN order) from Pinocchio's mass,
    lever (centre of mass) and rotational inertia about the centre of mass."""
    m, c, Ic = inertia.mass, np.asarray(inertia.lever), np.asarray(inertia.inertia)
    Io = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))  # parallel-axis theorem
    return np.array([m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])


def _assert_close_groups(actual, expected, what):
    """Mass, first moment and rotational inertia each to 1e-9 relative to their magnitude."""
    for sl, name in ((slice(0, 1), "mass"), (slice(1, 4), "first moment"), (slice(4, 10), "inertia")):
        scale = np.abs(expected[sl]).max()
        np.testing.assert_allclose(actual[sl], expected[sl], rtol=1e-9, atol=1e-9 * scale + 1e-15,
                                   err_msg=f"{what}: {name}")


def _assert_matches_pinocchio(model: rd.Model, pm: pin.Model) -> None:
    n_continuous = sum(1 for j in pm.joints[1:] if j.nv == 1 and j.nq == 2)  # cos, sin
    assert model.nv == pm.nv
    assert model.nq == pm.nq - n_continuous
    assert list(model.body_joint_names) == list(pm.names[1:])
    pm_mass = sum(pm.inertias[i].mass for i in range(1, pm.njoints))
    assert model.total_mass == pytest.approx(pm_mass, rel=1e-12, abs=1e-300)
    for j in range(1, pm.njoints):
        i = model.body_joint_names.index(pm.names[j])
        _assert_close_groups(model.theta[i], _theta_from_pinocchio(pm.inertias[j]), f"body of {pm.names[j]}")
        placement = pm.jointPlacements[j]
        np.testing.assert_allclose(model.X_tree_R[i], placement.rotation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(model.X_tree_p[i], placement.translation, rtol=0, atol=1e-12)
        assert model.parent[i] < i


@pytest.mark.parametrize("path", PIN_URDFS, ids=erd_id)
def test_example_robot_data_matches_pinocchio(path):
    pm = _pin_model(str(path), False)
    model = _load_quietly(path, physical=_physical(path))
    _assert_matches_pinocchio(model, pm)
    assert list(model.joint_names) == list(pm.names[1:])
    # Pinocchio's joint limits, velocity and effort limits, damping and friction
    np.testing.assert_array_equal(model.damping, pm.damping)
    np.testing.assert_array_equal(model.coulomb, pm.friction)
    np.testing.assert_array_equal(model.velocity_limit, pm.velocityLimit)
    np.testing.assert_array_equal(model.effort_limit, pm.effortLimit)
    for j in range(1, pm.njoints):
        if pm.joints[j].nq == 1:
            k, iq = model.joint_names.index(pm.names[j]), pm.joints[j].idx_q
            assert (model.lower[k], model.upper[k]) == (pm.lowerPositionLimit[iq], pm.upperPositionLimit[iq])


@pytest.mark.parametrize("path", PIN_URDFS, ids=erd_id)
def test_example_robot_data_floating_base_matches_pinocchio(path):
    pm = _pin_model(str(path), True)
    model = _load_quietly(path, floating_base=True, physical=_physical(path, True))
    assert model.floating_base and model.body_joint_names[0] == "root_joint"
    _assert_matches_pinocchio(model, pm)
    assert list(model.joint_names) == list(pm.names[2:])


@pytest.mark.parametrize("rel", sorted(UNPHYSICAL))
def test_unphysical_example_robot_data_refused_then_loaded_with_warning(rel):
    """robodyn refuses the file naming the first unphysical body (depth first) and its links,
    and with physical="warn" warns about each unphysical body, fixed and floating base."""
    path = next(p for p in ALL_URDFS if erd_id(p) == rel)
    (body, links), *_ = UNPHYSICAL[rel]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        with pytest.raises(rd.ModelError) as err:
            rd.load_urdf(path)
    msg = str(err.value)
    assert str(path) in msg and f"body {body!r}" in msg and "line " in msg
    assert all(f"<link name={link!r}>" in msg for link in links), msg
    assert ("principal moments" in msg and "mass " in msg) or "zero mass" in msg  # the numbers
    assert "physical='warn'" in msg  # says how to load it anyway
    for floating_base in (False, True):
        with pytest.warns(rd.RobodynWarning) as record:
            model = rd.load_urdf(path, physical="warn", floating_base=floating_base)
        warned = [re.match(r".*?: body '([^']+)'", str(w.message)).group(1) for w in record
                  if "kept as given" in str(w.message)]
        assert warned == [b for b, _ in _unphysical(path, floating_base)]
        assert model.physical == "warn"


@pytest.mark.parametrize("rel", sorted(UNPHYSICAL))
def test_unphysical_example_robot_data_repaired(rel):
    """physical="repair" makes each unphysical body consistent, with a warning naming it and
    its principal moments before and after: negative moments raised to 0, then all three set
    to their mean where I1 + I2 >= I3 fails (MuJoCo's balanceinertia); mass, centre of mass and
    principal axes kept, every other body as in the file. Where the file only violates the
    triangle inequality, MuJoCo compiling the file's bodies with balanceinertia="true" has the
    repaired model's dynamics."""
    path = next(p for p in ALL_URDFS if erd_id(p) == rel)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        kept = rd.load_urdf(path, physical="warn", mimic="independent")
    with pytest.warns(rd.RobodynWarning) as record:
        model = rd.load_urdf(path, physical="repair", mimic="independent")
    notes = {re.match(r".*?: body '([^']+)'", str(w.message)).group(1): str(w.message) for w in record
             if "repaired to" in str(w.message)}
    assert list(notes) == [b for b, _ in _unphysical(path, False)]
    assert model.physical == "error" and rd.model.consistent_inertial_parameters(model.theta).all()
    only_triangle = True
    for i, name in enumerate(model.link_names):
        if name not in notes:
            np.testing.assert_array_equal(model.theta[i], kept.theta[i], err_msg=name)
            continue
        m0, c0, I0 = rd.model.mass_com_inertia(kept.theta[i])
        m1, c1, I1 = rd.model.mass_com_inertia(model.theta[i])
        before, V = np.linalg.eigh(I0)
        expected = np.maximum(before, 0.0)
        if expected[0] + expected[1] < expected[2]:
            expected[:] = expected.mean()
        only_triangle &= bool(before[0] >= 0)
        assert m1 == m0 and np.allclose(c1, c0, rtol=1e-12, atol=0.0), name
        assert_rel(V.T @ I1 @ V, np.diag(expected), 1e-12, f"{name}: the moments in the same axes")
        assert f"{before[0]:.6g}" in notes[name] and f"repaired to [{expected[0]:.6g}" in notes[name]
    if only_triangle:
        import mujoco
        from test_mjcf import compare_with_mujoco

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rd.RobodynWarning)
            text = rd.write_mjcf(kept).replace("<compiler ", '<compiler balanceinertia="true" ', 1)
        compare_with_mujoco(model, mujoco.MjModel.from_xml_string(text), label=lambda model, site: site)


def test_repair_of_one_body():
    """The rule on single bodies: a consistent body unchanged, a negative moment raised to 0
    (when the triangle inequality then holds, nothing else), a massless body with an inertia
    emptied; a negative mass cannot be repaired. ``Model(physical="repair")`` and the CLI take
    the option too."""
    repair = rd.model.repaired_inertial_parameters
    ok = rd.model.inertial_parameters_from(2.0, (0.1, 0.2, 0.3), np.diag([1.0, 2.0, 2.5]))
    np.testing.assert_array_equal(repair(ok)[0], ok)
    R = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    flat = rd.model.inertial_parameters_from(2.0, (0.1, 0.2, 0.3), R @ np.diag([-0.01, 1.0, 1.0]) @ R.T)
    fixed, before, after = repair(flat)
    assert_rel(after, [0.0, 1.0, 1.0], 1e-12)
    assert_rel(fixed, rd.model.inertial_parameters_from(2.0, (0.1, 0.2, 0.3), R @ np.diag([0.0, 1.0, 1.0]) @ R.T),
               1e-12)
    ghost = np.array([0.0, 0, 0, 0, 1e-6, 0, 1e-6, 0, 0, 1e-6])
    np.testing.assert_array_equal(repair(ghost)[0], np.zeros(10))
    with pytest.raises(rd.ModelError, match="cannot be repaired"):
        repair(np.r_[-1.0, np.zeros(9)])
    model = rd.models.load("double_pendulum")
    theta = model.theta.copy()
    theta[1] = flat
    with pytest.warns(rd.RobodynWarning, match=r"body 1 \('.*'\): principal moments of inertia \[-0.01, 1, 1\] "
                                               r"repaired to \[0, 1, 1\] \(negative principal moments raised to 0;"):
        repaired = model.replace(theta=theta, physical="repair")
    assert repaired.physical == "error"
    assert_rel(repaired.theta[1], fixed, 0.0)
    np.testing.assert_array_equal(repaired.theta[0], model.theta[0])
    with pytest.raises(ValueError, match="physical must be 'error', 'warn' or 'repair'"):
        model.replace(physical="fix")


@pytest.mark.parametrize("rel", sorted(PLACEHOLDERS))
def test_placeholder_links_merge_into_consistent_bodies(rel):
    """The link is not a rigid body alone (given alone, it is refused), but the body it shares
    with other links is: the file loads with the defaults, fixed and floating base."""
    path = next(p for p in ALL_URDFS if erd_id(p) == rel)
    for floating_base in (False, True):
        model = _load_quietly(path, floating_base=floating_base)
        assert model.physical == "error"
    link = PLACEHOLDERS[rel]
    b, _, _ = model.frame_index(link)
    together = [n for n in model.link_names + model.frame_names if model.frame_index(n)[0] == b]
    assert b >= 0 and len(together) > 1  # merged with another link by a fixed joint
    text = pathlib.Path(path).read_text()
    element = re.search(rf'<link\s+name="{re.escape(link)}"\s*>.*?</link>', text, re.S).group(0)
    alone = f'<robot name="r">{element}<link name="{link}_parent"/><joint name="j" type="revolute">' \
        f'<parent link="{link}_parent"/><child link="{link}"/><axis xyz="0 0 1"/>' \
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rd.RobodynWarning)
        with pytest.raises(rd.ModelError, match=f"body {re.escape(repr(link))}"):
            rd.load_urdf(alone)


@pytest.mark.parametrize("rel", sorted(PINOCCHIO_REFUSES))
def test_files_pinocchio_refuses_are_refused(rel):
    path = next(p for p in ALL_URDFS if erd_id(p) == rel)
    with pytest.raises(ValueError):
        pin.buildModelFromUrdf(str(path))
    with pytest.raises(rd.ModelError, match=PINOCCHIO_REFUSES[rel]) as err:
        rd.load_urdf(path)
    assert str(err.value).startswith(f"{path}: <robot> (line ")


# ----------------------------------------------------------------------------------------
# bad input: ModelError naming the file (or <string>), the element and the line
# ----------------------------------------------------------------------------------------

# (fixture file, element named in the message, what the message says); the lines marked
# <!-- ERROR --> in the file must all be named.
BAD_FILES = [
    ("malformed.urdf", "</joint>", "malformed XML"),
    ("unknown_joint_type.urdf", "<joint name='hinge'>", "unknown joint type 'ball'"),
    ("link_without_name.urdf", "<link>", "link without a name"),
    ("duplicate_link.urdf", "<link name='arm'>", "duplicate link name 'arm'"),
    ("duplicate_joint.urdf", "<joint name='j1'>", "duplicate joint name 'j1'"),
    ("missing_parent.urdf", "<joint name='j1'>", "parent link 'ghost' does not exist"),
    ("missing_child.urdf", "<joint name='j2'>", "child link 'ghost' does not exist"),
    ("several_roots.urdf", "<link name='island'>", "several root links"),
    ("two_parents.urdf", "<joint name='j2'>", "link 'hand' has two parents"),
    ("cycle.urdf", "<joint name='closing'>", "cycle"),
    ("negative_mass.urdf", "<link name='arm'> <inertial>", "negative mass"),
    ("zero_mass_with_inertia.urdf", "<link name='arm'> <inertial>", "zero mass"),
    ("inertia_not_psd.urdf", "<link name='arm'> <inertial>", "not positive semi-definite"),
    ("triangle_inequality.urdf", "<link name='arm'> <inertial>", "triangle inequality"),
    ("zero_axis.urdf", "<joint name='j1'>", "joint axis is zero"),
    ("wrong_number_count.urdf", "<origin>", "needs 3 number(s)"),
    ("billion_laughs.urdf", "<!DOCTYPE lolz>", "forbidden"),
    ("external_entity.urdf", "<!DOCTYPE robot>", "forbidden"),
    ("dtd.urdf", "<!DOCTYPE robot>", "forbidden"),
    ("too_deep.urdf", "<nest>", "nested deeper than 64 levels"),
]


@pytest.mark.parametrize("name, element, what", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_file_names_file_element_and_line(fixture_path, monkeypatch, name, element, what):
    monkeypatch.setattr(urdf_module, "MAX_DEPTH", 64)  # too_deep.urdf marks level 65
    path = fixture_path(name)
    text = path.read_text()
    lines = marked_lines(text)
    assert lines, f"{name} marks no line"
    for source, label in ((path, str(path)), (str(path), str(path)), (text, "<string>")):
        with pytest.raises(rd.ModelError) as err:
            rd.load_urdf(source)
        msg = str(err.value)
        assert msg.startswith(label), msg
        assert element in msg and what in msg, msg
        for line in lines:
            assert_names_line(msg, line)
    assert isinstance(err.value, ValueError)


_NONFINITE = """<robot name="nonfinite">
  <link name="base"/>
  <link name="arm">
    <inertial>
      <origin xyz="{inertial_xyz}" rpy="{inertial_rpy}"/>
      <mass value="{mass}"/>
      <inertia ixx="{ixx}" iyy="0.1" izz="0.1" ixy="{ixy}" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <origin xyz="{xyz}" rpy="{rpy}"/>
    <axis xyz="{axis}"/>
    <limit lower="{lower}" upper="1" effort="{effort}" velocity="2"/>
    <dynamics damping="{damping}" friction="0"/>
  </joint>
</robot>"""
_GOOD = dict(inertial_xyz="0 0 0.1", inertial_rpy="0 0 0", mass="1", ixx="0.1", ixy="0", xyz="0 0 0.5",
             rpy="0 0 0", axis="0 0 1", lower="-1", effort="10", damping="0.1")
_ELEMENT = dict(inertial_xyz="<origin>", inertial_rpy="<origin>", mass="<mass>", ixx="<inertia>",
                ixy="<inertia>", xyz="<origin>", rpy="<origin>", axis="<axis>", lower="<limit>",
                effort="<limit>", damping="<dynamics>")


def test_nonfinite_template_is_valid():
    model = rd.load_urdf(_NONFINITE.format(**_GOOD))
    assert model.nv == 1 and model.total_mass == 1.0


@pytest.mark.parametrize("bad", ["nan", "NaN", "inf", "-inf", "1e999"])
@pytest.mark.parametrize("field", sorted(_GOOD))
def test_nonfinite_number_names_element_and_line(field, bad):
    values = dict(_GOOD)
    n = len(values[field].split())
    values[field] = " ".join([bad] + ["0"] * (n - 1))
    text = _NONFINITE.format(**values)
    line = next(i for i, s in enumerate(_NONFINITE.splitlines(), 1) if "{" + field + "}" in s)
    with pytest.raises(rd.ModelError) as err:
        rd.load_urdf(text)
    msg = str(err.value)
    assert msg.startswith("<string>") and _ELEMENT[field] in msg and "not finite" in msg
    assert_names_line(msg, line)


def test_file_over_size_limit(fixture_path, monkeypatch):
    monkeypatch.setattr(urdf_module, "MAX_FILE_BYTES", 100)
    path = fixture_path("mimic.urdf")
    assert path.stat().st_size > 100
    with pytest.raises(rd.ModelError, match="exceeds the limit of 100 bytes") as err:
        rd.load_urdf(path)
    assert str(path) in str(err.value)
    with pytest.raises(rd.ModelError, match="exceeds the limit") as err:
        rd.load_urdf(path.read_text())
    assert str(err.value).startswith("<string>")


def test_missing_file(tmp_path):
    path = tmp_path / "no_such_robot.urdf"
    for source in (path, str(path)):
        with pytest.raises(rd.ModelError, match="cannot read URDF file") as err:
            rd.load_urdf(source)
        assert str(path) in str(err.value)


def test_directory_and_empty_input(tmp_path):
    with pytest.raises(rd.ModelError, match="not a regular file") as err:
        rd.load_urdf(tmp_path)
    assert str(tmp_path) in str(err.value)
    for empty in ("", "  \n"):
        with pytest.raises(rd.ModelError, match="empty input"):
            rd.load_urdf(empty)


def test_not_utf8_file(tmp_path):
    path = tmp_path / "latin1.urdf"
    path.write_bytes('<robot name="r\xe9"><link name="a"/></robot>'.encode("latin-1"))
    with pytest.raises(rd.ModelError, match="not UTF-8") as err:
        rd.load_urdf(path)
    assert str(path) in str(err.value)


def test_xml_string_with_byte_order_mark_and_bytes():
    text = '<robot name="r"><link name="a"/></robot>'
    assert rd.load_urdf("\ufeff" + text).link_names == ()
    assert rd.load_urdf(text.encode()).frame_names == ("a",)


def test_root_element_must_be_robot():
    with pytest.raises(rd.ModelError, match=r"<string>: <model name='r'> \(line 1\): root element must be <robot>"):
        rd.load_urdf('<model name="r"><link name="a"/></model>')


def test_mimic_joint_couples_by_default_and_loads_as_independent_joint_on_request(fixture_path):
    path = fixture_path("mimic.urdf")
    model = rd.load_urdf(path)  # no warning: the coupling is read
    assert isinstance(model, rd.CoupledModel) and model.nv == 1 and model.full.nv == 2
    assert model.joint_names == ("left_joint",) and model.mimic == (("right_joint", "left_joint", 1.0, 0.0),)
    with pytest.warns(rd.RobodynWarning, match=r"mimic joints loaded as independent joints: \['right_joint'\]") as rec:
        model = rd.load_urdf(path, mimic="independent")
    assert str(path) in str(rec[0].message)
    assert model.joint_names == ("left_joint", "right_joint") and model.nv == 2
    with pytest.raises(ValueError, match="mimic must be 'couple' or 'independent'"):
        rd.load_urdf(path, mimic="yes")


def test_ignored_elements_warn(fixture_path):
    path = fixture_path("ignored_elements.urdf")
    with pytest.warns(rd.RobodynWarning) as rec:
        model = rd.load_urdf(path)
    msg = " ".join(str(w.message) for w in rec)
    assert str(path) in msg
    for tag in ("gazebo", "transmission", "material", "calibration", "safety_controller"):
        assert f"<{tag}>" in msg
    assert model.nv == 1 and model.total_mass == 1.0


def test_valid_robot_loads_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = rd.load_urdf(_robot(_link("base"), _link("arm", 1.0), _joint("j", "revolute", "base", "arm")))
    assert model.nv == 1


def test_link_without_inertial_is_massless():
    model = rd.load_urdf(_robot(_link("base"), _link("arm"), _joint("j", "revolute", "base", "arm")))
    np.testing.assert_array_equal(model.theta, np.zeros((1, 10)))
    assert model.total_mass == 0.0


def _chain_urdf(n: int, close_cycle: bool = False) -> str:
    """A chain of n revolute joints; with close_cycle, a root plus a ring of n links."""
    parts = ['<robot name="chain">', '<link name="l0"/>']
    parts += [f'<link name="l{i}"/>' for i in range(1, n + 1)]
    for i in range(1, n + 1):
        parent = f"l{i - 1}" if not (close_cycle and i == 1) else f"l{n}"
        parts.append(f'<joint name="j{i:05d}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
                     '<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/></joint>')
    return "\n".join(parts + ["</robot>"])


def test_long_chain_loads_without_recursion():
    model = rd.load_urdf(_chain_urdf(5000))
    assert model.nv == model.nbodies == 5000
    np.testing.assert_array_equal(model.parent, np.arange(-1, 4999))
    assert model.joint_names[-1] == "j05000"


def test_long_cycle_detected_without_recursion():
    with pytest.raises(rd.ModelError, match="cycle") as err:
        rd.load_urdf(_chain_urdf(5000, close_cycle=True))
    msg = str(err.value)
    assert msg.startswith("<string>") and "<joint name='j0" in msg and "(line " in msg


# ----------------------------------------------------------------------------------------
# URDF semantics against hand computations
# ----------------------------------------------------------------------------------------


def _robot(*parts: str) -> str:
    return '<robot name="test">\n' + "\n".join(parts) + "\n</robot>"


def _link(name, mass=None, xyz="0 0 0", rpy="0 0 0", inertia=(0.01, 0, 0, 0.02, 0, 0.03)) -> str:
    if mass is None:
        return f'<link name="{name}"/>'
    ixx, ixy, ixz, iyy, iyz, izz = inertia
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial></link>')


def _joint(name, jtype, parent, child, xyz="0 0 0", rpy="0 0 0", axis="0 0 1", extra="") -> str:
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{extra}</joint>')


def _theta(m, c, Ic):
    """10 parameters about the origin, by hand: h = m c, I_o = I_c + m (|c|^2 1 - c c^T)."""
    c = np.asarray(c, dtype=float)
    Io = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
    return np.array([m, *(m * c), Io[0, 0], Io[0, 1], Io[1, 1], Io[0, 2], Io[1, 2], Io[2, 2]])


RPY = (0.3, -0.7, 1.1)
# inertia about the centre of mass in the inertial frame: (ixx, ixy, ixz, iyy, iyz, izz)
I_LIST = (0.05, 0.004, -0.003, 0.07, 0.002, 0.09)
I_MAT = np.array([[0.05, 0.004, -0.003], [0.004, 0.07, 0.002], [-0.003, 0.002, 0.09]])


def test_rpy_is_extrinsic_xyz():
    R = Rotation.from_euler("xyz", RPY).as_matrix()  # lower case: extrinsic
    np.testing.assert_allclose(R, rot("z", RPY[2]) @ rot("y", RPY[1]) @ rot("x", RPY[0]), atol=1e-15)
    assert np.abs(R - rot("x", RPY[0]) @ rot("y", RPY[1]) @ rot("z", RPY[2])).max() > 0.1  # the angles tell them apart


def test_inertial_origin_rotation_is_R_I_RT():
    com = (0.1, -0.2, 0.3)
    text = _robot(_link("base"), _link("arm", 2.5, " ".join(map(str, com)), " ".join(map(str, RPY)), I_LIST),
                  _joint("j", "revolute", "base", "arm"))
    model = rd.load_urdf(text)
    R = rot("z", RPY[2]) @ rot("y", RPY[1]) @ rot("x", RPY[0])
    np.testing.assert_allclose(model.theta[0], _theta(2.5, com, R @ I_MAT @ R.T), rtol=1e-13, atol=1e-15)


def test_joint_origin_rpy_and_xyz():
    text = _robot(_link("base"), _link("arm", 1.0), _joint("j", "revolute", "base", "arm", "1 2 3", " ".join(map(str, RPY))))
    model = rd.load_urdf(text)
    np.testing.assert_allclose(model.X_tree_R[0], rot("z", RPY[2]) @ rot("y", RPY[1]) @ rot("x", RPY[0]), atol=1e-15)
    np.testing.assert_array_equal(model.X_tree_p[0], [1, 2, 3])


def test_fixed_joint_merges_child_inertia_by_parallel_axis():
    m1, c1 = 2.0, np.array([0.1, 0.0, 0.2])
    m2, c2 = 0.5, np.array([0.0, 0.05, -0.1])
    I1 = np.diag([0.01, 0.02, 0.03])
    p, rpy = np.array([0.3, -0.1, 0.4]), (0.2, 0.5, -0.4)
    text = _robot(
        _link("base"),
        _link("arm", m1, " ".join(map(str, c1)), "0 0 0", (0.01, 0, 0, 0.02, 0, 0.03)),
        _link("tool", m2, " ".join(map(str, c2)), "0 0 0", I_LIST),
        _joint("j", "revolute", "base", "arm"),
        _joint("tool_mount", "fixed", "arm", "tool", " ".join(map(str, p)), " ".join(map(str, rpy))),
    )
    model = rd.load_urdf(text)
    assert model.nbodies == 1 and model.link_names == ("arm",) and model.joint_names == ("j",)
    R = rot("z", rpy[2]) @ rot("y", rpy[1]) @ rot("x", rpy[0])
    # by hand: both bodies about arm's origin, in arm's frame, then added
    c2_arm = p + R @ c2
    expected = _theta(m1, c1, I1) + _theta(m2, c2_arm, R @ I_MAT @ R.T)
    np.testing.assert_allclose(model.theta[0], expected, rtol=1e-13, atol=1e-15)
    # the merged link stays a frame of the model, at its placement on the body
    body, Rf, pf = model.frame_index("tool")
    assert body == 0
    np.testing.assert_allclose(Rf, R, atol=1e-15)
    np.testing.assert_allclose(pf, p, atol=1e-15)
    assert model.body_index("tool") == 0


def test_links_fixed_to_the_world_are_world_frames():
    text = _robot(_link("world"), _link("base", 3.0), _link("arm", 1.0),
                  _joint("weld", "fixed", "world", "base", "0 0 1"), _joint("j", "revolute", "base", "arm", "0 0 0.5"))
    model = rd.load_urdf(text)
    assert model.nbodies == 1 and model.total_mass == 1.0  # a body welded to the world does not move
    assert model.frame_index("base")[0] == -1
    np.testing.assert_allclose(model.X_tree_p[0], [0, 0, 1.5])


def test_axis_is_normalised():
    text = _robot(_link("base"), _link("a"), _link("b"),
                  _joint("ja", "revolute", "base", "a", axis="0 0 2"), _joint("jb", "prismatic", "base", "b", axis="1 1 0"))
    model = rd.load_urdf(text)
    np.testing.assert_allclose(model.joint_axis, [[0, 0, 1], [2 ** -0.5, 2 ** -0.5, 0]], atol=1e-15)


def test_default_axis_is_x():
    model = rd.load_urdf(_robot(_link("base"), _link("a"), '<joint name="j" type="revolute"><parent link="base"/>'
                                                          '<child link="a"/></joint>'))
    np.testing.assert_array_equal(model.joint_axis[0], [1, 0, 0])


def test_continuous_is_revolute_without_limits():
    limit = '<limit lower="-1" upper="1" effort="5" velocity="3"/>'
    text = _robot(_link("base"), _link("wheel", 1.0), _joint("spin", "continuous", "base", "wheel", extra=limit))
    model = rd.load_urdf(text)
    assert model.nq == model.nv == 1 and joints.NAMES[model.joint_type[0]] == "revolute"
    assert (model.lower[0], model.upper[0]) == (-np.inf, np.inf)
    assert (model.velocity_limit[0], model.effort_limit[0]) == (3.0, 5.0)


def test_limits_and_dynamics_are_read():
    text = _robot(
        _link("base"), _link("a", 1.0), _link("b", 1.0), _link("c", 1.0),
        _joint("ja", "revolute", "base", "a", extra='<limit lower="-1.5" upper="2" effort="40" velocity="3"/>'
                                                   '<dynamics damping="0.7" friction="1.25"/>'),
        _joint("jb", "prismatic", "a", "b", extra='<limit effort="7" velocity="0.5"/><dynamics damping="2"/>'),
        _joint("jc", "revolute", "b", "c"),
    )
    model = rd.load_urdf(text)
    assert model.joint_names == ("ja", "jb", "jc")
    np.testing.assert_array_equal(model.lower, [-1.5, 0.0, -np.inf])  # URDF: lower/upper default to 0
    np.testing.assert_array_equal(model.upper, [2.0, 0.0, np.inf])
    np.testing.assert_array_equal(model.velocity_limit, [3.0, 0.5, np.inf])
    np.testing.assert_array_equal(model.effort_limit, [40.0, 7.0, np.inf])
    np.testing.assert_array_equal(model.damping, [0.7, 2.0, 0.0])
    np.testing.assert_array_equal(model.coulomb, [1.25, 0.0, 0.0])


def test_negative_velocity_limit_is_refused():
    text = _robot(_link("base"), _link("a"), _joint("ja", "revolute", "base", "a", extra='<limit velocity="-1"/>'))
    with pytest.raises(rd.ModelError, match=r"<joint name='ja'> \(line \d+\): velocity must be finite and >= 0"):
        rd.load_urdf(text)


def test_children_are_ordered_by_joint_name():
    text = _robot(_link("base"), _link("a"), _link("b"), _link("b2"),
                  _joint("z_joint", "revolute", "base", "a"), _joint("m_joint", "revolute", "base", "b"),
                  _joint("a_joint", "revolute", "b", "b2"))
    model = rd.load_urdf(text)
    assert model.joint_names == ("m_joint", "a_joint", "z_joint")
    np.testing.assert_array_equal(model.parent, [-1, 0, -1])


def test_floating_base_layout():
    text = _robot(_link("torso", 10.0), _link("arm", 1.0), _link("head", 0.5),
                  _joint("shoulder", "revolute", "torso", "arm", "0 0.2 0"), _joint("neck", "fixed", "torso", "head", "0 0 0.3"))
    fixed = rd.load_urdf(text)
    model = rd.load_urdf(text, floating_base=True)
    assert model.floating_base and not fixed.floating_base
    assert model.body_joint_names[0] == "root_joint" and model.link_names[0] == "torso"
    assert joints.NAMES[model.joint_type[0]] == "free" and model.parent[0] == -1
    n = len(fixed.joint_names)
    assert (model.nq, model.nv) == (7 + n, 6 + n)
    assert model.joint_names == fixed.joint_names == ("shoulder",)
    assert (model.idx_q[1], model.idx_v[1]) == (7, 6)
    np.testing.assert_allclose(model.theta[0], _theta(10.0, [0, 0, 0], np.diag([0.01, 0.02, 0.03]))
                               + _theta(0.5, [0, 0, 0.3], np.diag([0.01, 0.02, 0.03])), atol=1e-15)
    assert model.frame_index("head")[0] == 0
    assert np.all(np.isinf(model.lower[:6])) and np.all(np.isinf(model.upper[:6]))
    assert model.total_mass == 11.5 and fixed.total_mass == 1.0


# ----------------------------------------------------------------------------------------
# files from the wild that the major loaders read
# ----------------------------------------------------------------------------------------

_ARM = (_link("base", 2.0) + _link("arm", 1.0, xyz="0.1 0 0.2")
        + _joint("j", "revolute", "base", "arm", xyz="0 0 0.3", axis="0 1 0",
                 extra='<limit lower="-1" upper="1" effort="5" velocity="2"/>'))


def _same_model(a, b):
    for field in ("parent", "joint_type", "joint_axis", "X_tree_R", "X_tree_p", "theta", "lower", "upper"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field), err_msg=field)
    assert a.link_names == b.link_names and a.joint_names == b.joint_names


def test_reversed_limits_load_unbounded_with_warning(fixture_path):
    """PyBullet reads lower > upper as no limit; robodyn too, with a warning naming the joint."""
    path = fixture_path("limits_reversed.urdf")
    with pytest.warns(rd.RobodynWarning, match=r"lower > upper loaded as unbounded: j1 \(1 > -1\)") as rec:
        model = rd.load_urdf(path)
    assert str(path) in str(rec[0].message)
    assert (model.lower[0], model.upper[0]) == (-np.inf, np.inf)
    assert (model.effort_limit[0], model.velocity_limit[0]) == (10.0, 2.0)


@pytest.mark.parametrize("head", ["\ufeff", "\n\n  ", "\ufeff\r\n\t"], ids=["bom", "blank-lines", "bom-and-blanks"])
def test_byte_order_mark_and_whitespace_before_the_declaration(tmp_path, head):
    text = head + '<?xml version="1.0" encoding="utf-8"?>\n' + _robot(_ARM)
    path = tmp_path / "lead.urdf"
    path.write_bytes(text.encode("utf-8"))
    reference = rd.load_urdf(_robot(_ARM))
    for source in (path, text):
        _same_model(rd.load_urdf(source), reference)
    # line numbers still count the leading lines
    bad = head + '<?xml version="1.0"?>\n<robot name="r">\n<link name="a"/>\n<link/>\n</robot>'
    with pytest.raises(rd.ModelError, match=rf"<link> \(line {4 + head.count(chr(10))}\): link without a name"):
        rd.load_urdf(bad)


def test_default_namespace_on_robot():
    text = _robot(_ARM).replace('<robot name="test">', '<robot name="test" xmlns="http://example.org/urdf">')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _same_model(rd.load_urdf(text), rd.load_urdf(_robot(_ARM)))


@pytest.mark.parametrize("declared", [True, False], ids=["declared", "undeclared"])
def test_extension_elements_in_a_namespace_are_ignored(declared):
    """``<drake:joint>`` and namespaced attributes, with ``xmlns:drake`` declared or not: the
    extension elements are listed in the one warning, and nothing of them is read as URDF."""
    extra = ('<drake:joint name="planar_x" type="planar"><drake:parent link="base"/></drake:joint>'
             '<link name="tool" drake:collision_filter="x"/>'
             + _joint("tool_fixed", "fixed", "arm", "tool"))
    text = _robot(_ARM, extra)
    if declared:
        text = text.replace('<robot name="test">', '<robot name="test" xmlns:drake="http://drake.mit.edu">')
    uri = "http://drake.mit.edu" if declared else "urn:undeclared:drake"
    with pytest.warns(rd.RobodynWarning, match=re.escape(f"1 <{{{uri}}}joint>")):
        model = rd.load_urdf(text)
    assert model.nv == 1 and model.joint_names == ("j",) and "tool" in model.frame_names


def test_floating_joint_is_a_free_joint_under_the_world():
    """A ``floating`` joint from a link welded to the world is a free joint, as in Pinocchio
    (JointModelFreeFlyer at the joint origin); under a moving link it is refused."""
    text = _robot(_link("world"), _ARM.replace('_link("base"', ''),
                  _joint("float", "floating", "world", "base", xyz="0.5 -0.2 1.0", rpy="0.1 0.2 0.3"))
    model = rd.load_urdf(text)
    assert model.floating_base and model.nq == 8 and model.nv == 7
    assert model.body_joint_names == ("float", "j") and "world" in model.frame_names
    np.testing.assert_allclose(model.X_tree_p[0], [0.5, -0.2, 1.0])
    pm = pin.buildModelFromXML(text)
    assert pm.joints[1].shortname() == "JointModelFreeFlyer"
    rng = np.random.default_rng(3)
    q = np.concatenate([rng.normal(size=3), Rotation.random(random_state=4).as_quat(), [0.4]])
    v, a = rng.normal(size=7), rng.normal(size=7)
    pd = pm.createData()
    np.testing.assert_allclose(rd.rnea(model, q, v, a), pin.rnea(pm, pd, q, v, a), rtol=1e-10, atol=1e-10)
    with pytest.raises(rd.ModelError, match=r"joint name='float'.*a free joint must attach to the world, but its "
                                            r"parent link 'arm' moves with body 'arm'"):
        rd.load_urdf(_robot(_ARM, _link("box", 1.0), _joint("float", "floating", "arm", "box")))


def test_planar_joint_matches_pinocchio_and_needs_a_z_normal():
    """A URDF planar joint (the plane's normal as its axis, z) is robodyn's planar joint, as it
    is Pinocchio's JointModelPlanar: q = [x, y, cos t, sin t]."""
    text = _robot(_link("world"), _link("base", 2.0, xyz="0.1 0 0.2"), _link("arm", 1.0, xyz="0 0 0.2"),
                  _joint("plane", "planar", "world", "base", xyz="0 0 0.5", rpy="0.1 0.2 0.3", axis="0 0 1"),
                  _joint("j", "revolute", "base", "arm", axis="0 1 0",
                         extra='<limit lower="-1" upper="1" effort="5" velocity="2"/>'))
    model = rd.load_urdf(text)
    assert (model.nq, model.nv) == (5, 4) and model.joint_type.tolist() == [joints.PLANAR, joints.REVOLUTE]
    pm = pin.buildModelFromXML(text)
    assert pm.joints[1].shortname() == "JointModelPlanar"
    q = np.array([0.3, -0.2, np.cos(0.7), np.sin(0.7), 0.4])
    v, a = np.array([0.1, 0.2, 0.3, 0.4]), np.array([0.5, -0.1, 0.2, 0.3])
    np.testing.assert_allclose(rd.rnea(model, q, v, a), pin.rnea(pm, pm.createData(), q, v, a), rtol=1e-12, atol=1e-12)
    with pytest.raises(rd.ModelError, match=r"<joint name='p'> \(line \d+\): planar joint with axis \[1.0, 0.0, 0.0\]: "
                                            r"only the joint frame's z axis"):
        rd.load_urdf(_robot(_ARM, _link("box", 1.0), _joint("p", "planar", "arm", "box", axis="1 0 0")))
