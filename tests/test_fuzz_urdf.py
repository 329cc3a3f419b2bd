"""Fuzzing the URDF loader: every input ends in a Model or a ModelError, nothing else, within
bounded memory and time.

A fixed-seed subset runs here (Hypothesis with ``derandomize=True``); raise ``FUZZ_EXAMPLES``
for a long campaign: ``FUZZ_EXAMPLES=20000 python -m pytest tests/test_fuzz_urdf.py``.

Bounds per case: the Python heap peak (``tracemalloc``) stays below ``MEMORY_BASE +
MEMORY_PER_BYTE * len(text)``, and the CPU time of the process below ``CPU_SECONDS``. The
time bound is a guard against hangs and super-linear blow-ups (it is two orders of magnitude
above the slowest case seen), not a speed requirement; CPU time, unlike wall-clock time, does
not grow when other processes load the machine.
"""

from __future__ import annotations

import os
import random
import time
import tracemalloc
import warnings
import xml.etree.ElementTree as ET

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn as rd
from conftest import example_robot_urdfs

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "150"))
FUZZ = settings(max_examples=EXAMPLES, derandomize=True, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from(["0", "1", "-1", "1e308", "-1e308", "1e-320", "nan", "inf", "", "abc", "1 2", "0x10"]),
)


MEMORY_BASE = 32 * 2**20
MEMORY_PER_BYTE = 40
CPU_SECONDS = 20.0


def load(text: str):
    """Load ``text``: returns a Model or None for a ModelError; any other exception, or a case
    beyond the memory and time bounds, fails the test."""
    tracemalloc.start()
    start = time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                return rd.load_urdf(text, physical="warn")
            except rd.ModelError:
                return None
    finally:
        cpu = time.process_time() - start
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert peak <= MEMORY_BASE + MEMORY_PER_BYTE * len(text), f"{peak} bytes for {len(text)} characters"
        assert cpu <= CPU_SECONDS, f"{cpu:.1f} s of CPU"


def _num(x) -> str:
    return x if isinstance(x, str) else repr(x)


@st.composite
def random_robot(draw):
    """A random tree of links and joints, often with invalid names, types and numbers."""
    n = draw(st.integers(1, 8))
    names = [draw(st.sampled_from([f"l{i}", f"l{i}", "dup", ""])) for i in range(n)]
    parts = ['<robot name="fuzz">']
    for name in names:
        if draw(st.booleans()):
            vals = [_num(draw(NUMBERS)) for _ in range(7)]
            parts.append(
                f'<link name="{name}"><inertial><origin xyz="{vals[0]} 0 0" rpy="0 {vals[1]} 0"/>'
                f'<mass value="{vals[2]}"/><inertia ixx="{vals[3]}" iyy="{vals[4]}" izz="{vals[5]}" '
                f'ixy="{vals[6]}" ixz="0" iyz="0"/></inertial></link>')
        else:
            parts.append(f'<link name="{name}"/>')
    for i in range(1, n):
        jtype = draw(st.sampled_from(["revolute", "continuous", "prismatic", "fixed", "floating", "planar", "bogus"]))
        parent = names[draw(st.integers(0, n - 1))]
        axis = " ".join(_num(draw(NUMBERS)) for _ in range(3))
        lim = " ".join(f'{k}="{_num(draw(NUMBERS))}"' for k in ("lower", "upper", "effort", "velocity"))
        parts.append(
            f'<joint name="j{draw(st.integers(0, n))}" type="{jtype}"><parent link="{parent}"/>'
            f'<child link="{names[i]}"/><origin xyz="0 0 {_num(draw(NUMBERS))}"/><axis xyz="{axis}"/>'
            f'<limit {lim}/><dynamics damping="{_num(draw(NUMBERS))}"/></joint>')
    parts.append("</robot>")
    return "".join(parts)


@FUZZ
@given(random_robot())
def test_random_robots_load_or_raise_model_error(text):
    load(text)  # any exception other than ModelError fails the test


MUTATIONS = ("delete_attribute", "nan", "huge", "swap_names", "duplicate_element", "delete_element",
             "truncate", "garbage_number", "entity", "external_entity", "entity_expansion", "deep_nesting",
             "cycle", "inflate")

# Declarations that put an entity into a real file (defusedxml must refuse every one).
ENTITIES = {
    "entity": '<!DOCTYPE robot [<!ENTITY e "0.1">]>',
    "external_entity": '<!DOCTYPE robot [<!ENTITY e SYSTEM "file:///etc/passwd">]>',
    "entity_expansion": '<!DOCTYPE robot [<!ENTITY a "0.1 0.1 0.1 0.1 0.1 0.1 0.1 0.1"><!ENTITY b "&a;&a;&a;&a;&a;'
                        '&a;&a;&a;"><!ENTITY e "&b;&b;&b;&b;&b;&b;&b;&b;">]>',
}


def _with_entity(text: str, rng: random.Random, kind: str) -> str:
    """``text`` with an entity declared before ``<robot`` and used in a random attribute."""
    head, sep, body = text.partition("<robot")
    quoted = [i for i in range(len(body)) if body[i] == '"']
    if len(quoted) >= 2:
        k = rng.randrange(len(quoted) // 2) * 2
        body = body[: quoted[k] + 1] + "&e;" + body[quoted[k + 1]:]
    return head + ENTITIES[kind] + sep + body


def mutate(text: str, rng: random.Random, kind: str, size: int = 100_000) -> str:
    """``text`` changed by a mutation of ``kind``; ``size``: the length an inflated file reaches."""
    if kind == "truncate":
        return text[: rng.randrange(len(text))]
    if kind in ENTITIES:
        return _with_entity(text, rng, kind)
    root = ET.fromstring(text)
    if kind == "deep_nesting":  # a random element wrapped in 100 levels (the limit is 64)
        elem = rng.choice(list(root) or [ET.Element("link", name="extra")])
        for _ in range(100):
            wrapper = ET.Element("nest")
            wrapper.append(elem)
            elem = wrapper
        root.append(elem)
        return ET.tostring(root, encoding="unicode")
    if kind == "cycle":  # a joint whose child is the root link, or a link that is its own parent
        joints = root.findall("joint")
        children = {c.get("link") for j in joints for c in j.findall("child")}
        roots = [l.get("name") for l in root.findall("link") if l.get("name") not in children]
        if joints and roots:
            joint = rng.choice(joints)
            for c in joint.findall("child"):
                c.set("link", rng.choice(roots + [p.get("link") for p in joint.findall("parent")]))
        return ET.tostring(root, encoding="unicode")
    if kind == "inflate":  # a large file: the robot's links and joints repeated under new names
        originals = list(root)
        for copy in range(1, 1 + max(1, size // max(1, len(text)))):
            for elem in originals:
                dup = ET.fromstring(ET.tostring(elem))
                for e in dup.iter():
                    for key in ("name", "link"):
                        if key in e.attrib:
                            e.attrib[key] += f"_{copy}"
                root.append(dup)
        return ET.tostring(root, encoding="unicode")
    elems = list(root.iter())
    elem = rng.choice(elems)
    if kind == "delete_attribute" and elem.attrib:
        del elem.attrib[rng.choice(sorted(elem.attrib))]
    elif kind in ("nan", "huge", "garbage_number") and elem.attrib:
        key = rng.choice(sorted(elem.attrib))
        elem.attrib[key] = {"nan": "nan 0 nan", "huge": "1e308 -1e308 1e308", "garbage_number": "1..2"}[kind]
    elif kind == "swap_names":
        named = [e for e in elems if "name" in e.attrib or "link" in e.attrib]
        if len(named) >= 2:
            a, b = rng.sample(named, 2)
            ka = "name" if "name" in a.attrib else "link"
            kb = "name" if "name" in b.attrib else "link"
            a.attrib[ka], b.attrib[kb] = b.attrib[kb], a.attrib[ka]
    elif kind == "duplicate_element" and elem is not root:
        parent = next(p for p in elems if elem in list(p))
        parent.append(ET.fromstring(ET.tostring(elem)))
    elif kind == "delete_element" and elem is not root:
        parent = next(p for p in elems if elem in list(p))
        parent.remove(elem)
    return ET.tostring(root, encoding="unicode")


@pytest.mark.parametrize("path", example_robot_urdfs(), ids=lambda p: p.name)
def test_mutated_real_urdfs_load_or_raise_model_error(path):
    text = path.read_text()
    rng = random.Random(path.name)
    for _ in range(max(3, EXAMPLES // 30)):
        load(mutate(text, rng, rng.choice(MUTATIONS)))


def test_inflated_real_urdf_loads_with_bounded_memory():
    """A 1 MB robot (a real URDF repeated as disconnected copies) ends in a ModelError (several
    roots) within the memory bound."""
    path = next(p for p in example_robot_urdfs() if p.name == "panda.urdf")
    text = mutate(path.read_text(), random.Random(0), "inflate", size=1_000_000)
    assert len(text) > 900_000
    assert load(text) is None


def test_files_over_the_size_limit_are_refused_before_parsing(tmp_path):
    from robodyn.io import urdf

    path = next(p for p in example_robot_urdfs() if p.name == "panda.urdf")
    text = path.read_text()
    big = text.replace("</robot>", "<!--" + " " * (urdf.MAX_FILE_BYTES - len(text)) + "--></robot>")
    assert len(big) > urdf.MAX_FILE_BYTES
    with pytest.raises(rd.ModelError, match="exceeds the limit"):
        rd.load_urdf(big)
    file = tmp_path / "big.urdf"
    file.write_text(big)
    with pytest.raises(rd.ModelError, match="exceeds the limit"):
        rd.load_urdf(file)
