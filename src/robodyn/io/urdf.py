"""URDF loader: ``load_urdf(path_or_xml_string, floating_base=False) -> Model``.

Reads links (``<inertial>`` with origin xyz/rpy applied as ``R I R^T``), and joints of type
revolute, continuous, prismatic, fixed (merged into the parent body), floating (a free
joint; its parent link must be the root or welded to it) and planar (with ``<axis xyz="0 0
1">``, the plane's normal), with ``<origin>``,
``<axis>`` (normalised; zero is an error), ``<limit lower upper velocity effort>`` (lower and
upper default to 0 as in the URDF specification; +-1.7976931348623157e+308, the largest
double, is no limit, as ``write_urdf`` writes it; a joint without ``<limit>`` is unbounded,
continuous joints always are), ``<dynamics damping friction>``, and a joint's armature from
Drake's ``<transmission>`` extension (an ``<actuator>`` with ``<drake:rotor_inertia value>``
and ``<drake:gear_ratio value>``: ``rotor_inertia * gear_ratio^2``; ``write_urdf`` writes it).
A ``<mimic joint multiplier offset>`` joint follows its source joint, ``q = multiplier q_source +
offset``: the model is then a :class:`~robodyn.coupling.CoupledModel` whose coordinates are the
independent joints (``mimic="independent"`` loads mimic joints as ordinary joints, with a
warning). Elements without rigid-body
dynamics (material, gazebo, transmission, joint calibration and safety_controller, ...) are
reported in one :class:`RobodynWarning` per file; link geometry (visual, collision) is not
dynamics and is skipped without a warning (:func:`read_collisions` reads the collision
geometry, which :func:`robodyn.contact.shapes_from_urdf` turns into contact shapes;
:func:`read_visuals` the visual geometry and its colours, which :mod:`robodyn.viewer` draws).

Lenient where the major loaders are: a byte-order mark or blank lines before ``<?xml ...?>``,
a default ``xmlns`` on ``<robot>``, extension elements and attributes in other namespaces
(``<drake:joint>``, with ``xmlns:drake`` declared or not: listed in the warning, not read), a
``<limit>`` with lower > upper (no limit, as PyBullet reads it, with a warning).

XML is parsed with DTDs, entities and external references forbidden (defusedxml). Every
error is a :class:`~robodyn.model.ModelError` naming the file, the element and its line.
Files are limited to ``MAX_FILE_BYTES`` bytes and ``MAX_DEPTH`` levels of nesting.
"""

from __future__ import annotations

from dataclasses import dataclass

import math
import warnings
from collections import Counter

import numpy as np

from ..builder import ModelBuilder
from ..errors import ModelError, RobodynWarning
from ..coupling import CoupledModel
from ..model import Model
from ._xml import MAX_DEPTH, is_xml_text, parse, parse_lazy_lines, read_source

# ``is_xml_text(source)``: whether a source is XML text rather than a path (relative mesh
# paths of a file start at its folder), shared with the readers of the geometry.
__all__ = ["MAX_DEPTH", "MAX_FILE_BYTES", "load_urdf", "read_collisions", "Collision", "read_visuals", "Visual",
           "is_xml_text"]

MAX_FILE_BYTES = 64 * 1024 * 1024


def _read_source(source) -> tuple[str, str]:
    return read_source(source, "URDF", MAX_FILE_BYTES)


NO_LIMIT = float(np.finfo(float).max)  # "no limit" in a file (URDF has no infinity; write_urdf's)


def _no_limit(x: float) -> float:
    """A limit of +-the largest double is no limit (+-inf)."""
    return math.copysign(math.inf, x) if abs(x) >= NO_LIMIT else x


DRAKE = ("http://drake.mit.edu", "urn:undeclared:drake")  # Drake's extension namespace, declared or not


def _drake(elem, name: str):
    """The first child ``<drake:name>`` of ``elem``, or None."""
    return next((c for c in elem if c.tag in {f"{{{uri}}}{name}" for uri in DRAKE}), None)


def _read_transmission(rd: "_Reader", elem) -> dict[str, float]:
    """``{joint: armature}`` of a ``<transmission>`` whose actuator has Drake's
    ``<drake:rotor_inertia value>`` (and ``<drake:gear_ratio value>``, default 1): the rotor
    inertia reflected on the joint, ``rotor_inertia * gear_ratio^2``. Empty for the other
    transmissions (no rigid-body dynamics)."""
    out = {}
    for act in (c for c in elem if c.tag == "actuator"):
        rotor = _drake(act, "rotor_inertia")
        if rotor is None:
            continue
        joints = [j.get("name") for j in elem if j.tag == "joint"]
        if len(joints) != 1 or not joints[0]:
            raise ModelError(f"{rd.where(elem)}: a transmission with drake:rotor_inertia needs one named <joint>, "
                             f"got {joints}")
        ratio = _drake(act, "gear_ratio")
        gear = rd.value(ratio, "value") if ratio is not None else 1.0
        out[joints[0]] = out.get(joints[0], 0.0) + rd.value(rotor, "value") * gear * gear
    return out


def _child(elem, tag: str):
    """The first child ``<tag>`` of ``elem`` (``Element.find`` without its path machinery)."""
    for c in elem:
        if c.tag == tag:
            return c
    return None


_ZEROS = (0.0, 0.0, 0.0)


class _Where:
    """``reader.where(elem, what)``, made when a message needs it (its line number is found
    then: :func:`._xml.parse_lazy_lines`)."""

    __slots__ = ("reader", "elem", "what")

    def __init__(self, reader: "_Reader", elem, what: str | None = None):
        self.reader, self.elem, self.what = reader, elem, what

    def __str__(self) -> str:
        return self.reader.where(self.elem, self.what)


class _Reader:
    def __init__(self, name: str, lines):
        self.name = name
        self.lines = lines
        self._parsed: dict[str, tuple] = {}  # attribute text -> its finite numbers ("0 0 0" recurs)

    def where(self, elem, what: str | None = None) -> str:
        label = what or f"<{elem.tag}" + (f" name={elem.get('name')!r}" if elem.get("name") is not None else "") + ">"
        return f"{self.name}: {label} (line {self.lines.get(id(elem), '?')})"

    def values(self, elem, attr: str, n: int, default: tuple | None = None) -> tuple:
        """The ``n`` finite numbers of attribute ``attr`` of ``elem`` (floats), or ``default``
        (floats) when it is absent."""
        raw = None if elem is None else elem.get(attr)
        if raw is None:
            if default is None:
                raise ModelError(f"{self.where(elem)}: missing attribute {attr!r}")
            return default
        vals = self._parsed.get(raw)
        if vals is not None and len(vals) == n:
            return vals
        parts = raw.split()
        if len(parts) == n:
            try:
                vals = tuple(map(float, parts))
            except ValueError:
                pass
            else:
                total = sum(vals)
                if total - total == 0.0:  # all finite (else, or on an overflow, the checks below)
                    self._parsed[raw] = vals
                    return vals
        try:
            vals = tuple([float(t) for t in parts])
        except ValueError:
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} is not {n} number(s)") from None
        if len(vals) != n:
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} needs {n} number(s)")
        if not all(map(math.isfinite, vals)):
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} is not finite")
        return vals

    def value(self, elem, attr: str, default: float | None = None) -> float:
        """The one number of attribute ``attr`` (:meth:`values`)."""
        raw = None if elem is None else elem.get(attr)
        if raw is not None:
            try:
                x = float(raw)  # as float(raw.split()[0]) when it succeeds
            except ValueError:
                pass
            else:
                if x - x == 0.0:
                    return x
        return self.values(elem, attr, 1, None if default is None else (default,))[0]

    def floats(self, elem, attr: str, n: int, default=None) -> np.ndarray:
        """:meth:`values` as an array (``default`` any sequence)."""
        return np.array(self.values(elem, attr, n, None if default is None else tuple(map(float, default))))

    def origin(self, parent):
        o = _child(parent, "origin")
        return self.floats(o, "xyz", 3, (0, 0, 0)), self.floats(o, "rpy", 3, (0, 0, 0))

    def origin_values(self, o) -> tuple[tuple, tuple]:
        """``(xyz, rpy)`` of an ``<origin>`` element as float triples (zeros for None)."""
        if o is None:
            return _ZEROS, _ZEROS
        return self.values(o, "xyz", 3, _ZEROS), self.values(o, "rpy", 3, _ZEROS)

    def required_child(self, elem, tag: str, attr: str, c=False) -> str:
        """Attribute ``attr`` of the first child ``<tag>`` of ``elem`` (or of ``c``, that child
        or None, when given)."""
        if c is False:
            c = _child(elem, tag)
        if c is None or c.get(attr) is None:
            raise ModelError(f"{self.where(elem)}: missing <{tag} {attr}=...>")
        return c.get(attr)


_LINK_IGNORED = {"visual", "collision"}


def load_urdf(source, floating_base: bool = False, gravity=(0.0, 0.0, -9.81), *, physical: str = "error",
              mimic: str = "couple") -> Model | CoupledModel:
    """Load a URDF file (path) or XML string into a :class:`Model`.

    ``floating_base=True`` adds a free joint at the root link (q gains 7 entries, v gains 6,
    layout in :mod:`robodyn.model`). Raises :class:`ModelError` for malformed or unphysical
    descriptions; warns (:class:`RobodynWarning`) about what it ignores. Some published URDFs
    carry inertias that no rigid body can have (violating ``I1 + I2 >= I3``, say);
    ``physical="warn"`` loads them as given with a warning naming each such link;
    ``physical="repair"`` makes each such body consistent, as MuJoCo's compiler does with
    ``balanceinertia``, with a warning giving its principal moments before and after
    (:func:`robodyn.model.repaired_inertial_parameters`: negative moments raised to 0, then all
    three set to their mean where ``I1 + I2 >= I3`` fails; mass, centre of mass and axes kept).

    The children of a link are ordered by joint name (as urdfdom does), so bodies and ``v``
    follow the order Pinocchio gives the same file.

    ``mimic="couple"`` (default): ``<mimic>`` joints are not degrees of freedom; a file with
    any returns a :class:`~robodyn.coupling.CoupledModel` (``nv`` counts the independent
    joints, as Pinocchio's ``buildModelFromUrdf(..., mimic=True)``). ``mimic="independent"``:
    they load as ordinary joints (a :class:`Model`, as Pinocchio's default), with a warning.
    """
    if mimic not in ("couple", "independent"):
        raise ValueError(f"mimic must be 'couple' or 'independent', got {mimic!r}")
    text, name = _read_source(source)
    root, lines = parse_lazy_lines(text, name)
    rd = _Reader(name, lines)
    if root.tag != "robot":
        raise ModelError(f"{rd.where(root)}: root element must be <robot>, got <{root.tag}>")
    b = ModelBuilder(root.get("name", "robot"), gravity=gravity, source=name, physical=physical)
    ignored: Counter[str] = Counter()
    mimics, reversed_limits = [], []
    joint_elems, armature = [], {}
    for elem in root:
        if not isinstance(elem.tag, str):
            continue
        if elem.tag == "link":
            _read_link(rd, b, elem, ignored)
        elif elem.tag == "joint":
            joint_elems.append(elem)
        elif elem.tag == "transmission" and (rotors := _read_transmission(rd, elem)):
            for joint, value in rotors.items():
                armature[joint] = armature.get(joint, 0.0) + value
        else:
            ignored[elem.tag] += 1
    unknown = sorted(set(armature) - {str(e.get("name")) for e in joint_elems})
    if unknown:
        raise ModelError(f"{name}: drake:rotor_inertia of joints that do not exist: {unknown}")
    if _child(root, "link") is None:
        raise ModelError(f"{rd.where(root)}: no <link> element")
    for elem in sorted(joint_elems, key=lambda e: str(e.get("name"))):
        _read_joint(rd, b, elem, ignored, reversed_limits, mimics, armature.get(str(elem.get("name")), 0.0))
    if reversed_limits:
        warnings.warn(
            f"{name}: joint limits with lower > upper loaded as unbounded: {', '.join(reversed_limits)}",
            RobodynWarning, stacklevel=2,
        )
    if mimics and mimic == "independent":
        warnings.warn(f"{name}: mimic joints loaded as independent joints: {[m[0] for m in mimics]}", RobodynWarning,
                      stacklevel=2)
    ignored_dyn = {k: v for k, v in ignored.items() if k not in _LINK_IGNORED}
    if ignored_dyn:
        summary = ", ".join(f"{n} <{k}>" for k, n in sorted(ignored_dyn.items()))
        warnings.warn(f"{name}: ignored elements without rigid-body dynamics: {summary}", RobodynWarning, stacklevel=2)
    model = b.build(floating_base=floating_base)
    if mimics and mimic == "couple":
        moving = set(model.body_joint_names)
        orphans = [m for m in mimics if m[1] not in moving]
        if orphans:  # as Pinocchio's default reads them, rather than refusing the file
            warnings.warn(f"{name}: mimic joints whose source is not a moving joint of the file, loaded as "
                          f"independent joints: {', '.join(f'{j} (source {s!r})' for j, s, _, _ in orphans)}",
                          RobodynWarning, stacklevel=2)
        kept = [m for m in mimics if m[1] in moving]
        return CoupledModel(model, kept) if kept else model
    return model


def _read_link(rd: _Reader, b: ModelBuilder, elem, ignored: Counter) -> None:
    lname = elem.get("name")
    if not lname:
        raise ModelError(f"{rd.where(elem)}: link without a name")
    inertial, count = None, 0
    for child in elem:
        tag = child.tag
        if tag == "inertial":
            inertial = inertial if count else child
            count += 1
        elif tag not in _LINK_IGNORED and isinstance(tag, str):  # visual and collision: never reported
            ignored[tag] += 1
    if count > 1:
        raise ModelError(f"{rd.where(elem)}: more than one <inertial>")
    if inertial is None:
        b._add_link_values(lname, 0.0, _ZEROS, None, None, _Where(rd, elem))
        return
    where = _Where(rd, inertial, f"<link name={lname!r}> <inertial>")
    origin = mass_el = I_el = None
    for child in inertial:
        tag = child.tag
        if tag == "origin":
            origin = origin if origin is not None else child
        elif tag == "mass":
            mass_el = mass_el if mass_el is not None else child
        elif tag == "inertia":
            I_el = I_el if I_el is not None else child
    xyz, rpy = rd.origin_values(origin)
    if mass_el is None:
        raise ModelError(f"{where}: missing <mass value=...>")
    mass = rd.value(mass_el, "value")
    inertia = None if I_el is None else _inertia(rd, I_el)
    # the inertia in axes turned by rpy_to_matrix(rpy), as add_link(inertia_rotation=...)
    b._add_link_values(lname, mass, xyz, inertia, rpy, where)


_INERTIA_ATTRS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _inertia(rd: _Reader, elem) -> tuple:
    """``(ixx, ixy, ixz, iyy, iyz, izz)`` of an ``<inertia>`` (``rd.value`` of each, 0 when absent)."""
    attrib = elem.attrib
    try:  # all six given and finite: what rd.value gives
        values = tuple([float(attrib[k]) for k in _INERTIA_ATTRS])
        total = sum(values)
        if total - total == 0.0:
            return values
    except (KeyError, ValueError):
        pass
    return tuple([rd.value(elem, k, 0.0) for k in _INERTIA_ATTRS])


@dataclass(frozen=True, eq=False)
class Collision:
    """One ``<collision>`` geometry of a URDF link: ``kind`` ``"sphere"`` (``size = (radius,)``),
    ``"box"`` (``size``: the three edges), ``"cylinder"`` (``(radius, length)``, along the
    local z axis) or ``"mesh"`` (``size = ()``, ``filename`` set); ``xyz``, ``rpy`` the
    element's ``<origin>`` in the link frame; ``where`` the file, element and line."""
    link: str
    kind: str
    size: tuple
    xyz: np.ndarray
    rpy: np.ndarray
    filename: str | None
    where: str


def read_collisions(source) -> list[Collision]:
    """The ``<collision>`` geometry of every link of a URDF file (path) or XML string, in
    file order, read with the safeguards of :func:`load_urdf`. A ``<collision>`` without a
    geometry, an unknown geometry, or sizes that are not positive are a :class:`ModelError`."""
    rd, root = _parse_source(source)
    out = []
    for link, col, where in _link_elements(rd, root, "collision"):
        kind, size, g = _geometry(rd, col, where)
        xyz, rpy = rd.origin(col)
        out.append(Collision(link.get("name"), kind, size, xyz, rpy, g.get("filename"), where))
    return out


@dataclass(frozen=True, eq=False)
class Visual(Collision):
    """One ``<visual>`` of a URDF link: the fields of :class:`Collision` (the geometry frame is
    the ``<origin>`` in the link frame; a cylinder lies along its local z axis), and ``scale``
    (3,) the ``<mesh scale>`` (ones without one; 1 for the primitives); ``rgba`` (4,) in
    [0, 1], the ``<material>``'s ``<color>`` (inline, or the robot-level ``<material name>``
    it refers to), or None when the file gives none (textures are not read)."""
    scale: np.ndarray = None
    rgba: np.ndarray | None = None


def read_visuals(source) -> list[Visual]:
    """The ``<visual>`` geometry of every link of a URDF file (path) or XML string, in file
    order, read with the safeguards of :func:`load_urdf` (hardened XML, size and depth
    limits). Drawing is forgiving where dynamics is not: a ``<visual>`` without a geometry,
    with an unknown one, a ``<mesh>`` without a filename or sizes that are not positive finite
    numbers is left out with a :class:`RobodynWarning` naming the link, the element and its
    line; malformed XML is still a :class:`ModelError`."""
    rd, root = _parse_source(source)
    named = {}  # robot-level <material name=...><color rgba=.../></material>
    for m in (m for m in root if m.tag == "material" and m.get("name")):
        try:
            if (rgba := _color(rd, m)) is not None:
                named[m.get("name")] = rgba
        except ModelError as e:
            warnings.warn(f"{e}; the visuals that use it get their mesh's or the default colour",
                          RobodynWarning, stacklevel=2)
    out = []
    for link, vis, where in _link_elements(rd, root, "visual"):
        try:
            kind, size, g = _geometry(rd, vis, where)
            if kind == "mesh" and not g.get("filename"):
                raise ModelError(f"{where}: <mesh> without a filename")
            xyz, rpy = rd.origin(vis)
            scale = rd.floats(g, "scale", 3, (1.0, 1.0, 1.0)) if kind == "mesh" else np.ones(3)
            material = _child(vis, "material")
            rgba = None if material is None else _color(rd, material)
            if rgba is None and material is not None:
                rgba = named.get(material.get("name"))
        except ModelError as e:
            warnings.warn(f"{e}; this visual of link {link.get('name')!r} is not drawn", RobodynWarning,
                          stacklevel=2)
            continue
        out.append(Visual(link.get("name"), kind, size, xyz, rpy, g.get("filename"), where, scale, rgba))
    return out


def _parse_source(source) -> tuple[_Reader, object]:
    """``(reader, root element)`` of a URDF path or XML string, hardened (:mod:`._xml`)."""
    text, name = _read_source(source)
    root, lines = parse(text, name)
    return _Reader(name, lines), root


def _link_elements(rd: _Reader, root, tag: str):
    """``(link, element, where)`` for every child ``<tag>`` of every ``<link>``, in file order."""
    for link in root:
        if link.tag != "link":
            continue
        for elem in link:
            if elem.tag == tag:
                yield link, elem, rd.where(elem, f"<link name={link.get('name')!r}> <{tag}>")


_SIZES = {"sphere": ("radius",), "cylinder": ("radius", "length"), "box": ("size",), "mesh": ()}


def _geometry(rd: _Reader, elem, where: str) -> tuple[str, tuple, object]:
    """``(kind, size, geometry element)`` of the one shape in ``elem``'s ``<geometry>``
    (:class:`Collision` describes ``kind`` and ``size``); a :class:`ModelError` otherwise."""
    geometry = _child(elem, "geometry")
    shapes = [] if geometry is None else [g for g in geometry if isinstance(g.tag, str)]
    if len(shapes) != 1:
        raise ModelError(f"{where}: expected one geometry in <geometry>, got {len(shapes)}")
    g = shapes[0]
    if g.tag not in _SIZES:
        raise ModelError(f"{where}: unknown geometry <{g.tag}>")
    size = (tuple(rd.floats(g, "size", 3)) if g.tag == "box"
            else tuple(rd.floats(g, k, 1)[0] for k in _SIZES[g.tag]))
    if any(x <= 0 for x in size):
        raise ModelError(f"{where}: <{g.tag}> sizes must be > 0, got {list(size)}")
    return g.tag, size, g


def _color(rd: _Reader, material) -> np.ndarray | None:
    """The ``rgba`` (4,) of a ``<material>``'s ``<color>``, clipped to [0, 1]; None without one."""
    color = _child(material, "color")
    return None if color is None else np.clip(rd.floats(color, "rgba", 4), 0.0, 1.0)


_JOINT_READ = {"origin", "parent", "child", "axis", "limit", "dynamics", "mimic"}


def _read_joint(rd: _Reader, b: ModelBuilder, elem, ignored: Counter, reversed_limits: list, mimics: list,
                armature: float = 0.0) -> None:
    where = _Where(rd, elem)
    kids = {}  # the first child of each tag read
    for child in elem:
        tag = child.tag
        if tag in _JOINT_READ:
            if tag not in kids:
                kids[tag] = child
        elif isinstance(tag, str):
            ignored[tag] += 1
    if "mimic" in kids and elem.get("type") == "fixed":
        ignored["mimic"] += 1  # a fixed joint has nothing to couple (Pinocchio ignores it too)
    elif "mimic" in kids:  # (joint, source, multiplier, offset)
        m = kids["mimic"]
        source = m.get("joint")
        if not source:
            raise ModelError(f"{rd.where(m)}: <mimic> without a joint attribute")
        mimics.append((elem.get("name"), source, rd.value(m, "multiplier", 1.0), rd.value(m, "offset", 0.0)))
    jname = elem.get("name")
    jtype = elem.get("type")
    if not jname:
        raise ModelError(f"{where}: joint without a name")
    if jtype is None:
        raise ModelError(f"{where}: joint without a type")
    if jtype == "floating":
        jtype = "free"  # the builder checks that its parent link is welded to the world
    parent = rd.required_child(elem, "parent", "link", kids.get("parent"))
    child = rd.required_child(elem, "child", "link", kids.get("child"))
    xyz, rpy = rd.origin_values(kids.get("origin"))
    axis = rd.values(kids.get("axis"), "xyz", 3, (1.0, 0.0, 0.0))
    if jtype == "planar":
        a = np.array(axis)
        if not (np.linalg.norm(a) > 0 and np.allclose(a / np.linalg.norm(a), (0, 0, 1), rtol=0, atol=1e-12)):
            raise ModelError(f"{where}: planar joint with axis {a.tolist()}: only the joint frame's z axis is "
                             "supported as the plane's normal (turn the joint's origin so that it is z)")
    lim = kids.get("limit")
    dyn = kids.get("dynamics")
    kw = {}
    if lim is not None:
        # URDF: lower and upper default to 0 in a <limit> (urdfdom and Pinocchio read it so);
        # without a <limit> element robodyn leaves the joint unbounded.
        for key in ("lower", "upper"):
            kw[key] = _no_limit(rd.value(lim, key, 0.0))
        if kw["lower"] > kw["upper"] and jtype != "continuous":
            # PyBullet reads such a limit as no limit; robodyn does too, and says so
            reversed_limits.append(f"{jname} ({kw.pop('lower'):g} > {kw.pop('upper'):g})")
        for key in ("velocity", "effort"):
            if lim.get(key) is not None:
                kw[key] = _no_limit(rd.value(lim, key))
    if dyn is not None:
        for key in ("damping", "friction"):
            if dyn.get(key) is not None:
                kw[key] = rd.value(dyn, key)
    if armature:
        kw["armature"] = armature
    b._add_joint_values(jname, jtype, parent, child, xyz, rpy, axis, where, **kw)
