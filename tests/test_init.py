"""The package entry point: ``import robodyn`` stays light (no Numba, no SciPy, no sympy, no
matplotlib until a function that needs them is used), and the lazy names resolve."""

from __future__ import annotations

import subprocess
import sys

import robodyn as rd


def test_import_loads_no_heavy_dependency():
    code = ("import sys, robodyn; heavy = [m for m in ('numba', 'scipy', 'sympy', 'matplotlib') if m in sys.modules];"
            "print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == ""


def test_every_public_name_resolves():
    for name in rd.__all__:
        assert getattr(rd, name) is not None, name
    assert set(rd.__all__) <= set(dir(rd))
