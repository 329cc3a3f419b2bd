"""URDF loader: ``load_urdf(path_or_xml_string, floating_base=False) -> Model``.

Reads links (``<inertial>`` with origin xyz/rpy applied as ``R I R^T``), and joints of type
revolute, continuous, prismatic and fixed (merged into the parent body), with ``<origin>``,
``<axis>`` (normalised; zero is an error), ``<limit lower upper velocity effort>`` (lower and
upper default to 0 as in the URDF specification; a joint without ``<limit>`` is unbounded,
continuous joints always are), ``<dynamics damping friction>``.
``<mimic>`` joints load as independent joints with a warning. Elements without rigid-body
dynamics (material, gazebo, transmission, joint calibration and safety_controller, ...) are
reported in one :class:`RobodynWarning` per file; link geometry (visual, collision) is not
dynamics and is skipped without a warning.

XML is parsed with DTDs, entities and external references forbidden (defusedxml). Every
error is a :class:`~robodyn.model.ModelError` naming the file, the element and its line.
Files are limited to ``MAX_FILE_BYTES`` bytes and ``MAX_DEPTH`` levels of nesting.
"""

from __future__ import annotations

import os
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
from defusedxml import DefusedXmlException, DTDForbidden
from defusedxml.ElementTree import DefusedXMLParser, ParseError

from ..builder import ModelBuilder, rpy_to_matrix
from ..errors import ModelError, RobodynWarning
from ..model import Model

MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_DEPTH = 64


class _LineParser(DefusedXMLParser):
    """DefusedXMLParser that records the line of every element and bounds the nesting."""

    def __init__(self):
        super().__init__(forbid_dtd=True, forbid_entities=True, forbid_external=True)
        self.lines: dict[int, int] = {}
        self._depth = 0

    def _start(self, tag, attr_list):
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise ModelError(
                f"<{tag}> (line {self.parser.CurrentLineNumber}): elements nested deeper than {MAX_DEPTH} levels"
            )
        elem = super()._start(tag, attr_list)
        self.lines[id(elem)] = self.parser.CurrentLineNumber
        return elem

    def _end(self, tag):
        self._depth -= 1
        return super()._end(tag)


def _read_source(source) -> tuple[str, str]:
    """``(xml_text, name)`` from a path or an XML string."""
    if isinstance(source, str) and not source.strip():
        raise ModelError("<string>: empty input: expected a URDF path or XML text")
    if isinstance(source, (str, os.PathLike)) and not (isinstance(source, str) and source.lstrip("\ufeff \t\r\n").startswith("<")):
        path = Path(source)
        try:
            is_file = path.is_file()
            size = path.stat().st_size if is_file else 0
        except (OSError, ValueError) as e:
            raise ModelError(f"{path}: cannot read URDF file ({getattr(e, 'strerror', None) or e})") from None
        if not is_file:
            reason = "not a regular file" if path.exists() else "no such file"
            raise ModelError(f"{path}: cannot read URDF file ({reason})")
        if size > MAX_FILE_BYTES:
            raise ModelError(f"{path}: file of {size} bytes exceeds the limit of {MAX_FILE_BYTES} bytes")
        try:
            return path.read_bytes().decode("utf-8"), str(path)
        except OSError as e:
            raise ModelError(f"{path}: cannot read URDF file ({e.strerror or e})") from None
        except UnicodeDecodeError as e:
            raise ModelError(f"{path}: not UTF-8 text ({e})") from None
    if isinstance(source, bytes):
        source = source.decode("utf-8", errors="strict")
    if not isinstance(source, str):
        raise TypeError(f"load_urdf expects a path or an XML string, got {type(source).__name__}")
    if len(source) > MAX_FILE_BYTES:
        raise ModelError(f"<string>: XML of {len(source)} characters exceeds the limit of {MAX_FILE_BYTES}")
    return source, "<string>"


def _source_line(text: str, line) -> str:
    """The stripped text of a 1-based line (shortened), to show where the XML breaks."""
    lines = text.splitlines()
    if not isinstance(line, int) or not 1 <= line <= len(lines):
        return ""
    snippet = lines[line - 1].strip()
    return f": {snippet[:80] + ('...' if len(snippet) > 80 else '')!r}"


def _parse(text: str, name: str):
    parser = _LineParser()
    try:
        parser.feed(text)
        root = parser.close()
    except ParseError as e:
        line = e.position[0] if getattr(e, "position", None) else "?"
        raise ModelError(f"{name}: line {line}{_source_line(text, line)}: malformed XML ({e})") from None
    except DefusedXmlException as e:
        line = parser.parser.CurrentLineNumber
        if isinstance(e, DTDForbidden):
            what = f"<!DOCTYPE {e.name}>"
        else:
            what = f"<!ENTITY {e.name}>" if hasattr(e, "name") else "external reference"
        raise ModelError(
            f"{name}: {what} (line {line}): forbidden XML construct ({type(e).__name__}); "
            "DTDs and entities are not allowed"
        ) from None
    except ModelError as e:
        raise ModelError(f"{name}: {e}") from None
    except RecursionError:
        raise ModelError(f"{name}: XML nested too deeply") from None
    return root, parser.lines


class _Reader:
    def __init__(self, name: str, lines: dict[int, int]):
        self.name = name
        self.lines = lines

    def where(self, elem, what: str | None = None) -> str:
        label = what or f"<{elem.tag}" + (f" name={elem.get('name')!r}" if elem.get("name") is not None else "") + ">"
        return f"{self.name}: {label} (line {self.lines.get(id(elem), '?')})"

    def floats(self, elem, attr: str, n: int, default=None) -> np.ndarray:
        raw = None if elem is None else elem.get(attr)
        if raw is None:
            if default is None:
                raise ModelError(f"{self.where(elem)}: missing attribute {attr!r}")
            return np.asarray(default, dtype=float)
        try:
            vals = np.array([float(t) for t in raw.split()], dtype=float)
        except ValueError:
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} is not {n} number(s)") from None
        if vals.shape != (n,):
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} needs {n} number(s)")
        if not np.all(np.isfinite(vals)):
            raise ModelError(f"{self.where(elem)}: attribute {attr}={raw!r} is not finite")
        return vals

    def origin(self, parent):
        o = parent.find("origin")
        return self.floats(o, "xyz", 3, (0, 0, 0)), self.floats(o, "rpy", 3, (0, 0, 0))

    def required_child(self, elem, tag: str, attr: str) -> str:
        c = elem.find(tag)
        if c is None or c.get(attr) is None:
            raise ModelError(f"{self.where(elem)}: missing <{tag} {attr}=...>")
        return c.get(attr)


_LINK_IGNORED = {"visual", "collision"}


def load_urdf(source, floating_base: bool = False, gravity=(0.0, 0.0, -9.81), *, physical: str = "error") -> Model:
    """Load a URDF file (path) or XML string into a :class:`Model`.

    ``floating_base=True`` adds a free joint at the root link (q gains 7 entries, v gains 6,
    layout in :mod:`robodyn.model`). Raises :class:`ModelError` for malformed or unphysical
    descriptions; warns (:class:`RobodynWarning`) about what it ignores. Some published URDFs
    carry inertias that no rigid body can have (violating ``I1 + I2 >= I3``, say);
    ``physical="warn"`` loads them as given with a warning naming each such link.

    The children of a link are ordered by joint name (as urdfdom does), so bodies and ``v``
    follow the order Pinocchio gives the same file.
    """
    text, name = _read_source(source)
    root, lines = _parse(text, name)
    rd = _Reader(name, lines)
    if root.tag != "robot":
        raise ModelError(f"{rd.where(root)}: root element must be <robot>, got <{root.tag}>")
    b = ModelBuilder(root.get("name", "robot"), gravity=gravity, source=name, physical=physical)
    ignored: Counter[str] = Counter()
    mimic = []
    joint_elems = []
    for elem in root:
        if not isinstance(elem.tag, str):
            continue
        if elem.tag == "link":
            _read_link(rd, b, elem, ignored)
        elif elem.tag == "joint":
            joint_elems.append(elem)
        else:
            ignored[elem.tag] += 1
    if root.find("link") is None:
        raise ModelError(f"{rd.where(root)}: no <link> element")
    for elem in sorted(joint_elems, key=lambda e: str(e.get("name"))):
        if elem.find("mimic") is not None:
            mimic.append(elem.get("name"))
        _read_joint(rd, b, elem, ignored)
    if mimic:
        warnings.warn(f"{name}: mimic joints loaded as independent joints: {mimic}", RobodynWarning, stacklevel=2)
    ignored_dyn = {k: v for k, v in ignored.items() if k not in _LINK_IGNORED}
    if ignored_dyn:
        summary = ", ".join(f"{n} <{k}>" for k, n in sorted(ignored_dyn.items()))
        warnings.warn(f"{name}: ignored elements without rigid-body dynamics: {summary}", RobodynWarning, stacklevel=2)
    return b.build(floating_base=floating_base)


def _read_link(rd: _Reader, b: ModelBuilder, elem, ignored: Counter) -> None:
    lname = elem.get("name")
    if not lname:
        raise ModelError(f"{rd.where(elem)}: link without a name")
    for child in elem:
        if isinstance(child.tag, str) and child.tag != "inertial":
            ignored[child.tag] += 1
    inertials = elem.findall("inertial")
    if len(inertials) > 1:
        raise ModelError(f"{rd.where(elem)}: more than one <inertial>")
    if not inertials:
        b.add_link(lname, where=rd.where(elem))
        return
    inertial = inertials[0]
    where = rd.where(inertial, f"<link name={lname!r}> <inertial>")
    xyz, rpy = rd.origin(inertial)
    mass_el = inertial.find("mass")
    if mass_el is None:
        raise ModelError(f"{where}: missing <mass value=...>")
    mass = rd.floats(mass_el, "value", 1)[0]
    I_el = inertial.find("inertia")
    if I_el is None:
        I = np.zeros((3, 3))
    else:
        ixx, ixy, ixz, iyy, iyz, izz = (rd.floats(I_el, k, 1, (0.0,))[0] for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
        I = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    b.add_link(lname, mass=mass, com=xyz, inertia=I, inertia_rotation=rpy_to_matrix(rpy), where=where)


_JOINT_READ = {"origin", "parent", "child", "axis", "limit", "dynamics", "mimic"}


def _read_joint(rd: _Reader, b: ModelBuilder, elem, ignored: Counter) -> None:
    where = rd.where(elem)
    for child in elem:
        if isinstance(child.tag, str) and child.tag not in _JOINT_READ:
            ignored[child.tag] += 1
    jname = elem.get("name")
    jtype = elem.get("type")
    if not jname:
        raise ModelError(f"{where}: joint without a name")
    if jtype is None:
        raise ModelError(f"{where}: joint without a type")
    if jtype in ("floating", "planar"):
        raise ModelError(
            f"{where}: joint type {jtype!r} is not supported inside a URDF tree; "
            "use load_urdf(..., floating_base=True) for a free-flying root"
        )
    parent = rd.required_child(elem, "parent", "link")
    child = rd.required_child(elem, "child", "link")
    xyz, rpy = rd.origin(elem)
    axis = rd.floats(elem.find("axis"), "xyz", 3, (1.0, 0.0, 0.0))
    lim = elem.find("limit")
    dyn = elem.find("dynamics")
    kw = {}
    if lim is not None:
        # URDF: lower and upper default to 0 in a <limit> (urdfdom and Pinocchio read it so);
        # without a <limit> element robodyn leaves the joint unbounded.
        for key in ("lower", "upper"):
            kw[key] = rd.floats(lim, key, 1, (0.0,))[0]
        for key in ("velocity", "effort"):
            if lim.get(key) is not None:
                kw[key] = rd.floats(lim, key, 1)[0]
    if dyn is not None:
        for key in ("damping", "friction"):
            if dyn.get(key) is not None:
                kw[key] = rd.floats(dyn, key, 1)[0]
    b.add_joint(jname, jtype, parent, child, xyz=xyz, rpy=rpy, axis=axis, where=where, **kw)
