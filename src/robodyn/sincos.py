"""Sine and cosine of one angle together, for the joint placements of every kernel.

Two calls to the C library's ``sin`` and ``cos`` cost about 30 ns per revolute joint, a
quarter of a batched RNEA on a 7-dof arm. :func:`sincos` computes both in about 7 ns, to
within 2 units in the last place of the library values:

1. Range reduction (Cody and Waite): ``n = round(x 2/pi)``, ``r = x - n pi/2`` with ``pi/2``
   split in three parts whose products with ``n`` are exact, so ``|r| <= pi/4`` carries no
   rounding error beyond ``1e-25`` absolute for ``|x| <= REDUCE_MAX``.
2. Minimax polynomials on ``[-pi/4, pi/4]`` (the coefficients of the Cephes library,
   S. L. Moshier, *Methods and Programs for Mathematical Functions*, 1989):
   ``sin r = r + r z P(z)``, ``cos r = 1 - z/2 + z^2 Q(z)``, ``z = r^2``.
3. The quadrant ``n mod 4`` swaps and negates ``(sin r, cos r)``, without branches.

Angles beyond ``REDUCE_MAX`` (16,000 turns), and NaN or infinite ones, go to the library;
angles below ``TINY`` in magnitude are their own sine (``sin(-0.0) = -0.0``, as in C).

This function is compiled with floating-point contraction (fused multiply-add) only: the
reassociation allowed elsewhere would merge the three-part reduction into one product and
lose the digits it exists to keep.
"""

from __future__ import annotations

import numpy as np

from ._jit import exact

REDUCE_MAX = 1e5
TINY = 2.0 ** -27  # below it, x^3 / 6 < ulp(x) / 2 and x^2 / 2 < ulp(1) / 2
TWO_OVER_PI = 0.6366197723675814
# pi/2 = PIO2_1 + PIO2_2 + PIO2_3; PIO2_1 and PIO2_2 have 24 significant bits, so their
# products with n (|n| < 2^17) are exact.
PIO2_1 = 1.5707962512969971
PIO2_2 = 7.549789415861596e-08
PIO2_3 = 5.390302858158119e-15


@exact
def sincos(x):
    """``(sin x, cos x)``."""
    if not abs(x) <= REDUCE_MAX:
        return np.sin(x), np.cos(x)
    if abs(x) < TINY:  # sin x = x and cos x = 1 to the last bit; keeps the sign of -0.0
        return x, 1.0
    n = np.floor(x * TWO_OVER_PI + 0.5)
    r = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3
    z = r * r
    sr = r + r * z * (((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z
                         + 2.75573136213857245213e-6) * z - 1.98412698295895385996e-4) * z
                       + 8.33333333332211858878e-3) * z - 1.66666666666666307295e-1)
    cr = 1.0 - 0.5 * z + z * z * (((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z
                                     - 2.75573141792967388112e-7) * z + 2.48015872888517045348e-5) * z
                                   - 1.38888888888730564116e-3) * z + 4.16666666666665929218e-2)
    k = np.int64(n) & 3  # quadrant: (s, c) = (sr, cr), (cr, -sr), (-sr, -cr), (-cr, sr)
    s = cr if k & 1 else sr
    c = sr if k & 1 else cr
    return s * (1.0 - 2.0 * ((k >> 1) & 1)), c * (1.0 - 2.0 * (((k + 1) >> 1) & 1))
