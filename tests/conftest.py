"""Shared test helpers: example-robot-data URDFs, fixture files and error-message checks."""

from __future__ import annotations

import re
import site
import sysconfig
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn as rd

FIXTURES = Path(__file__).parent / "fixtures"

# example-robot-data ships no Python module: its wheel installs the robots under the cmeel
# prefix of site-packages.
_ERD_SUBDIR = Path("cmeel.prefix") / "share" / "example-robot-data" / "robots"


def _site_dirs() -> list[Path]:
    dirs = [sysconfig.get_paths()[key] for key in ("purelib", "platlib")]
    dirs += site.getsitepackages() + [site.getusersitepackages()]
    seen, out = set(), []
    for d in dirs:
        p = Path(d)
        if p not in seen:
            seen.add(p)
            out.append(p)
    return out


def example_robot_data_dir() -> Path:
    """The ``robots`` folder of the installed example-robot-data wheel."""
    for d in _site_dirs():
        if (d / _ERD_SUBDIR).is_dir():
            return d / _ERD_SUBDIR
    raise RuntimeError(
        "example-robot-data is a test dependency but its robots were not found under "
        f"{[str(d / _ERD_SUBDIR) for d in _site_dirs()]}; pip install example-robot-data"
    )


def example_robot_urdfs() -> list[Path]:
    """Every URDF file of example-robot-data, sorted by path."""
    files = sorted(example_robot_data_dir().rglob("*.urdf"))
    if not files:
        raise RuntimeError(f"no URDF files under {example_robot_data_dir()}")
    return files


def erd_id(path: Path) -> str:
    """Short test id of an example-robot-data URDF: ``package/.../file.urdf``."""
    return path.relative_to(example_robot_data_dir()).as_posix()


def rot(axis: str, angle: float) -> np.ndarray:
    """Rotation matrix about ``axis`` ("x", "y" or "z") by ``angle`` (computed by scipy,
    independently of robodyn)."""
    return Rotation.from_euler(axis, angle).as_matrix()


def marked_lines(text: str, marker: str = "<!-- ERROR -->") -> list[int]:
    """1-based numbers of the lines of ``text`` that carry ``marker``."""
    return [i for i, line in enumerate(text.splitlines(), start=1) if marker in line]


def assert_names_line(message: str, line: int) -> None:
    """The error message names ``line`` (as ``line N``, not a prefix of a longer number)."""
    assert re.search(rf"\bline {line}\b", message), f"line {line} not named in: {message}"


@pytest.fixture
def fixture_path():
    """``fixture_path(name)``: path of a file in ``tests/fixtures`` (must exist)."""

    def get(name: str) -> Path:
        p = FIXTURES / name
        assert p.is_file(), f"missing fixture {p}"
        return p

    return get


def small_tree_builder(physical: str = "error"):
    """A branching tree with every 1-dof joint type and a merged fixed link::

        base -(shoulder, revolute z)-> upper -(slide, prismatic x)-> lower
             \\-(hip, revolute y)-> side         upper -(mount, fixed)-> sensor
    """
    b = rd.ModelBuilder("tree", physical=physical)
    b.add_link("base")
    b.add_link("upper", mass=2.0, com=(0.0, 0.0, 0.25), inertia=np.diag([0.02, 0.02, 0.004]))
    b.add_link("lower", mass=1.0, com=(0.2, 0.0, 0.0), inertia=np.diag([0.001, 0.01, 0.01]))
    b.add_link("sensor", mass=0.1, com=(0.01, 0.0, 0.0), inertia=np.eye(3) * 1e-5)
    b.add_link("side", mass=0.5, com=(0.0, 0.1, 0.0), inertia=np.diag([0.003, 0.001, 0.003]))
    b.add_joint("shoulder", "revolute", "base", "upper", xyz=(0, 0, 0.1), axis=(0, 0, 1), lower=-2, upper=2,
                velocity=3, effort=50, damping=0.1, friction=0.2)
    b.add_joint("slide", "prismatic", "upper", "lower", xyz=(0, 0, 0.5), rpy=(0, np.pi / 2, 0), axis=(1, 0, 0),
                lower=0, upper=0.3)
    b.add_joint("mount", "fixed", "upper", "sensor", xyz=(0.05, 0, 0.4))
    b.add_joint("hip", "revolute", "base", "side", xyz=(0.2, 0, 0), axis=(0, 1, 0))
    return b
