"""MJCF (MuJoCo XML) loader: ``load_mjcf(path_or_xml_string) -> Model``.

Reads what a robot description uses, with MuJoCo's own rules (its compiler, ``user_objects.cc``):

- ``<worldbody>`` body trees; ``<frame>`` elements compose into their children. A body's pose
  is ``pos`` and one of ``quat`` (w x y z), ``axisangle``, ``euler`` (``<compiler eulerseq>``:
  lower case axes rotate with the frame, upper case stay fixed), ``xyaxes``, ``zaxis``; angles
  in ``<compiler angle>`` units (degrees unless ``radian``).
- joints ``hinge``, ``slide``, ``ball`` (a spherical joint: ``q`` is MuJoCo's quaternion
  reordered, ``v`` its angular velocity in the body frame) and ``free`` (``<freejoint>``
  too), with ``pos``, ``axis``,
  ``ref``, ``range`` (``limited`` true/false/auto with ``<compiler autolimits>``),
  ``armature``, ``damping`` and ``frictionloss`` (Coulomb friction). Several joints in one
  body become a chain of massless bodies named ``body:joint``, the last one named after the
  body; MuJoCo applies them in order, each about its anchor ``pos`` in the frame the earlier
  ones have moved. ``ref`` is folded into the joint placement, so ``q`` is MuJoCo's ``qpos``
  exactly (for free joints up to the quaternion order, see :mod:`robodyn.interop.mujoco`).
  A body without joints is welded to its parent (merged, as URDF fixed joints are).
- ``<inertial>`` (``mass``, ``pos``, ``diaginertia`` with an orientation, or ``fullinertia``),
  or, when it is absent (``<compiler inertiafromgeom="auto">``, the default; ``true`` and
  ``false`` as MuJoCo), the inertia of the body's geoms in ``<compiler inertiagrouprange>``:
  spheres, capsules, cylinders, boxes and ellipsoids of uniform ``density`` (1000 unless
  given) or of a given ``mass``, ``size`` or ``fromto``; then ``boundmass``,
  ``boundinertia``, ``balanceinertia`` and ``settotalmass`` as MuJoCo applies them.
- ``<default>`` classes with inheritance (``class``, ``childclass``), ``<include file>``
  (relative to the main file's folder), ``<option gravity>`` and its gravity flag, named
  ``<site>`` elements as frames (``site:name`` where a body already has the name).
- ``<equality><joint joint1 joint2 polycoef>`` with a linear polynomial (``polycoef="a0 a1 0 0
  0"``, the default ``"0 1 0 0 0"``) between two named hinge or slide joints: ``joint1`` follows
  ``joint2`` exactly, a mimic joint (:class:`~robodyn.coupling.CoupledModel`; ``mimic=
  "independent"`` keeps both as degrees of freedom). MuJoCo holds the equality softly
  (``solref``, ``solimp``); robodyn holds it exactly.

Refused with a :class:`~robodyn.model.ModelError` naming the file, element and line: inertia
from mesh, height-field or
SDF geoms (give the body an ``<inertial>``), shell inertia, elements that generate bodies
(``<composite>``, ``<flexcomp>``, ``<replicate>``, ``<attach>``), global coordinates, a free
joint below a moving body. Ignored with one :class:`~robodyn.errors.RobodynWarning` listing
them: elements that are not the rigid-body dynamics of the tree (actuators, tendons, the
other equality constraints (``connect``, ``weld``, ``tendon``, inactive or polynomial joint
equalities, a joint locked by an equality without ``joint2``), sensors, contact pairs, ...), springs of ball and free joints, the cone
limits of ball joints (``range``: a bound on the rotation angle, which robodyn's box limits on
dofs cannot hold) and gravity compensation (``gravcomp``). Springs of hinge and slide joints (``stiffness``,
``springref``) are the model's ``stiffness`` and ``spring_reference``. Visual elements (assets, cameras, lights) are skipped
silently. Contacts are not part of the model. The geoms to draw, on the same bodies:
:func:`read_mjcf_visuals` (what ``robodyn.viewer`` draws of an MJCF file).

The XML is read as the URDF loader reads it: DTDs, entities and external references
forbidden, size and depth bounded, at most ``MAX_INCLUDES`` included files.
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..builder import ModelBuilder
from ..coupling import CoupledModel
from ..errors import ModelError, RobodynWarning
from ..lie import exp_so3, quat_matrix
from ..model import Model
from ._xml import is_xml_text, parse, read_source

__all__ = ["MAX_FILE_BYTES", "MAX_INCLUDES", "GeomVisual", "load_mjcf", "read_mjcf_visuals"]

MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_INCLUDES = 100

# Elements read, or skipped silently because they draw or store things (no dynamics).
_TOP_READ = {"compiler", "option", "default", "worldbody", "include", "equality"}
_TOP_SILENT = {"asset", "visual", "statistic", "size", "custom", "extension", "keyframe"}
_BODY_READ = {"body", "joint", "freejoint", "geom", "site", "inertial", "frame"}
_BODY_SILENT = {"camera", "light", "plugin"}
_GENERATORS = {"composite", "flexcomp", "replicate", "attach"}
_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_EPS = 1e-14  # mjEPS
_DEFAULT_RGBA = np.array([0.5, 0.5, 0.5, 1.0], np.float32)  # a geom's rgba when the file gives none


@dataclass
class _Compiler:
    degree: bool = True
    eulerseq: str = "xyz"
    autolimits: bool = True
    inertiafromgeom: str = "auto"
    inertiagrouprange: tuple = (0, 5)
    boundmass: float = 0.0
    boundinertia: float = 0.0
    balanceinertia: bool = False
    settotalmass: float = -1.0
    alignfree: bool = False


class _Doc:
    """Where each element comes from (file and line), and the reading helpers."""

    def __init__(self, name: str, lines: dict[int, int]):
        self.name = name
        self.lines = lines
        self.files: dict[int, str] = {}
        self.included_bytes = 0
        self.includes = 0

    def where(self, elem) -> str:
        label = f"<{elem.tag}" + (f" name={elem.get('name')!r}" if elem.get("name") is not None else "") + ">"
        return f"{self.files.get(id(elem), self.name)}: {label} (line {self.lines.get(id(elem), '?')})"

    def floats(self, elem, attrs: dict, key: str, n, default=None) -> np.ndarray:
        """``n`` numbers (an int, or a (min, max) range of counts) of attribute ``key``."""
        raw = attrs.get(key)
        if raw is None:
            if default is None:
                raise ModelError(f"{self.where(elem)}: missing attribute {key!r}")
            return np.asarray(default, dtype=float)
        lo, hi = (n, n) if isinstance(n, int) else n
        try:
            vals = np.array([float(t) for t in raw.split()], dtype=float)
        except ValueError:
            raise ModelError(f"{self.where(elem)}: attribute {key}={raw!r} is not a list of numbers") from None
        if not lo <= vals.size <= hi:
            count = f"{lo}" if lo == hi else f"{lo} to {hi}"
            raise ModelError(f"{self.where(elem)}: attribute {key}={raw!r} needs {count} number(s)")
        if not np.all(np.isfinite(vals)):
            raise ModelError(f"{self.where(elem)}: attribute {key}={raw!r} is not finite")
        return vals

    def number(self, elem, attrs, key, default) -> float:
        return float(self.floats(elem, attrs, key, 1, None if default is None else (default,))[0])

    def flag(self, elem, attrs, key, default, choices=("true", "false")) -> str:
        raw = attrs.get(key, default)
        if raw not in choices:
            raise ModelError(f"{self.where(elem)}: attribute {key}={raw!r} must be one of {list(choices)}")
        return raw


def load_mjcf(source, *, physical: str = "error", mimic: str = "couple") -> Model | CoupledModel:
    """Load an MJCF file (path) or XML string into a :class:`Model` (rules in the module
    docstring). Every body tree of ``<worldbody>`` hangs from the fixed world; bodies with a
    free joint are floating bases. ``physical`` as in :func:`~robodyn.io.urdf.load_urdf`.
    The order of bodies and of ``v`` is MuJoCo's (depth first, in file order).

    ``mimic="couple"`` (default): a linear ``<equality><joint joint1 joint2 polycoef>`` makes
    ``joint1`` follow ``joint2`` exactly (MJCF's mimic joint; MuJoCo enforces it softly), and
    the model is a :class:`~robodyn.coupling.CoupledModel` of the independent joints, as
    :func:`~robodyn.io.urdf.load_urdf` reads ``<mimic>``. ``mimic="independent"``: every joint
    is a degree of freedom (the equalities are ignored, with a warning naming them)."""
    if mimic not in ("couple", "independent"):
        raise ValueError(f"mimic must be 'couple' or 'independent', got {mimic!r}")
    root, doc, reader = _read_tree(source)
    name, ignored = doc.name, reader.ignored
    for elem in root:
        if isinstance(elem.tag, str) and elem.tag not in _TOP_READ | _TOP_SILENT:
            ignored[elem.tag] += 1
    b = ModelBuilder(root.get("model", "mujoco"), gravity=_read_gravity(root, doc), source=name, physical=physical)
    reader.build(b)
    couplings = _joint_equalities(root, doc, reader, ignored)
    notes = []
    if couplings and mimic == "independent":
        notes.append(f"joint equalities loaded as independent joints (mimic='independent'): "
                     f"{[c[0] for c in couplings]}")
    if ignored:
        notes.append("ignored elements that are not the rigid-body dynamics of the tree: "
                     + ", ".join(f"{n} <{k}>" for k, n in sorted(ignored.items())))
    for what, names in reader.unmodelled.items():
        if names:
            notes.append(f"{what} not modelled: {names}")
    if notes:
        warnings.warn(f"{name}: " + "; ".join(notes), RobodynWarning, stacklevel=2)
    model = b.build()
    return CoupledModel(model, couplings) if couplings and mimic == "couple" else model


def _read_tree(source, visuals: bool = False):
    """``(root, doc, reader)``: the parsed file (includes expanded) and its body tree read;
    with ``visuals`` the reader also collects the drawable geoms (:func:`read_mjcf_visuals`)."""
    text, name = read_source(source, "MJCF", MAX_FILE_BYTES)
    root, lines = parse(text, name)
    doc = _Doc(name, lines)
    if root.tag != "mujoco":
        raise ModelError(f"{doc.where(root)}: root element must be <mujoco>, got <{root.tag}>")
    base = None if is_xml_text(source) or isinstance(source, bytes) else Path(name).parent
    _expand_includes(root, doc, base, [name])
    reader = _Bodies(doc, _read_compiler(root, doc), _read_defaults(root, doc), Counter())
    if visuals:
        reader.visuals = _Visuals(root, doc, reader, Path.cwd() if base is None else base)
    worlds = root.findall("worldbody")
    for world in worlds if visuals else ():  # the world's geoms come first in MuJoCo's order
        reader.visuals.collect(world, "world", (np.eye(3), np.zeros(3)), "main")
    for world in worlds:
        reader.children(world, "world", (np.eye(3), np.zeros(3)), "main", world=True)
    return root, doc, reader


class GeomVisual(NamedTuple):
    """One drawable ``<geom>`` of an MJCF file: ``link`` the body it belongs to (``"world"``
    for the ``<worldbody>``'s own), ``index`` its geom number in MuJoCo's model (``mjModel``'s
    geom id: every geom in body order), ``name`` its name or ``<link>_<k>`` (k: its place
    among the link's drawn geoms; ``_1``, ``_2``, ... appended to a name the file uses),
    ``kind`` one of ``sphere``, ``capsule``, ``cylinder``, ``box``, ``ellipsoid``, ``mesh``,
    ``size`` as the viewer takes it (``(radius,)``; ``(radius, length)`` along z, a capsule's
    between its sphere centres; a box's three edges; an ellipsoid's semi-axes; ``()`` for a
    mesh), ``filename`` the mesh file (None for the others), ``R`` (3, 3), ``p`` (3,) the geom
    frame in the link frame, ``scale`` (3,) the mesh's, ``rgba`` (4,) the colour MuJoCo draws
    or None (neither an rgba nor a material: MuJoCo's grey 0.5 0.5 0.5 1, the viewer's
    default), ``where`` file and line."""
    link: str
    index: int
    name: str
    kind: str
    size: tuple
    filename: str | None
    R: np.ndarray
    p: np.ndarray
    scale: np.ndarray
    rgba: np.ndarray | None
    where: str


def read_mjcf_visuals(source) -> list[GeomVisual]:
    """The geoms MuJoCo draws by default (``group`` 0, 1 or 2, not transparent) of an MJCF
    file (path) or XML string, on the bodies :func:`load_mjcf` reads, in MuJoCo's geom order
    (planes, the ground, left out). Mesh files come from ``<asset><mesh file scale>`` in the
    ``<compiler>``'s ``meshdir`` or ``assetdir`` (the last given, as MuJoCo reads them; the
    file's folder part dropped with ``strippath``), relative to the file's folder. Colours as
    MuJoCo's viewer: a ``<material>``'s ``rgba`` (white by default) unless the geom's own
    ``rgba`` (its class's) differs from the default 0.5 0.5 0.5 1. Height fields, SDFs and
    primitives fitted to a mesh are not drawn; they and a geom that cannot be drawn (a mesh
    without a file, an unknown mesh) are left out with one :class:`RobodynWarning` naming
    them. Errors of the body tree are the loader's."""
    _, doc, reader = _read_tree(source, visuals=True)
    v = reader.visuals
    if v.skipped:
        warnings.warn(f"{doc.name}: geoms not drawn: " + "; ".join(v.skipped), RobodynWarning, stacklevel=2)
    return v.out


class _Visuals:
    """Collects a body's drawable geoms while :class:`_Bodies` walks the tree."""

    DEFAULT_GROUPS = (0, 1, 2)  # the groups MuJoCo's viewer shows at start

    def __init__(self, root, doc: _Doc, reader, base: Path):
        self.doc, self.reader, self.out, self.skipped, self.count = doc, reader, [], [], 0
        self.taken = {g.get("name") for g in root.iter("geom") if g.get("name")}  # the file's own names
        self.drawn: Counter = Counter()  # drawn geoms per link, for the generated names
        mesh_dir, strip = "", False
        for e in root.findall("compiler"):  # in order, as MuJoCo; a meshdir overrides its assetdir
            mesh_dir = e.get("meshdir", e.get("assetdir", mesh_dir))
            if "strippath" in e.attrib:
                strip = doc.flag(e, e.attrib, "strippath", "false") == "true"
        self.meshes, self.materials = {}, {}
        for m in (m for asset in root.findall("asset") for m in asset if m.tag in ("mesh", "material")):
            try:
                a = reader.attrs(m, "main")
                if m.tag == "material" and m.get("name"):  # MuJoCo's material colour is white by default
                    self.materials[m.get("name")] = doc.floats(m, a, "rgba", 4, (1.0, 1.0, 1.0, 1.0))
                elif m.tag == "mesh" and "file" in a:  # (vertices in the XML itself are not read)
                    file = Path(re.split(r"[/\\]", a["file"])[-1] if strip else a["file"])
                    self.meshes[m.get("name") or file.stem] = (base / mesh_dir / file,
                                                               doc.floats(m, a, "scale", 3, (1.0, 1.0, 1.0)))
            except ModelError as e:  # its geoms are then named as not drawn
                self.skipped.append(str(e))

    def collect(self, elem, link: str, pre, cls: str) -> None:
        """The geoms of body (or frame) ``elem`` whose frame sits at ``pre`` in ``link``'s."""
        for g in elem:
            if g.tag == "frame":
                a = self.reader.attrs(g, cls)
                self.collect(g, link, _compose(pre, self.reader.pose(g, a)), g.get("childclass", cls))
            elif g.tag == "geom":
                index, self.count = self.count, self.count + 1
                try:
                    self.geom(g, self.reader.attrs(g, cls), link, pre, index)
                except ModelError as e:
                    self.skipped.append(str(e))

    def geom(self, g, a, link: str, pre, index: int) -> None:
        doc = self.doc
        kind = a.get("type", "sphere")
        if min(max(int(doc.number(g, a, "group", 0)), 0), 5) not in self.DEFAULT_GROUPS:  # clamped as MuJoCo
            return
        if kind == "plane":
            return  # the ground: a viewer draws its own
        if kind not in ("sphere", "capsule", "cylinder", "box", "ellipsoid", "mesh"):
            raise ModelError(f"{doc.where(g)}: type {kind!r}")
        if kind != "mesh" and "mesh" in a:
            raise ModelError(f"{doc.where(g)}: a {kind} fitted to mesh {a['mesh']!r} (sized from the mesh)")
        size = np.zeros(3)
        if kind != "mesh":
            given = doc.floats(g, a, "size", (1, 3), (0.0,))
            size[: given.size] = given
        if "fromto" in a and kind != "mesh":
            pose, half = self.reader.fromto(g, a)
            size[1:] = (size[0], half) if kind in ("box", "ellipsoid") else (half, 0.0)
        else:
            pose = self.reader.pose(g, a)
        filename, scale = None, np.ones(3)
        if kind == "mesh":
            if a.get("mesh") not in self.meshes:
                raise ModelError(f"{doc.where(g)}: mesh {a.get('mesh')!r} is not an <asset> mesh with a file")
            path, scale = self.meshes[a["mesh"]]
            filename = str(path)
        shape = {"sphere": (size[0],), "capsule": (size[0], 2 * size[1]), "cylinder": (size[0], 2 * size[1]),
                 "box": tuple(2 * size), "ellipsoid": tuple(size), "mesh": ()}[kind]
        if any(not x > 0 for x in shape):
            raise ModelError(f"{doc.where(g)}: size {shape} is not positive")
        rgba = self.colour(g, a)
        if rgba is not None and rgba[3] == 0:
            return  # MuJoCo does not draw a transparent geom
        R, p = _compose(pre, pose)
        k, self.drawn[link] = self.drawn[link], self.drawn[link] + 1
        self.out.append(GeomVisual(link, index, g.get("name") or self.generated_name(link, k), kind, shape,
                                   filename, R, p, np.asarray(scale, dtype=float), rgba, doc.where(g)))

    def colour(self, g, a) -> np.ndarray | None:
        """MuJoCo's (``setMaterial``): the material's rgba unless the geom's own differs from
        the default 0.5 0.5 0.5 1; None for neither (the viewer's default colour)."""
        own = self.doc.floats(g, a, "rgba", 4) if "rgba" in a else None
        if a.get("material") not in self.materials:
            return own
        if own is not None and (own.astype(np.float32) != _DEFAULT_RGBA).any():  # compared as MuJoCo's floats
            return own
        return self.materials[a["material"]]

    def generated_name(self, link: str, k: int) -> str:
        """``<link>_<k>`` (``_1``, ``_2``, ... appended while the file or an earlier geom uses it)."""
        name, n = f"{link}_{k}", 0
        while name in self.taken:
            n += 1
            name = f"{link}_{k}_{n}"
        self.taken.add(name)
        return name


def _joint_equalities(root, doc: _Doc, reader: _Bodies, ignored: Counter) -> list[tuple]:
    """The linear joint equalities of ``<equality>`` as mimic couplings ``(joint, source,
    multiplier, offset)``: MuJoCo's ``y - y0 = a0 + a1 (x - x0) + a2 (x - x0)^2 + ...`` (``y``
    joint1, ``x`` joint2, ``y0``, ``x0`` their ``ref``; robodyn's ``q`` is ``qpos``) with
    ``a2 = a3 = a4 = 0`` is ``q_y = a1 q_x + (y0 + a0 - a1 x0)``. Inactive ones, those without
    ``joint2`` (a joint locked at a value), polynomial ones and the other kinds (``connect``,
    ``weld``, ``tendon``, ``flex``) are counted in ``ignored`` (``equality/<kind>``)."""
    out, named = [], reader.named
    for group in root.findall("equality"):
        for e in group:
            if not isinstance(e.tag, str):
                continue
            a = reader.attrs(e, "main", "equality")
            if e.tag != "joint" or doc.flag(e, a, "active", "true") == "false":
                ignored[f"equality/{e.tag}" + (" (inactive)" if e.tag == "joint" else "")] += 1
                continue
            y, x = a.get("joint1"), a.get("joint2")
            for key, joint in (("joint1", y), ("joint2", x)):
                if joint is not None and (joint not in named or named[joint][0] not in ("hinge", "slide")):
                    raise ModelError(f"{doc.where(e)}: {key}={joint!r} is not a named hinge or slide joint "
                                     f"of the model")
            if y is None:
                raise ModelError(f"{doc.where(e)}: missing attribute 'joint1'")
            c = doc.floats(e, a, "polycoef", 5, (0.0, 1.0, 0.0, 0.0, 0.0))
            if x is None or np.any(c[2:] != 0):
                ignored["equality/joint (" + ("a locked joint" if x is None else "polynomial") + ")"] += 1
                continue
            out.append((y, x, float(c[1]), float(named[y][1] + c[0] - c[1] * named[x][1])))
    return out


# --------------------------------------------------------------------------------------------
# document level: includes, compiler, option, defaults
# --------------------------------------------------------------------------------------------

def _expand_includes(elem, doc: _Doc, base: Path | None, stack: list[str]) -> None:
    """Replace every ``<include file>`` below ``elem`` by the children of the included
    ``<mujoco>`` (recursively), with cycles, count and total size bounded."""
    for k, child in enumerate(list(elem)):
        if child.tag != "include":
            if isinstance(child.tag, str):
                _expand_includes(child, doc, base, stack)
            continue
        where = doc.where(child)
        file = child.get("file")
        if not file:
            raise ModelError(f"{where}: missing attribute 'file'")
        if base is None:
            raise ModelError(f"{where}: <include> in XML text: load the model from its file")
        path = base / file
        if str(path) in stack:
            raise ModelError(f"{where}: {path} includes itself (through {' -> '.join(stack)})")
        doc.includes += 1
        if doc.includes > MAX_INCLUDES:
            raise ModelError(f"{where}: more than {MAX_INCLUDES} included files")
        text, name = read_source(path, "MJCF", MAX_FILE_BYTES - doc.included_bytes)
        doc.included_bytes += len(text)
        sub, lines = parse(text, name)
        if sub.tag != "mujoco":
            raise ModelError(f"{name}: root element of an included file must be <mujoco>, got <{sub.tag}>")
        doc.lines.update(lines)
        for e in sub.iter():
            doc.files[id(e)] = name
        _expand_includes(sub, doc, base, stack + [str(path)])
        elem.remove(child)
        for j, inc in enumerate(list(sub)):
            elem.insert(k + j, inc)
    # children inserted above were expanded inside their own file


def _read_compiler(root, doc: _Doc) -> _Compiler:
    c = _Compiler()
    for e in root.findall("compiler"):
        a = e.attrib
        if "coordinate" in a and a["coordinate"] != "local":
            raise ModelError(f"{doc.where(e)}: coordinate={a['coordinate']!r}: only local coordinates are supported")
        if "angle" in a:
            c.degree = doc.flag(e, a, "angle", "degree", ("degree", "radian")) == "degree"
        if "eulerseq" in a:
            seq = a["eulerseq"]
            if len(seq) != 3 or any(ch not in "xyzXYZ" for ch in seq):
                raise ModelError(f"{doc.where(e)}: eulerseq={seq!r} must be 3 letters of x, y, z, X, Y, Z")
            c.eulerseq = seq
        for key in ("autolimits", "balanceinertia", "alignfree"):
            if key in a:
                setattr(c, key, doc.flag(e, a, key, "false") == "true")
        if "inertiafromgeom" in a:
            c.inertiafromgeom = doc.flag(e, a, "inertiafromgeom", "auto", ("auto", "true", "false"))
        if "inertiagrouprange" in a:
            g = doc.floats(e, a, "inertiagrouprange", 2)
            c.inertiagrouprange = (int(g[0]), int(g[1]))
        for key in ("boundmass", "boundinertia", "settotalmass"):
            if key in a:
                setattr(c, key, doc.number(e, a, key, 0.0))
    return c


def _read_gravity(root, doc: _Doc) -> np.ndarray:
    g = np.array([0.0, 0.0, -9.81])
    for e in root.findall("option"):
        if "gravity" in e.attrib:
            g = doc.floats(e, e.attrib, "gravity", 3)
        for f in e.findall("flag"):
            if f.get("gravity") == "disable":
                g = np.zeros(3)
    return g


def _read_defaults(root, doc: _Doc) -> dict[str, dict[str, dict[str, str]]]:
    """``{class: {element tag: attributes}}`` with inheritance resolved; the top class is "main"."""
    out: dict[str, dict[str, dict[str, str]]] = {"main": {}}

    def visit(elem, name, inherited):
        own = {t: dict(v) for t, v in inherited.items()}
        for child in elem:
            if isinstance(child.tag, str) and child.tag != "default":
                own[child.tag] = _override(own.get(child.tag, {}), child.attrib)
        out[name] = own
        for child in elem.findall("default"):
            cls = child.get("class")
            if cls is None:
                raise ModelError(f"{doc.where(child)}: a nested <default> needs a class")
            if cls in out:
                raise ModelError(f"{doc.where(child)}: default class {cls!r} defined twice")
            visit(child, cls, own)

    for top in root.findall("default"):
        visit(top, top.get("class", "main"), out["main"])
    return out


def _override(base: dict, own) -> dict:
    """Attributes ``own`` over defaults ``base``, as MuJoCo applies them: an explicit
    orientation replaces the default's, and a ``size`` of fewer numbers keeps the default's
    others."""
    merged = dict(base)
    if any(k in own for k in _ORIENTATIONS):
        for k in _ORIENTATIONS:
            merged.pop(k, None)
    own = dict(own)
    if "size" in own and "size" in merged:
        d, e = merged["size"].split(), own.pop("size").split()
        merged["size"] = " ".join(e + d[len(e):])
    merged.update(own)
    return merged


# --------------------------------------------------------------------------------------------
# the body tree
# --------------------------------------------------------------------------------------------

@dataclass
class _Link:
    name: str
    mass: float = 0.0
    com: np.ndarray = None
    inertia: np.ndarray = None  # about the centre of mass, link axes
    where: str = ""


def _compose(a, b):
    """Pose ``a * b`` of (R, p) pairs."""
    return a[0] @ b[0], a[1] + a[0] @ b[1]


def _axis_rotation(axis, angle) -> np.ndarray:
    """Rotation by ``angle`` about the unit ``axis``."""
    return exp_so3(np.asarray(axis, dtype=float) * angle)


def _z_to(vec) -> np.ndarray:
    """Rotation taking the z axis to the unit vector ``vec`` by the shortest arc (mjuu_z2quat)."""
    axis = np.cross([0.0, 0.0, 1.0], vec)
    s = np.linalg.norm(axis)
    axis = np.array([1.0, 0.0, 0.0]) if s < 1e-10 else axis / s
    return _axis_rotation(axis, np.arctan2(s, vec[2]))


class _Bodies:
    """Walks the body tree, collecting links (with their inertia), joints and frames."""

    def __init__(self, doc: _Doc, compiler: _Compiler, defaults, ignored: Counter):
        self.doc, self.c, self.defaults, self.ignored = doc, compiler, defaults, ignored
        self.links: list[_Link] = [_Link("world", where=f"{doc.name}: <worldbody>")]
        self.joints: list[tuple] = []  # (name, type, parent, child, xyz, R, axis, limits, where)
        self.sites: list[tuple] = []
        self.unmodelled = {"springs of ball and free joints (stiffness)": [], "gravity compensation (gravcomp)": [],
                           "cone limits of ball joints (range)": []}
        self.nbody = 0
        self.njoint = 0
        self.named: dict[str, tuple[str, float]] = {}  # joint named in the file -> (MJCF type, ref in q units)
        self.visuals = None  # a _Visuals when the drawable geoms are read too

    # attributes with defaults -----------------------------------------------------------
    def attrs(self, elem, cls: str, tag: str | None = None) -> dict:
        """``elem``'s attributes over the defaults of its class (``cls`` unless it names one)
        for its tag (``tag``: another, as ``equality`` for every kind of equality)."""
        cls = elem.get("class", cls)
        if cls not in self.defaults:
            raise ModelError(f"{self.doc.where(elem)}: unknown default class {cls!r}")
        return _override(self.defaults[cls].get(tag or elem.tag, {}), elem.attrib)

    def rotation(self, elem, a) -> np.ndarray:
        doc, given = self.doc, [k for k in _ORIENTATIONS if k in a]
        if len(given) > 1:
            raise ModelError(f"{doc.where(elem)}: several orientations given ({', '.join(given)})")
        if not given:
            return np.eye(3)
        kind = given[0]
        unit = np.pi / 180 if self.c.degree else 1.0
        if kind == "quat":
            q = doc.floats(elem, a, "quat", 4)
            n = np.linalg.norm(q)
            if n < _EPS:
                raise ModelError(f"{doc.where(elem)}: quat is zero")
            return quat_matrix(np.r_[q[1:], q[0]] / n)
        if kind == "axisangle":
            v = doc.floats(elem, a, "axisangle", 4)
            n = np.linalg.norm(v[:3])
            if n < _EPS:
                raise ModelError(f"{doc.where(elem)}: axisangle axis is zero")
            return _axis_rotation(v[:3] / n, v[3] * unit)
        if kind == "euler":
            e = doc.floats(elem, a, "euler", 3) * unit
            R = np.eye(3)
            for ch, angle in zip(self.c.eulerseq, e):  # lower case: about the turned axes
                Ri = _axis_rotation(np.eye(3)["xyz".index(ch.lower())], angle)
                R = R @ Ri if ch.islower() else Ri @ R
            return R
        if kind == "xyaxes":
            v = doc.floats(elem, a, "xyaxes", 6)
            x, y = v[:3], v[3:]
            if np.linalg.norm(x) < _EPS:
                raise ModelError(f"{doc.where(elem)}: xyaxes: x axis is zero")
            x = x / np.linalg.norm(x)
            y = y - x * (x @ y)
            if np.linalg.norm(y) < _EPS:
                raise ModelError(f"{doc.where(elem)}: xyaxes: y axis is parallel to x")
            y = y / np.linalg.norm(y)
            return np.column_stack([x, y, np.cross(x, y)])
        z = doc.floats(elem, a, "zaxis", 3)
        if np.linalg.norm(z) < _EPS:
            raise ModelError(f"{doc.where(elem)}: zaxis is zero")
        return _z_to(z / np.linalg.norm(z))

    def pose(self, elem, a):
        """The frame of ``elem`` in its parent's frame (``fromto`` for geoms and sites)."""
        if "fromto" in a and elem.tag in ("geom", "site"):
            return self.fromto(elem, a)[0]
        return self.rotation(elem, a), self.doc.floats(elem, a, "pos", 3, (0.0, 0.0, 0.0))

    def fromto(self, elem, a):
        """``((R, p), half length)`` of a ``fromto`` segment: centred, z from the end to the start."""
        ft = self.doc.floats(elem, a, "fromto", 6)
        vec = ft[:3] - ft[3:]
        half = np.linalg.norm(vec) / 2
        if half < _EPS:
            raise ModelError(f"{self.doc.where(elem)}: fromto points too close")
        return (_z_to(vec / (2 * half)), (ft[:3] + ft[3:]) / 2), half

    # the tree -----------------------------------------------------------------------------
    def children(self, elem, link: str, pre, cls: str, world: bool = False) -> None:
        """Read the children of a body (or frame) ``elem``, whose frame sits at ``pre`` in
        ``link``'s frame; ``world`` when ``link`` is welded to the world."""
        for child in elem:
            tag = child.tag
            if not isinstance(tag, str) or tag in ("joint", "freejoint", "inertial", "geom"):
                continue  # read with their body
            if tag == "body":
                self.body(child, link, pre, cls, world)
            elif tag == "frame":
                a = self.attrs(child, cls)
                self.children(child, link, _compose(pre, self.pose(child, a)), child.get("childclass", cls), world)
            elif tag == "site":
                name = child.get("name")
                if name:
                    self.sites.append((name, link, _compose(pre, self.pose(child, self.attrs(child, cls))),
                                       self.doc.where(child)))
            elif tag in _GENERATORS:
                raise ModelError(f"{self.doc.where(child)}: <{tag}> (generated bodies) is not supported")
            elif tag not in _BODY_SILENT:
                self.ignored[tag] += 1

    def body(self, elem, parent: str, pre, cls: str, world: bool) -> None:
        doc = self.doc
        self.nbody += 1
        name = elem.get("name") or f"body{self.nbody}"
        cls = elem.get("childclass", cls)
        a = dict(elem.attrib)
        if float(a.get("gravcomp", 0) or 0) != 0:
            self.unmodelled["gravity compensation (gravcomp)"].append(name)
        frame = _compose(pre, self.pose(elem, a))  # the body frame in the parent link's frame
        joints = [j for j in elem if j.tag in ("joint", "freejoint")]
        link, types = parent, []
        for k, j in enumerate(joints):
            ja = self.attrs(j, cls) if j.tag == "joint" else dict(j.attrib, type="free")
            types.append(ja.get("type", "hinge"))
            self.njoint += 1
            jname = ja.get("name") or f"joint{self.njoint}"
            jtype = ja.get("type", "hinge")
            where = doc.where(j)
            if jtype not in ("hinge", "slide", "ball", "free"):
                raise ModelError(f"{where}: unknown joint type {jtype!r}")
            child = name if k == len(joints) - 1 else f"{name}:{jname}"
            if jtype == "free":
                if len(joints) > 1:
                    raise ModelError(f"{where}: a free joint must be the only joint of its body")
                if not world:
                    raise ModelError(f"{where}: a free joint must be in a body whose parent is the world")
                self.links.append(_Link(child, where=doc.where(elem)))
                self.joints.append((jname, "free", link, child, np.zeros(3), np.eye(3), np.zeros(3),
                                    self.joint_options(j, ja, jtype), where))
                frame = (np.eye(3), np.zeros(3))
            elif jtype == "ball":  # F Trans(p) Rot(quat) Trans(-p)
                anchor = doc.floats(j, ja, "pos", 3, (0.0, 0.0, 0.0))
                place = _compose(frame, (np.eye(3), anchor))
                self.links.append(_Link(child, where=doc.where(elem)))
                self.joints.append((jname, "spherical", link, child, place[1], place[0], np.zeros(3),
                                    self.joint_options(j, ja, jtype), where))
                frame = (np.eye(3), -anchor)
            else:
                axis = doc.floats(j, ja, "axis", 3, (0.0, 0.0, 1.0))
                if np.linalg.norm(axis) < _EPS:
                    raise ModelError(f"{where}: joint axis is zero")
                axis = axis / np.linalg.norm(axis)
                anchor = doc.floats(j, ja, "pos", 3, (0.0, 0.0, 0.0))
                ref = doc.number(j, ja, "ref", 0.0) * (np.pi / 180 if jtype == "hinge" and self.c.degree else 1.0)
                if j.get("name"):
                    self.named[j.get("name")] = (jtype, ref)
                if jtype == "hinge":  # F Trans(p) Rot(a, q - ref) = [F Trans(p) Rot(a, -ref)] Rot(a, q)
                    place = _compose(frame, (_axis_rotation(axis, -ref), anchor))
                else:  # F Trans(p + a (q - ref)) = [F Trans(p - a ref)] Trans(a q)
                    place = _compose(frame, (np.eye(3), anchor - axis * ref))
                self.links.append(_Link(child, where=doc.where(elem)))
                self.joints.append((jname, "revolute" if jtype == "hinge" else "prismatic", link, child,
                                    place[1], place[0], axis, self.joint_options(j, ja, jtype), where))
                frame = (np.eye(3), -anchor)  # the body frame in the new link's frame
            if jtype in ("free", "ball") and float(ja.get("stiffness", 0) or 0) != 0:
                self.unmodelled["springs of ball and free joints (stiffness)"].append(jname)
            if jtype == "ball" and self.limited(j, ja):  # a cone on the rotation angle, not a box on dofs
                self.unmodelled["cone limits of ball joints (range)"].append(jname)
            link = child
        if not joints:  # welded to the parent
            self.links.append(_Link(name, where=doc.where(elem)))
            self.joints.append((f"{name}:weld", "fixed", parent, name, frame[1], frame[0], np.zeros(3), {},
                                doc.where(elem)))
            link, frame = name, (np.eye(3), np.zeros(3))
        self.inertia(elem, cls, self.links[-1], frame, any(t == "free" for t in types))
        if self.visuals is not None:
            self.visuals.collect(elem, link, frame, cls)
        self.children(elem, link, frame, cls, world and not joints)

    def limited(self, elem, a) -> bool:
        """Whether joint ``elem`` has its ``range`` on (``limited``, or ``auto`` with
        ``<compiler autolimits="true">`` and a range given)."""
        limited = self.doc.flag(elem, a, "limited", "auto", ("true", "false", "auto"))
        return limited == "true" or (limited == "auto" and self.c.autolimits and "range" in a)

    def joint_options(self, elem, a, jtype: str) -> dict:
        doc = self.doc
        out = {}
        for key, field in (("armature", "armature"), ("damping", "damping"), ("frictionloss", "friction")):
            out[field] = doc.number(elem, a, key, 0.0)
        if jtype in ("free", "ball"):
            return out  # a ball joint's range is a cone: not a box on the dofs
        # the spring torque -stiffness (qpos - springref); robodyn's q is MuJoCo's qpos
        out["stiffness"] = doc.number(elem, a, "stiffness", 0.0)
        out["spring_reference"] = doc.number(elem, a, "springref", 0.0) * (
            np.pi / 180 if jtype == "hinge" and self.c.degree else 1.0)
        if self.limited(elem, a):
            lo, hi = doc.floats(elem, a, "range", 2, (0.0, 0.0)) * (np.pi / 180 if jtype == "hinge" and self.c.degree else 1.0)
            if lo >= hi:
                raise ModelError(f"{doc.where(elem)}: range {a.get('range')!r} must have min < max")
            out["lower"], out["upper"] = lo, hi
        return out

    # inertia ----------------------------------------------------------------------------------
    def inertia(self, elem, cls: str, link: _Link, frame, free: bool) -> None:
        """Mass, centre of mass and inertia (about the centre of mass) of the MuJoCo body
        ``elem`` in ``link``'s frame (the body frame sits at ``frame`` in it)."""
        doc, c = self.doc, self.c
        inertials = elem.findall("inertial")
        if len(inertials) > 1:
            raise ModelError(f"{doc.where(inertials[1])}: more than one <inertial>")
        mass, pos, I = 0.0, np.zeros(3), np.zeros((3, 3))
        if inertials:
            e = inertials[0]
            a = e.attrib
            mass = doc.number(e, a, "mass", None)
            pos = doc.floats(e, a, "pos", 3)
            if "fullinertia" in a:
                if any(k in a for k in _ORIENTATIONS) or "diaginertia" in a:
                    raise ModelError(f"{doc.where(e)}: fullinertia excludes diaginertia and orientations")
                f = doc.floats(e, a, "fullinertia", 6)
                I = np.array([[f[0], f[3], f[4]], [f[3], f[1], f[5]], [f[4], f[5], f[2]]])
            else:
                R = self.rotation(e, a)
                I = R @ np.diag(doc.floats(e, a, "diaginertia", 3)) @ R.T
        if c.inertiafromgeom == "true" or (c.inertiafromgeom == "auto" and not inertials):
            mass, pos, I = self.geom_inertia(elem, cls) or (mass, pos, I)  # no geoms: as it was
        if mass < 0:
            raise ModelError(f"{doc.where(elem)}: negative mass {mass}")
        if c.boundmass > 0 or c.boundinertia > 0 or c.balanceinertia:
            d, V = np.linalg.eigh(I)
            mass = max(mass, c.boundmass)
            d = np.maximum(d, c.boundinertia)
            if c.balanceinertia and (d[0] + d[1] < d[2]):
                d[:] = d.sum() / 3
            I = V @ np.diag(d) @ V.T
        if free and c.alignfree:
            raise ModelError(f"{doc.where(elem)}: alignfree (a free body frame moved to its inertia) is not supported")
        R, p = frame
        link.mass, link.com, link.inertia = mass, p + R @ pos, R @ I @ R.T

    def geom_inertia(self, body, cls: str):
        """MuJoCo's inertia from geoms (``mjCGeom::SetInertia``, solid bodies): ``(mass, com,
        inertia about the com)`` in the body frame, or None when no geom has mass."""
        doc, lo_hi = self.doc, self.c.inertiagrouprange
        parts = []

        def collect(elem, pre, cls):
            for g in elem:
                if g.tag == "frame":
                    a = self.attrs(g, cls)
                    collect(g, _compose(pre, self.pose(g, a)), g.get("childclass", cls))
                elif g.tag == "geom":
                    a = self.attrs(g, cls)
                    group = int(doc.number(g, a, "group", 0))
                    if lo_hi[0] <= group <= lo_hi[1]:
                        part = self.geom(g, a)
                        if part is not None:
                            parts.append((part[0], _compose(pre, part[1]), part[2]))

        collect(body, (np.eye(3), np.zeros(3)), cls)
        parts = [p for p in parts if p[0] > _EPS]
        if not parts:
            return None
        mass = sum(p[0] for p in parts)
        com = sum(m * pose[1] for m, pose, _ in parts) / mass
        I = np.zeros((3, 3))
        for m, (R, p), d in parts:
            r = p - com
            I += R @ np.diag(d) @ R.T + m * (r @ r * np.eye(3) - np.outer(r, r))
        return mass, com, I

    def geom(self, g, a):
        """``(mass, (R, p), principal moments)`` of one geom in its body's frame, or None."""
        doc = self.doc
        gtype = a.get("type", "sphere")
        where = doc.where(g)
        if gtype in ("mesh", "sdf", "hfield") or ("mesh" in a and gtype != "plane"):
            raise ModelError(f"{where}: inertia from a {gtype} geom is not supported; give the body an <inertial>")
        if a.get("shellinertia", "false") == "true":
            raise ModelError(f"{where}: shell inertia is not supported")
        if gtype not in ("sphere", "capsule", "cylinder", "box", "ellipsoid", "plane"):
            raise ModelError(f"{where}: unknown geom type {gtype!r}")
        size = np.zeros(3)
        given = doc.floats(g, a, "size", (1, 3), (0.0,))
        size[: given.size] = given
        if "fromto" in a:
            if gtype not in ("capsule", "cylinder", "ellipsoid", "box"):
                raise ModelError(f"{where}: fromto needs a capsule, cylinder, box or ellipsoid")
            pose, half = self.fromto(g, a)
            if gtype in ("ellipsoid", "box"):
                size[2], size[1] = half, size[0]
            else:
                size[1] = half
        else:
            pose = self.pose(g, a)
        r, h = size[0], 2 * size[1]
        volume = {
            "sphere": 4 * np.pi * r ** 3 / 3,
            "capsule": np.pi * (r * r * h + 4 * r ** 3 / 3),
            "cylinder": np.pi * r * r * h,
            "ellipsoid": 4 * np.pi * size[0] * size[1] * size[2] / 3,
            "box": 8 * size[0] * size[1] * size[2],
            "plane": 0.0,
        }[gtype]
        if "mass" in a:
            mass = doc.number(g, a, "mass", 0.0)
            if mass != 0 and volume <= _EPS:
                return None
        else:
            mass = doc.number(g, a, "density", 1000.0) * volume
        if mass < 0:
            raise ModelError(f"{where}: negative mass or density")
        if mass == 0:
            return None
        s = size * size
        if gtype == "sphere":
            d = np.full(3, 2 * mass * r * r / 5)
        elif gtype == "capsule":
            ms = mass * 4 * r / (4 * r + 3 * h)  # the two hemispheres
            mc = mass - ms
            axial = mc * (3 * r * r + h * h) / 12 + 2 * ms * r * r / 5 + ms * h * (3 * r + 2 * h) / 8
            d = np.array([axial, axial, mc * r * r / 2 + 2 * ms * r * r / 5])
        elif gtype == "cylinder":
            axial = mass * (3 * r * r + h * h) / 12
            d = np.array([axial, axial, mass * r * r / 2])
        elif gtype == "ellipsoid":
            d = mass * np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]]) / 5
        else:
            d = mass * np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]]) / 3
        return mass, pose, d

    # into the builder ------------------------------------------------------------------------
    def build(self, b: ModelBuilder) -> None:
        scale = 1.0
        total = sum(k.mass for k in self.links[1:])
        if self.c.settotalmass > 0 and total > 0:
            scale = self.c.settotalmass / total
        names = set()
        for k in self.links:
            names.add(k.name)
            if k.com is None:
                b.add_link(k.name, where=k.where)
            else:
                b.add_link(k.name, mass=k.mass * scale, com=k.com, inertia=k.inertia * scale, where=k.where)
        for name, jtype, parent, child, xyz, R, axis, options, where in self.joints:
            b.add_joint(name, jtype, parent, child, xyz=xyz, rotation=R, axis=axis if jtype != "fixed" else (1, 0, 0),
                        where=where, **options)
        for name, link, (R, p), where in self.sites:
            label = name if name not in names else f"site:{name}"
            names.add(label)
            b.add_link(label, where=where)
            b.add_joint(f"{label}:site", "fixed", link, label, xyz=p, rotation=R, where=where)
