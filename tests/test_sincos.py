"""The joint placements' sine and cosine (``robodyn.sincos``) against the C library: within
2 units in the last place wherever the reduction applies, and the library's own values for
angles beyond it, NaN and infinities."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn._jit import kernel
from robodyn.sincos import REDUCE_MAX
from robodyn.sincos import sincos as _compiled_sincos

ULP1 = np.spacing(1.0)


@kernel
def sincos(x):
    """The helper as the kernels call it (only compiled code calls it); its flags stay its own
    when inlined, so its results are the kernels'."""
    return _compiled_sincos(x)


def both(x):
    out = np.array([sincos(float(t)) for t in x])
    return out[:, 0], out[:, 1]


@pytest.mark.parametrize("scale", [1e-3, np.pi / 4, 4.0, 100.0, REDUCE_MAX])
def test_matches_the_library_to_two_ulp(scale):
    x = np.random.default_rng(7).uniform(-scale, scale, 20000)
    s, c = both(x)
    for mine, ref in ((s, np.sin(x)), (c, np.cos(x))):
        assert np.all(np.abs(mine - ref) <= 2 * np.spacing(np.maximum(np.abs(ref), np.finfo(float).tiny)) + 1e-300)


def test_quadrant_boundaries_and_multiples_of_half_pi():
    k = np.arange(-2000, 2001)
    x = np.concatenate([k * (np.pi / 2), np.nextafter(k * (np.pi / 4), np.inf), np.nextafter(k * (np.pi / 4), -np.inf)])
    s, c = both(x)
    assert np.max(np.abs(s - np.sin(x))) <= 2 * ULP1
    assert np.max(np.abs(c - np.cos(x))) <= 2 * ULP1
    assert np.max(np.abs(s * s + c * c - 1.0)) <= 4 * ULP1


def test_tiny_angles_are_exact():
    for x in (0.0, -0.0, 1e-300, -1e-300, 5e-324, 1e-9, -7e-9, np.nextafter(2.0 ** -27, 0.0), 2.0 ** -27, 1e-8):
        s, c = sincos(x)
        assert s == np.sin(x) and c == np.cos(x)
        assert np.signbit(s) == np.signbit(x)  # sin(-0.0) is -0.0, as in C


@pytest.mark.parametrize("x", [np.nan, np.inf, -np.inf, REDUCE_MAX * 1.0001, -1e300, 1e22])
def test_outside_the_reduction_range_the_library_answers(x):
    s, c = sincos(x)
    with np.errstate(invalid="ignore"):
        np.testing.assert_equal((s, c), (np.sin(x), np.cos(x)))
