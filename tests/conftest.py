"""Shared test helpers: example-robot-data URDFs, fixture files and error-message checks."""

from __future__ import annotations

import re
import site
import sysconfig
from pathlib import Path

import pytest

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
