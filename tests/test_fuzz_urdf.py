"""Fuzzing the URDF loader: every input ends in a Model or a ModelError, nothing else.

A fixed-seed subset runs here (Hypothesis with ``derandomize=True``); raise ``FUZZ_EXAMPLES``
for a long campaign: ``FUZZ_EXAMPLES=20000 python -m pytest tests/test_fuzz_urdf.py``.
"""

from __future__ import annotations

import os
import random
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


def load(text: str):
    """Load ``text``: returns a Model or raises ModelError; anything else fails the test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return rd.load_urdf(text, physical="warn")
        except rd.ModelError:
            return None


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
             "truncate", "garbage_number")


def mutate(text: str, rng: random.Random, kind: str) -> str:
    if kind == "truncate":
        return text[: rng.randrange(len(text))]
    root = ET.fromstring(text)
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
