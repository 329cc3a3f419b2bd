"""Certified bounds of the mass matrix's eigenvalues over a box of joint angles:
``lambda_m 1 <= M(q) <= lambda_M 1`` for every ``q`` in the box, not only at samples.

Fourier series. For revolute joints every entry of ``M(q)`` is a trigonometric polynomial of
degree at most 2 in each angle (``M = sum_b J_b^T I_b J_b`` and each joint's rotation enters a
body Jacobian once), so ``M`` sampled on the grid of 5 angles per joint gives its coefficients
exactly (a discrete Fourier transform)::

    M(q) = sum_n A_n exp(i n.q),    n in {-2, ..., 2}^nv.

A joint whose parent is the world turns its whole subtree rigidly, so ``M`` does not depend on
it (the first joint of a fixed-base arm): it is left out of the grid. A joint on which no
coefficient depends (PUMA 560's last joint: its link is symmetric about the axis) is passive.
The other, active, joints are the ones the box is split in. The coefficients also bound ``M``
everywhere, ``eig(A_0) -+ rho(sum_(n != 0) |A_n|)``: the bounds of the whole box before any
split.

One box, centre ``c``, half-widths ``r``, ``q = c + d``, ``|d_k| <= r_k``::

    M(c + d) = M(c) + sum_k D_k d_k + R(d),    D_k = dM/dq_k (c) = Gamma[:, :, k] + Gamma[:, :, k]^T
    |R_ij(d)| <= E_ij = 1/2 sum_n |A_n,ij| (sum_k |n_k| r_k)^2        for every d in the box

(``|exp(ix) - 1 - ix| <= x^2 / 2``; ``Gamma``: :func:`christoffel_symbols`; a passive joint's
first-order term goes into ``E`` as ``|D_k| r_k``). The remainder is weighed against ``M(c)``
itself: with ``t0 < lambda_min(M(c))`` and ``P = (M(c) - t0 1)^(-1/2)``::

    R(d) >= -eps (M(c) - t0 1),    eps = rho(|P| E |P|)

(``x = P y``: ``|y^T P R P y| <= rho(|P| E |P|) |y|^2`` and ``|y|^2 = x^T (M(c) - t0 1) x``), so an
error in the arm's large entries counts against the arm's large eigenvalues, not against the
wrist's small one as Weyl's inequality would charge it. Then ``M(c + d) >= L(d) - eps (M(c) -
t0 1)`` with ``L(d) = M(c) + sum_k D_k d_k``; the right side is affine in ``d`` and
``lambda_min`` is concave, so its minimum over the box is at one of the ``2^m`` vertices
(``m`` active joints), where it is computed exactly::

    lambda_min(M(q)) >= min_{v in {-1, 1}^m} lambda_min(M(c) + sum_k D_k v_k r_k - eps (M(c) - t0 1))

and the mirror bound for ``lambda_max`` (``t0 > lambda_max(M(c))``, ``R(d) <= eps (t0 1 -
M(c))``, maximum over the vertices). ``t0`` is tried at the distances ``GAPS`` (relative) from
the extreme eigenvalue of ``M(c)`` and the best bound kept; each is valid.

Branch and bound, one heap per bound, best first: the boxes whose bound is not yet within
``rtol`` of the best sampled eigenvalue are halved (``BATCH`` at a time) in the active joint
of largest share ``r_k |P (sum_l W_kl r_l) P|_F`` of the remainder (``W_kl`` the Fourier weights
of ``E``). A box's bound is at least its parent's (the parent's holds on it), so the certified
interval never loosens as boxes are split. The sampled eigenvalues are those of ``M`` at the
box centres and at each box's extreme vertex: true values at points of the box.

Measured (benchmarks/inertia_bounds.py; boxes, and seconds on a 2-core machine): the planar
arm over all angles to 1 % of its closed form, 31 boxes; PUMA 560 over its joint limits to
10 %: 133 boxes, 0.1 s; to 1 %: 527, 0.2 s; to 0.1 %: 8,613, 6 s. The Panda to 10 % on a box
of +-0.1 rad about a pose: 203 boxes, 0.3 s; +-0.15 rad: 2,605, 2 s; +-0.2 rad: 14,771, 9 s;
to 1 % on +-0.1 rad: 4,621, 3 s. Limits: the number of boxes grows like ``prod_k (range_k /
width_k)`` over the active joints, and the Panda's smallest eigenvalue (0.0035, in the wrist;
the largest is 3.9) needs boxes about 0.1 rad wide in all six active joints, so over the
Panda's full joint limits the interval does not approach 10 % within any affordable number of
boxes: after 20,000 boxes (13 s) it is still the global bound ``[-8.7, 10.3]`` for sampled
extremes ``[0.0035, 3.85]`` (valid, and useless). Revolute joints only (a prismatic joint,
such as a finger of the example-robot-data Panda, makes ``M`` polynomial, not periodic, in it:
bound the arm without its gripper, as the built-in ``panda``), at most ``MAX_GRID_JOINTS``
joints not attached to the world (the grid has ``5^k`` points). The armature is included.

Reference: the bounded-inertia property (Spong, Hutchinson & Vidyasagar (2006), 7.5.2;
Ghorbel, Srinivasan & Spong, "On the uniform boundedness of the inertia matrix of serial
robot manipulators", J. Robotic Systems 15(1), 1998); ``lambda_min`` is concave as a minimum
of Rayleigh quotients (Horn & Johnson, Matrix Analysis, 2nd ed., 2013, section 4.2); the
remainder is a relative perturbation in the sense of Ipsen, "Relative perturbation results
for matrix eigenvalues and singular values", Acta Numerica 7 (1998).
"""

from __future__ import annotations

import heapq
import itertools
from typing import NamedTuple

import numpy as np

from .. import joints as J
from .coriolis import christoffel_symbols
from .crba import crba

MAX_GRID_JOINTS = 7
SAMPLES = 5                  # angles per joint: exact for trigonometric degree 2
GAPS = (0.01, 0.03, 0.1)     # |lambda - t0| / |lambda| of the remainder's reference shifts
BATCH = 32                   # boxes split per round and heap
SAFETY = 1e-10               # relative margin for the rounding of the coefficients and eigenvalues


class InertiaBounds(NamedTuple):
    """``lambda_m``, ``lambda_M``: certified bounds (every ``M(q)`` in the box has its
    eigenvalues in ``[lambda_m, lambda_M]``); ``sampled_min``, ``sampled_max``: the extreme
    eigenvalues met at the evaluated points (true values, inside the certified interval);
    ``boxes``: boxes evaluated (the whole box, then two per split)."""
    lambda_m: float
    lambda_M: float
    sampled_min: float
    sampled_max: float
    boxes: int


def _fourier(model):
    """``(W, active, (low, high))`` from the exact Fourier coefficients ``A_n`` of ``M`` on the
    grid of SAMPLES angles per joint not attached to the world: ``W`` (nv, nv, nv, nv),
    ``W[i, j, k, l] = sum_n |A_n,ij| |n_k| |n_l|``; ``active`` (nv,) bool, the joints ``M``
    depends on; ``low, high``, bounds of its eigenvalues at every ``q``,
    ``eig(A_0) -+ rho(sum_(n != 0) |A_n|)`` (``|x^T A_n x| <= |x|^T |A_n| |x|``)."""
    n = model.nv
    grid = np.ones(n, bool)
    grid[model.idx_v[model.parent < 0]] = False               # M is independent of these
    dims = np.flatnonzero(grid)
    angles = 2.0 * np.pi * np.arange(SAMPLES) / SAMPLES
    Q = np.zeros((SAMPLES ** dims.size, n))
    Q[:, dims] = np.array(list(itertools.product(angles, repeat=dims.size))).reshape(Q.shape[0], dims.size)
    Ms = crba(model, Q).reshape((SAMPLES,) * dims.size + (n, n))
    A = np.fft.fftn(Ms, axes=tuple(range(dims.size))) / SAMPLES ** dims.size if dims.size else Ms
    size = np.abs(A).reshape(-1, n * n)                        # |A_n,ij|, one row per n
    freq = np.abs(np.fft.fftfreq(SAMPLES, 1.0 / SAMPLES))      # |n_k|: 0, 1, 2, 2, 1
    F = np.zeros((size.shape[0], n))
    F[:, dims] = np.array(list(itertools.product(freq, repeat=dims.size))).reshape(F.shape[0], dims.size)
    W = np.einsum("na,nk,nl->akl", size, F, F).reshape(n, n, n, n)
    active = F.T @ size.sum(axis=1) > 1e-12 * size.sum()     # zero slope and curvature: passive
    A0 = A.reshape(-1, n, n)[0]
    spread = np.linalg.eigvalsh((size[1:].sum(axis=0).reshape(n, n) + np.abs(A0.imag)))[-1]
    w0 = np.linalg.eigvalsh(A0.real)
    margin = SAFETY * (np.abs(w0).max() + spread)
    return W * (1.0 + SAFETY), active, (w0[0] - spread - margin, w0[-1] + spread + margin)


def _box_bounds(model, W, active, c, r, side):
    """Bounds over the boxes ``c +- r`` (B, nv): where ``side`` (B,) is 1, a lower bound of
    ``lambda_min``; where -1, an upper bound of ``lambda_max`` (module docstring). Returns
    ``(bound (B,), sampled min (B,), sampled max (B,), split score (B, nv))``."""
    B, n = c.shape
    M = crba(model, c)
    G = christoffel_symbols(model, c)
    D = G + np.swapaxes(G, -3, -2)                              # D[b, i, j, k] = dM_ij/dq_k
    E = 0.5 * np.einsum("ijkl,bk,bl->bij", W, r, r)
    E += np.einsum("bijk,bk->bij", np.abs(D[..., ~active]), r[:, ~active])
    lam, U = np.linalg.eigh(M)
    act = np.flatnonzero(active)
    V = np.array(list(itertools.product((-1.0, 1.0), repeat=act.size))).reshape(2 ** act.size, act.size)
    L = M[:, None] + np.einsum("bijk,vk->bvij", D[..., act] * r[:, None, None, act], V)   # L at the vertices
    of_min = side > 0
    extreme = np.where(of_min, lam[:, 0], lam[:, -1])
    scale = np.maximum(np.abs(extreme), 1e-9 * np.abs(lam).max(axis=1))
    rows = np.arange(B)
    bound = np.full(B, -np.inf)                                 # side * bound: larger is better
    vertex, P_best = np.zeros(B, int), np.zeros_like(M)
    for gap in GAPS:
        t0 = extreme - side * gap * scale
        P = np.abs(np.einsum("bik,bk,bjk->bij", U, 1.0 / np.sqrt(side[:, None] * (lam - t0[:, None])), U))
        eps = np.linalg.eigvalsh(P @ E @ P)[:, -1]             # Perron root of a nonnegative matrix
        w = np.linalg.eigvalsh(L - (eps[:, None, None] * (M - t0[:, None, None] * np.eye(n)))[:, None])
        margin = SAFETY * np.abs(w).max(axis=(1, 2))
        w = np.where(of_min[:, None], w[..., 0], -w[..., -1])  # (B, vertices): side * eigenvalue
        v = w.argmin(axis=1)
        b = w[rows, v] - margin
        better = b > bound
        bound, vertex = np.where(better, b, bound), np.where(better, v, vertex)
        P_best[better] = P[better]
    q = c.copy()
    q[:, act] += V[vertex] * r[:, act]                          # the extreme vertex: a point of the box
    w = np.linalg.eigvalsh(crba(model, q))
    WR = np.einsum("ijkl,bl->bkij", W, r)
    score = r * np.sqrt(((P_best[:, None] @ WR @ P_best[:, None]) ** 2).sum(axis=(-2, -1)))
    score[:, ~active] = 0.0
    return side * bound, np.minimum(lam[:, 0], w[:, 0]), np.maximum(lam[:, -1], w[:, -1]), score


def inertia_bounds(model, lower=None, upper=None, *, rtol: float = 0.01, max_boxes: int = 20000) -> InertiaBounds:
    """Certified bounds of the eigenvalues of ``M(q)`` over a box of joint angles:

        lambda_m 1 <= M(q) <= lambda_M 1    for every q with lower <= q <= upper

    lower, upper: (nv,), radians; default the model's joint limits, ``[-pi, pi]`` where a joint
    has none. Returns :class:`InertiaBounds` ``(lambda_m, lambda_M, sampled_min, sampled_max,
    boxes)``. The bounds hold at every point of the box, by branch and bound over sub-boxes
    (module docstring: exact Fourier coefficients of ``M``, a first-order term exact at the
    boxes' vertices, a Taylor remainder relative to ``M`` at the box centre); they are within
    ``rtol`` (relative) of the sampled extremes unless ``max_boxes`` runs out first, and then
    still valid, only wider. More boxes never widen them.

    Equivalences: ``sampled_min``, ``sampled_max`` are eigenvalues of ``crba(model, q)`` at
    points of the box, so ``lambda_m <= sampled_min <= sampled_max <= lambda_M``. Revolute
    joints only; the armature is included, as in :func:`robodyn.crba`. Reference: the
    bounded-inertia property, Spong, Hutchinson & Vidyasagar (2006), 7.5.2.
    """
    if np.any(model.joint_type != J.REVOLUTE):
        raise ValueError("inertia_bounds: revolute joints only (a prismatic, free, ball, planar or helical joint "
                         "makes M(q) non-periodic in it; bound an arm without its gripper's fingers)")
    n = model.nv
    grid = n - np.count_nonzero(model.parent < 0)
    if grid > MAX_GRID_JOINTS:
        raise ValueError(f"inertia_bounds: at most {MAX_GRID_JOINTS} joints not attached to the world "
                         f"(the Fourier grid has 5^k points), got {grid}")
    if not (np.isfinite(rtol) and rtol >= 0):
        raise ValueError(f"rtol: expected a finite number >= 0, got {rtol}")
    if int(max_boxes) != max_boxes or max_boxes < 1:
        raise ValueError(f"max_boxes: expected an integer >= 1, got {max_boxes}")
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi) if lower is None else np.asarray(lower, float)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi) if upper is None else np.asarray(upper, float)
    if lo.shape != (n,) or hi.shape != (n,) or not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError(f"lower, upper: expected {n} finite numbers each")
    if np.any(lo > hi):
        raise ValueError(f"lower > upper at joints {np.flatnonzero(lo > hi).tolist()}")
    W, active, (low, high) = _fourier(model)
    c = (lo + hi) / 2.0
    r = np.minimum((hi - lo) / 2.0, np.pi)                      # M is 2 pi periodic: a full turn covers all
    heaps = {1: [], -1: []}       # (side * bound, tie, centre, half-widths, split score): the worst box first
    sampled = [np.inf, -np.inf]
    counter = itertools.count()

    def evaluate(sides, cs, rs, parent_keys):
        sides = np.array(sides, float)
        b, s_min, s_max, score = _box_bounds(model, W, active, np.array(cs), np.array(rs), sides)
        sampled[0], sampled[1] = min(sampled[0], s_min.min()), max(sampled[1], s_max.max())
        for i, side in enumerate(sides.astype(int)):   # the parent's bound holds on its halves too
            key = max(side * b[i], parent_keys[i])
            heapq.heappush(heaps[side], (key, next(counter), cs[i], rs[i], score[i]))

    def unfinished(side):
        key, *_, score = heaps[side][0]
        extreme = sampled[0] if side > 0 else sampled[1]
        return key < side * extreme - rtol * abs(extreme) and score.max() > 0.0   # zero width: cannot split

    evaluate([1, -1], [c, c], [r, r], [low, -high])          # the global bounds hold on every box
    boxes = 1
    while True:
        sides, cs, rs, keys = [], [], [], []
        for side in (1, -1):
            for _ in range(BATCH):
                if boxes + 2 > max_boxes or not heaps[side] or not unfinished(side):
                    break
                key, _, cc, rr, score = heapq.heappop(heaps[side])
                boxes += 2
                k = int(np.argmax(score))                       # halve the joint of the largest share
                half = rr.copy()
                half[k] /= 2.0
                for sign in (-1.0, 1.0):
                    child = cc.copy()
                    child[k] += sign * half[k]
                    cs.append(child)
                    rs.append(half)
                sides += [side, side]
                keys += [key, key]
        if not cs:
            break
        evaluate(sides, cs, rs, keys)
    return InertiaBounds(float(heaps[1][0][0]), float(-heaps[-1][0][0]), float(sampled[0]), float(sampled[1]), boxes)
