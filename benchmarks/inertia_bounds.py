"""Certified eigenvalue bounds of M(q) (``rd.inertia_bounds``): boxes and seconds to a tolerance.

    python benchmarks/inertia_bounds.py [--max-boxes 20000]

Built-in robots: the planar 2R arm (all angles), PUMA 560 (its joint limits), the Panda on
boxes of half-width 0.1 to 1 rad about the pose ``PANDA_POSE`` and over its full joint limits
(to 10 %, 5 % and 1 %). For each: the certified interval, the sampled extremes (true
eigenvalues at points of the box), their ratios, the boxes evaluated and the wall time of the
call (the model's Fourier coefficients included; the compiled kernels are loaded first). A
ratio within ``1 -+ rtol`` means the tolerance was reached; otherwise ``max_boxes`` ran out
first and the interval is valid but wider. The Panda rows past 0.1 rad and the PUMA 560 and
planar rows are settled by the direct branch and bound alone when it needs fewer than
``DIRECT_BOXES`` boxes (1,000), by the chain certificate otherwise (module docstring).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import robodyn as rd

PANDA_POSE = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])


def cases():
    """``(label, model, lower, upper, rtol)`` of the table."""
    panda = rd.models.load("panda")
    rows = [("planar_2r, all angles", rd.models.load("planar_2r"), None, None, 0.01),
            ("puma560, joint limits", rd.models.load("puma560"), None, None, 0.1),
            ("puma560, joint limits", rd.models.load("puma560"), None, None, 0.01)]
    for h, rtol in ((0.1, 0.1), (0.15, 0.1), (0.2, 0.1), (0.5, 0.1), (1.0, 0.1), (0.1, 0.01)):
        lo, hi = np.maximum(PANDA_POSE - h, panda.lower), np.minimum(PANDA_POSE + h, panda.upper)
        rows.append((f"panda, pose +- {h} rad", panda, lo, hi, rtol))
    for rtol in (0.1, 0.05, 0.01):
        rows.append(("panda, joint limits", panda, None, None, rtol))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-boxes", type=int, default=20000)
    args = parser.parse_args()
    rd.inertia_bounds(rd.models.load("planar_2r"), max_boxes=3)  # load the compiled kernels
    print(f"  {'robot, box':<26} {'rtol':>5} {'lambda_m':>10} {'sampled':>10} {'ratio':>7} "
          f"{'lambda_M':>9} {'sampled':>9} {'ratio':>7} {'boxes':>7} {'s':>7}")
    for label, model, lo, hi, rtol in cases():
        t = time.perf_counter()
        b = rd.inertia_bounds(model, lo, hi, rtol=rtol, max_boxes=args.max_boxes)
        seconds = time.perf_counter() - t
        print(f"  {label:<26} {rtol:5.2g} {b.lambda_m:10.4g} {b.sampled_min:10.4g} {b.lambda_m / b.sampled_min:7.4f} "
              f"{b.lambda_M:9.4g} {b.sampled_max:9.4g} {b.lambda_M / b.sampled_max:7.4f} {b.boxes:7d} {seconds:7.2f}",
              flush=True)


if __name__ == "__main__":
    main()
