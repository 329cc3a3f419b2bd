"""Certified bounds of the mass matrix's eigenvalues over a box of joint angles:
``lambda_m 1 <= M(q) <= lambda_M 1`` for every ``q`` in the box, not only at samples.

Two methods, each valid at every point of the box: a branch and bound over boxes of all the
joints (any revolute tree), and, for a serial chain that it does not settle within
``DIRECT_BOXES`` boxes, a chain certificate that needs boxes of one joint at a time.

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
of ``E``). A box's bound is at least its parent's (the parent's bound holds on its halves
too). The sampled eigenvalues are those of ``M`` at the box centres and at each box's extreme
vertex: true values at points of the box. The remainder grows like ``(sum_k |n_k| r_k)^2``, so
this needs boxes narrow in every active joint at once: the Panda's smallest eigenvalue (0.0035,
in the wrist; the largest is 3.9) needs them about 0.1 rad wide in six joints, and over its full
joint limits 20,000 boxes still leave the global bound ``[-8.7, 10.3]``.

Chain certificate (a serial chain, body ``i``'s parent ``i - 1``, ``n >= 3`` joints). The
kinetic energy is the sum of the bodies' (RBDA, Featherstone 2008, chapters 2 and 4; twists
``V = [v; omega]`` in body frames, ``I_i`` the spatial inertia, ``a_i`` the armature)::

    x^T M(q) x = sum_i (V_i^T I_i V_i + a_i x_i^2),    V_i = X_i(q_i) V_(i-1) + S_i x_i,  V_(-1) = 0

and each transform ``X_i`` depends on its own joint's angle only. For any constant symmetric
6 x 6 multipliers ``Lambda_1 .. Lambda_(n-2)`` (``Lambda_(n-1) = 0``) the terms ``V_(i-1)^T
Lambda_(i-1) V_(i-1) - V_i^T Lambda_i V_i`` sum to zero, so, with ``Psi_i = [X_i, S_i]``::

    x^T (s (M(q) - t 1)) x = sum_(i=1)^(n-1) y_i^T K_i(q_i) y_i,    y_i = [V_(i-1); x_i]
    K_i(q_i) = Psi_i^T (s I_i - Lambda_i) Psi_i + diag(Lambda_(i-1), s (a_i - t))

(``s = 1`` for ``lambda_min >= t``, ``s = -1`` for ``lambda_max <= t``; body 0 turns about a
fixed axis, ``V_0 = S_0 x_0``, so its term joins body 1's: ``y_1 = [x_0; x_1]``,
``Psi_1 = [X_1 S_0, S_1]``, ``K_1`` is 2 x 2 and has ``s (S_0^T I_0 S_0 + a_0 - t)`` in place
of ``Lambda_0``). If every ``K_i(q_i) >= 0`` over its joint's interval then ``s (M(q) - t 1)
>= 0`` on the whole box: one question in ``n - 1`` angles becomes ``n - 1`` questions in one
angle each, and each ``K_i`` is a trigonometric polynomial of degree 2 in ``q_i``, certified
over its interval by the branch and bound above (goal 0, one joint, its exact Fourier
coefficients from 5 samples). The multipliers are a storage function in the sense of Willems
(1972): at one configuration the exact choice is the value function of dynamic programming,
``V^T Lambda_i V`` = the least of ``s`` (the energy of bodies ``0..i`` minus ``t`` times their
joints' ``|x|^2``) over the joint velocities that give body ``i`` the twist ``V`` (a shifted
articulated inertia of bodies ``0..i`` seen at body ``i``, infinite off the twists they can
reach), and with it every ``K_i >= 0`` wherever ``s (M - t 1) >= 0``; over a box one
``Lambda_i`` must serve every configuration, which costs little when, as for the Panda, the
extreme eigenvalue is decided in a few joints. They are chosen by maximising the margin
``z`` of ``K_i(q) >= z (Psi_i^T I_i Psi_i + |t| 1)`` at samples every ``MULTIPLIER_STEP`` rad
of each joint, with ``|Lambda_i| <= MULTIPLIER_BOUND m (1 + l^2)`` (``m`` the total mass,
``l`` the sum of the link offsets): a semidefinite program in ``21 (n - 2)`` unknowns, solved
by the log-det barrier method with Newton steps (Boyd & Vandenberghe 2004, 11.2 and 11.6);
the angles between the samples where
a check every ``CHECK_STEP`` finds less than half that margin are added to the samples and
the program solved again (at most ``REFINEMENTS`` times). The fit only chooses the
multipliers; the proof is the certification of each ``K_i`` over its whole interval. ``t`` is
``extreme -+ TARGETS rtol |extreme|`` (first 0.7, then 0.9 times the tolerance) about the
sampled extreme, which ``SEARCH_POINTS`` points of the box (a Sobol sequence) and a bounded
local search (L-BFGS-B) from the best three refine first. A proven ``t`` is the bound; the
direct branch and bound goes on for a bound not proven, with the boxes left.

Measured (benchmarks/inertia_bounds.py; boxes, and seconds on a shared 2-core machine under
load, two runs). By the direct branch and bound alone, as before the chain certificate: the
planar arm over all angles to 1 % of its closed form, 31 boxes, 0.03 s; PUMA 560 over its joint
limits to 10 %: 133 boxes, 0.3 to 0.4 s; to 1 %: 527, 0.7 s; the Panda to 10 % on a box of
+-0.1 rad about a pose: 203, 0.85 to 1.0 s. With the chain certificate after the first 1,000
direct boxes, the Panda to 10 % on +-0.15, +-0.2, +-0.5 and +-1 rad: 1,055 to 1,211 boxes, 2 to
4 s (the direct method alone: 2,605 and 14,771 boxes for +-0.15 and +-0.2; for +-0.5
``[-8.7, 3.56]`` after 20,000 boxes, 34 s); to 1 % on +-0.1 rad: 1,067, 2 to 3.6 s (direct
alone: 4,621); over its full joint limits to 10 %: ``[0.003275, 4.147]`` for sampled extremes
``[0.003522, 3.876]``, 1,627 boxes, 3.3 to 4.6 s; to 5 %: 1,803, 3.5 to 4.4 s; to 1 %:
``[0.003497, 3.903]``, 2,459 boxes, 6 to 9 s (the direct method alone: ``[-8.7, 10.3]`` after
20,000 boxes). Random serial chains (``random_model(n, seed, branching=0)``, n = 3..7, seeds
0..3, over all angles or random boxes; measured during development, not in the benchmark): all
20 to 10 %, 19 of 20 to 1 %, 0.1 to 9 s each. Limits: the direct method's boxes grow like
``prod_k (range_k / width_k)`` over the active joints; the chain certificate needs a serial
chain, and fails (then the direct method goes on, valid and wider) when no constant
multipliers fit at the ``t`` tried, within ``rtol`` of the sampled extreme.

Revolute joints only (a prismatic joint, such as a finger of the example-robot-data Panda,
makes ``M`` polynomial, not periodic, in it: bound the arm without its gripper, as the built-in
``panda``), at most ``MAX_GRID_JOINTS`` joints not attached to the world (the grid has ``5^k``
points). The chain certificate needs a serial chain (a tree, several roots: the direct method
only) and ``rtol > 0``. The armature is included.

References: the bounded-inertia property (Spong, Hutchinson & Vidyasagar (2006), 7.5.2;
Ghorbel, Srinivasan & Spong, "On the uniform boundedness of the inertia matrix of serial
robot manipulators", J. Robotic Systems 15(1), 1998); ``lambda_min`` is concave as a minimum
of Rayleigh quotients (Horn & Johnson, Matrix Analysis, 2nd ed., 2013, section 4.2); the
remainder is a relative perturbation in the sense of Ipsen, "Relative perturbation results
for matrix eigenvalues and singular values", Acta Numerica 7 (1998); spatial transforms and
inertias: Featherstone, Rigid Body Dynamics Algorithms (RBDA), 2008; storage functions:
Willems, "Dissipative dynamical systems, part I: general theory", Arch. Rational Mech. Anal.
45 (1972); the barrier method: Boyd & Vandenberghe, Convex Optimization, 2004.
"""

from __future__ import annotations

import heapq
import itertools
from functools import partial
from typing import NamedTuple

import numpy as np
from scipy.linalg import cho_factor, cho_solve
from scipy.optimize import minimize
from scipy.stats import qmc

from .. import joints as J
from ..coupling import is_coupled, not_supported
from .coriolis import christoffel_symbols
from .crba import crba

MAX_GRID_JOINTS = 7
SAMPLES = 5                  # angles per joint: exact for trigonometric degree 2
GAPS = (0.01, 0.03, 0.1)     # |lambda - t0| / |lambda| of the remainder's reference shifts
BATCH = 32                   # boxes split per round and heap
SAFETY = 1e-10               # relative margin for the rounding of the coefficients and eigenvalues
DIRECT_BOXES = 1000          # boxes of the direct branch and bound before the chain certificate is tried
TARGETS = (0.7, 0.9)         # the chain certificate's t: the sampled extreme -+ TARGETS * rtol * |extreme|
SEARCH_POINTS = 4096         # points of the search for the extremes before the chain certificate (2^k)
MULTIPLIER_STEP = 0.25       # radians between the samples of a joint the multipliers are fitted on
CHECK_STEP = 0.01            # radians between the angles the fitted multipliers are checked at
REFINEMENTS = 3              # refits with the angles of low margin added to the samples
MULTIPLIER_BOUND = 10.0      # |Lambda| <= MULTIPLIER_BOUND * total mass * (1 + reach^2)
MULTIPLIER_ROUNDS = 8        # barrier parameters tried (each 10 times the last)
CENTRING_STEPS = 60          # Newton steps at most per barrier parameter


def _symmetric_basis():
    """(21, 6, 6): ``E_ab + E_ba`` for ``a < b`` and ``E_aa``, a basis of the symmetric 6 x 6 matrices."""
    a, b = np.triu_indices(6)
    E = np.zeros((a.size, 6, 6))
    E[np.arange(a.size), a, b] = E[np.arange(a.size), b, a] = 1.0
    return E


BASIS = _symmetric_basis()   # the multipliers Lambda_i = sum_p x_p BASIS_p


class InertiaBounds(NamedTuple):
    """``lambda_m``, ``lambda_M``: certified bounds (every ``M(q)`` in the box has its
    eigenvalues in ``[lambda_m, lambda_M]``); ``sampled_min``, ``sampled_max``: the extreme
    eigenvalues met at the evaluated points (true values, inside the certified interval);
    ``boxes``: boxes evaluated (the whole box, then two per split; with the chain certificate,
    the boxes of its one-angle conditions included)."""
    lambda_m: float
    lambda_M: float
    sampled_min: float
    sampled_max: float
    boxes: int


def _fourier_grid(nd):
    """``(points, n)``, both (5^nd, nd): the grid of SAMPLES angles per joint and the frequencies
    ``n in {-2, ..., 2}^nd`` of the discrete Fourier transform on it, in the same order."""
    angles = 2.0 * np.pi * np.arange(SAMPLES) / SAMPLES
    freq = np.rint(np.fft.fftfreq(SAMPLES, 1.0 / SAMPLES)).astype(int)
    points = np.array(list(itertools.product(angles, repeat=nd)), float).reshape(SAMPLES ** nd, nd)
    return points, np.array(list(itertools.product(freq, repeat=nd)), int).reshape(SAMPLES ** nd, nd)


def _series(values, nd):
    """``A_n`` (5^nd, m, m), ``F(q) = sum_n A_n exp(i n.q)``, from the values (5^nd, m, m) of a
    trigonometric polynomial of degree <= 2 in each angle on :func:`_fourier_grid`'s points."""
    m = values.shape[-1]
    if nd == 0:
        return values.astype(complex)
    A = np.fft.fftn(values.reshape((SAMPLES,) * nd + (m, m)), axes=tuple(range(nd))) / SAMPLES ** nd
    return A.reshape(-1, m, m)


def _weights(freq, A):
    """``(W, active, (low, high))`` of the series ``F(q) = sum_n A_n exp(i n.q)`` (``freq`` (N,
    nd), ``A`` (N, m, m), ``freq[0] = 0``): ``W`` (m, m, nd, nd), ``W[i, j, k, l] = sum_n
    |A_n,ij| |n_k| |n_l|``; ``active`` (nd,) bool, the angles ``F`` depends on; ``low, high``,
    bounds of its eigenvalues at every ``q``, ``eig(A_0) -+ rho(sum_(n != 0) |A_n|)``
    (``|x^T A_n x| <= |x|^T |A_n| |x|``)."""
    m, nd = A.shape[-1], freq.shape[1]
    size = np.abs(A).reshape(-1, m * m)
    F = np.abs(freq).astype(float)
    W = np.einsum("na,nk,nl->akl", size, F, F).reshape(m, m, nd, nd)
    active = F.T @ size.sum(axis=1) > 1e-12 * size.sum()      # zero slope and curvature: passive
    spread = np.linalg.eigvalsh(size[1:].sum(axis=0).reshape(m, m) + np.abs(A[0].imag))[-1]
    w0 = np.linalg.eigvalsh(A[0].real)
    margin = SAFETY * (np.abs(w0).max() + spread)
    return W * (1.0 + SAFETY), active, (w0[0] - spread - margin, w0[-1] + spread + margin)


def _synthesis(freq, A, q, slopes=True):
    """``(F(q), dF/dq)`` of ``F(q) = sum_n A_n exp(i n.q)`` at the points ``q`` (B, nd): (B, m,
    m) and (B, m, m, nd) (``dF/dq_k = sum_n i n_k A_n exp(i n.q)``; None without ``slopes``)."""
    m = A.shape[-1]
    E = np.exp(1j * (q @ freq.T))
    Af = A.reshape(len(A), m * m)
    F = (E @ Af).real.reshape(-1, m, m)
    if not slopes:
        return F, None
    D = np.einsum("bn,nk,na->bak", 1j * E, freq, Af).real.reshape(-1, m, m, freq.shape[1])
    return F, D


def _mass_matrix(model, q, slopes=True):
    """``(M(q), dM/dq)``: :func:`crba` (B, nv, nv) and ``D[b, i, j, k] = dM_ij/dq_k = Gamma_ijk +
    Gamma_jik`` (B, nv, nv, nv) from :func:`christoffel_symbols` (None without ``slopes``)."""
    M = crba(model, q)
    if not slopes:
        return M, None
    G = christoffel_symbols(model, q)
    return M, G + np.swapaxes(G, -3, -2)


def _fourier(model):
    """``(W, active, (low, high))`` of :func:`_weights` for ``M`` itself, from the exact Fourier
    coefficients on the grid of SAMPLES angles per joint not attached to the world (``M`` does
    not depend on those; their rows of ``W`` and ``active`` are zero)."""
    n = model.nv
    grid = np.ones(n, bool)
    grid[model.idx_v[model.parent < 0]] = False
    dims = np.flatnonzero(grid)
    points, freq = _fourier_grid(dims.size)
    Q = np.zeros((points.shape[0], n))
    Q[:, dims] = points
    full = np.zeros((freq.shape[0], n), int)
    full[:, dims] = freq
    return _weights(full, _series(crba(model, Q), dims.size))


def _box_bounds(evaluate, W, active, c, r, side):
    """Bounds over the boxes ``c +- r`` (B, nd) of the eigenvalues of ``F`` (``evaluate(q) ->
    (F(q), dF/dq)``): where ``side`` (B,) is 1, a lower bound of ``lambda_min``; where -1, an
    upper bound of ``lambda_max`` (module docstring). Returns ``(bound (B,), sampled min (B,),
    sampled max (B,), split score (B, nd))``."""
    B, n = c.shape
    M, D = evaluate(c)
    m = M.shape[-1]
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
        w = np.linalg.eigvalsh(L - (eps[:, None, None] * (M - t0[:, None, None] * np.eye(m)))[:, None])
        margin = SAFETY * np.abs(w).max(axis=(1, 2))
        w = np.where(of_min[:, None], w[..., 0], -w[..., -1])  # (B, vertices): side * eigenvalue
        v = w.argmin(axis=1)
        b = w[rows, v] - margin
        better = b > bound
        bound, vertex = np.where(better, b, bound), np.where(better, v, vertex)
        P_best[better] = P[better]
    q = c.copy()
    q[:, act] += V[vertex] * r[:, act]                          # the extreme vertex: a point of the box
    w = np.linalg.eigvalsh(evaluate(q, slopes=False)[0])
    WR = np.einsum("ijkl,bl->bkij", W, r)
    score = r * np.sqrt(((P_best[:, None] @ WR @ P_best[:, None]) ** 2).sum(axis=(-2, -1)))
    score[:, ~active] = 0.0
    return side * bound, np.minimum(lam[:, 0], w[:, 0]), np.maximum(lam[:, -1], w[:, -1]), score


_TIE = itertools.count()     # the heaps' tie-breaker: insertion order


def _push(evaluate, W, active, heaps, sampled, sides, cs, rs, parent_keys):
    """Bound the boxes ``cs +- rs`` (one side each) and push them on ``heaps[side]`` as ``(side *
    bound, tie, centre, half-widths, split score)``; a box's key is at least its parent's (the
    parent's bound holds on its halves too). Updates ``sampled = [min, max]`` in place."""
    sides = np.array(sides, float)
    b, s_min, s_max, score = _box_bounds(evaluate, W, active, np.array(cs), np.array(rs), sides)
    sampled[0], sampled[1] = min(sampled[0], s_min.min()), max(sampled[1], s_max.max())
    for i, side in enumerate(sides.astype(int)):
        key = max(side * b[i], parent_keys[i])
        heapq.heappush(heaps[side], (key, next(_TIE), cs[i], rs[i], score[i]))



def _branch_and_bound(evaluate, W, active, heaps, sampled, goal, boxes, max_boxes):
    """Best first, one heap per side: halve the worst boxes (``BATCH`` a round and side) in the
    joint of largest split score while the side's worst key is below ``goal(side)`` and that goal
    is not above a sampled value (``side * sampled extreme``: then it cannot be reached), until
    ``max_boxes``. ``heaps`` and ``sampled`` are updated in place; returns the boxes evaluated."""
    def unfinished(side):
        key, *_, score = heaps[side][0]
        extreme = sampled[0] if side > 0 else sampled[1]
        return key < goal(side) <= side * extreme and score.max() > 0.0   # zero width: cannot split

    while True:
        sides, cs, rs, keys = [], [], [], []
        for side in heaps:
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
            return boxes
        _push(evaluate, W, active, heaps, sampled, sides, cs, rs, keys)


def _certify(values, nd, lo, hi, max_boxes):
    """``(proven, boxes)``: whether ``F(q) >= 0`` (positive semidefinite) at every ``q`` of the box
    ``[lo, hi]`` (nd,), for the trigonometric polynomial ``F`` of degree <= 2 in each angle whose
    values on :func:`_fourier_grid`'s points are ``values``; by the branch and bound of
    :func:`_box_bounds` with the goal 0, stopped by a sampled ``F(q)`` not positive semidefinite."""
    if max_boxes < 1:
        return False, 0
    freq = _fourier_grid(nd)[1]
    A = _series(values, nd)
    W, active, (low, _) = _weights(freq, A)
    evaluate = partial(_synthesis, freq, A)
    heaps, sampled = {1: []}, [np.inf, -np.inf]
    c, r = (lo + hi) / 2.0, np.minimum((hi - lo) / 2.0, np.pi)
    _push(evaluate, W, active, heaps, sampled, [1], [c], [r], [low])
    boxes = _branch_and_bound(evaluate, W, active, heaps, sampled, lambda side: 0.0, 1, max_boxes)
    return heaps[1][0][0] >= 0.0, boxes


def _skew(p):
    """``[p]x`` (..., 3, 3): ``[p]x y = p x y``."""
    Z = np.zeros(np.shape(p)[:-1] + (3, 3))
    Z[..., 0, 1], Z[..., 0, 2], Z[..., 1, 2] = -p[..., 2], p[..., 1], -p[..., 0]
    return Z - np.swapaxes(Z, -1, -2)


def _joint_maps(model, i, q):
    """``Phi = [Xup(q), S]`` (B, 6, 7) of the revolute joint of body ``i`` at the angles ``q``
    (B,): ``V_i = Xup V_parent + S x_i``, twists ``V = [v; omega]`` (linear velocity of the frame
    origin, angular velocity) in the body frames: ``R = X_tree_R exp(q [axis]x)`` (Rodrigues),
    ``Xup = [[R^T, -R^T [p]x], [0, R^T]]`` with ``p = X_tree_p``, ``S = [0; axis]`` (the
    Plücker transform and motion subspace of RBDA chapters 2 and 4, linear part first)."""
    a = model.joint_axis[i]
    K = _skew(a)
    c, s = np.cos(q)[:, None, None], np.sin(q)[:, None, None]
    Rt = np.swapaxes(model.X_tree_R[i] @ (np.eye(3) + s * K + (1.0 - c) * (K @ K)), 1, 2)
    Phi = np.zeros((len(q), 6, 7))
    Phi[:, :3, :3] = Phi[:, 3:, 3:6] = Rt
    Phi[:, :3, 3:6] = -Rt @ _skew(model.X_tree_p[i])
    Phi[:, 3:, 6] = a
    return Phi


def _spatial_inertia(theta):
    """The 6 x 6 spatial inertia of a body about its frame's origin, twists ``[v; omega]``:
    ``[[m 1, -[h]x], [[h]x, I_o]]`` (``h = m c``, ``I_o`` the rotational inertia about the
    origin; RBDA chapter 2, linear part first): ``1/2 V^T I V`` is the kinetic energy."""
    I = np.zeros((6, 6))
    I[:3, :3] = theta[0] * np.eye(3)
    I[:3, 3:], I[3:, :3] = -_skew(theta[1:4]), _skew(theta[1:4])
    I[3:, 3:] = [[theta[4], theta[5], theta[7]], [theta[5], theta[6], theta[8]], [theta[7], theta[8], theta[9]]]
    return I


def _chain_terms(model, i, q, side, t):
    """Body ``i``'s condition of the chain certificate (module docstring) at its angles ``q``
    (B,): ``K_i(q) = C - sum_p u[var_p] F_p`` in the variables ``y_i = [V_(i-1); x_i]`` (``[x_0;
    x_1]`` for ``i = 1``: the root's energy joins body 1's), ``u`` the multipliers ``Lambda_1 ..
    Lambda_(n-2)``, 21 coordinates on BASIS each; returns ``(C, F (B, P, d, d), var (P,), S)``
    with the scale ``S = Psi^T I_i Psi + |t| 1`` of the margin (d = 7, or 2 for ``i = 1``)."""
    n, B = model.nbodies, len(q)
    Psi = _joint_maps(model, i, q)
    I = _spatial_inertia(model.theta[i])
    inner = np.zeros(6)
    if i == 1:
        S0 = _joint_maps(model, 0, np.zeros(1))[0, :, 6]
        Psi = np.concatenate([Psi[:, :, :6] @ S0[:, None], Psi[:, :, 6:]], axis=2)
        inner = np.array([S0 @ _spatial_inertia(model.theta[0]) @ S0 + model.armature[0] - t])
    d = Psi.shape[2]
    energy = np.swapaxes(Psi, 1, 2) @ I @ Psi
    C = side * (energy + np.diag(np.r_[inner, model.armature[i] - t]))
    F, var = [], []
    if i >= 2:                                               # + V_(i-1)^T Lambda_(i-1) V_(i-1)
        E = np.zeros((21, d, d))
        E[:, :6, :6] = -BASIS
        F.append(np.broadcast_to(E, (B, 21, d, d)))
        var.append(21 * (i - 2) + np.arange(21))
    if i <= n - 2:                                           # - V_i^T Lambda_i V_i
        F.append(np.einsum("bji,pjk,bkl->bpil", Psi, BASIS, Psi))
        var.append(21 * (i - 1) + np.arange(21))
    return C, np.concatenate(F, axis=1), np.concatenate(var), energy + abs(t) * np.eye(d)


def _multipliers(blocks, nx):
    """``(x (nx,), z)`` maximising ``z`` subject to ``C - sum_p x[var_p] F_p - z S >= 0`` at every
    sample of every block ``(C (B, d, d), F (B, P, d, d), var (P,), S (B, d, d))``: a small
    semidefinite program, solved by the log-det barrier method with Newton steps (Boyd &
    Vandenberghe, Convex Optimization, 2004, 11.2 and 11.6)."""
    z = nx

    def slacks(x):
        return [C - np.einsum("p,bpij->bij", x[var], F) - x[z] * S for C, F, var, S in blocks]

    def barrier(x, tau):
        value = -tau * x[z]
        for Y in slacks(x):
            try:
                value -= 2.0 * np.log(np.diagonal(np.linalg.cholesky(Y), axis1=1, axis2=2)).sum()
            except np.linalg.LinAlgError:
                return np.inf
        return value

    x = np.zeros(nx + 1)
    x[z] = min(np.linalg.eigvals(np.linalg.solve(S, C)).real.min() for C, _, _, S in blocks if S.any()) - 1.0
    dims = sum(C.shape[0] * C.shape[1] for C, *_ in blocks)
    tau = dims / (abs(x[z]) + 1.0)                          # the duality gap dims / tau starts near |z|
    for _ in range(MULTIPLIER_ROUNDS):
        for _ in range(CENTRING_STEPS):                          # centring: damped Newton steps
            g, H = np.zeros(nx + 1), np.zeros((nx + 1, nx + 1))
            g[z] = -tau
            try:
                for (C, F, var, S), Y in zip(blocks, slacks(x)):
                    Z = np.linalg.inv(Y)[:, None] @ np.concatenate([F, S[:, None]], axis=1)   # Y^-1 (-dY/dx)
                    B, P, d, _ = Z.shape
                    idx = np.r_[var, z]
                    g[idx] += np.trace(Z, axis1=2, axis2=3).sum(axis=0)
                    H[np.ix_(idx, idx)] += (Z.reshape(B, P, d * d) @ np.swapaxes(Z, 2, 3).reshape(B, P, d * d)
                                            .transpose(0, 2, 1)).sum(axis=0)
                scale = np.sqrt(np.diagonal(H))                    # Jacobi scaling: the variables' units differ
                dx = -cho_solve(cho_factor(H / np.outer(scale, scale) + 1e-12 * np.eye(nx + 1)), g / scale) / scale
            except np.linalg.LinAlgError:                          # the limit of the arithmetic: x is feasible
                return x[:nx], x[z]
            decrement, step, f0 = -g @ dx, 1.0, barrier(x, tau)
            while barrier(x + step * dx, tau) > f0 - 0.25 * step * decrement:
                step /= 2.0
                if step < 1e-8:
                    return x[:nx], x[z]
            x = x + step * dx
            if decrement < 1e-3:
                break
        if x[z] > 0.0 and dims / tau < 0.05 * x[z]:             # the duality gap is below 5 % of z
            break
        tau *= 10.0
    return x[:nx], x[z]


def _chain_certificate(model, lo, hi, side, t, max_boxes):
    """``(proven, boxes)``: whether ``side (M(q) - t 1) >= 0`` at every ``q`` of the box ``[lo,
    hi]`` is proven for a serial chain by constant multipliers ``Lambda_i`` (module docstring):
    fitted by :func:`_multipliers` on samples every MULTIPLIER_STEP of each joint (and, up to
    REFINEMENTS times, at the angles between them where a check every CHECK_STEP finds a margin
    below half the fitted one), then each body's condition ``K_i(q_i) >= 0`` certified over its
    joint's interval by :func:`_certify`."""
    n = model.nbodies
    width = np.minimum(hi - lo, 2.0 * np.pi)
    bound = MULTIPLIER_BOUND * model.theta[:, 0].sum() * (1.0 + np.linalg.norm(model.X_tree_p, axis=1).sum() ** 2)
    limits = [(bound * np.eye(6)[None], sign * BASIS[None], 21 * (j - 1) + np.arange(21), np.zeros((1, 6, 6)))
              for j in range(1, n - 1) for sign in (1.0, -1.0)]        # -bound 1 <= Lambda_j <= bound 1
    samples = [lo[i] + np.linspace(0.0, width[i], 2 + int(np.ceil(width[i] / MULTIPLIER_STEP))) for i in range(n)]
    checks = [lo[i] + np.linspace(0.0, width[i], 2 + int(np.ceil(width[i] / CHECK_STEP))) for i in range(n)]
    for _ in range(REFINEMENTS + 1):
        x, z = _multipliers([_chain_terms(model, i, samples[i], side, t) for i in range(1, n)] + limits, 21 * (n - 2))
        if not z > 0.0:                                          # infeasible on the samples: on the box too
            return False, 0
        added = False
        for i in range(1, n):
            C, F, var, S = _chain_terms(model, i, checks[i], side, t)
            L = np.linalg.inv(np.linalg.cholesky(S))
            margin = np.linalg.eigvalsh(L @ (C - np.einsum("p,bpij->bij", x[var], F)) @ np.swapaxes(L, 1, 2))[:, 0]
            low = (margin < 0.5 * z) & (margin <= np.r_[np.inf, margin[:-1]]) & (margin <= np.r_[margin[1:], np.inf])
            if low.any():                                        # local minima of the margin below z / 2
                samples[i], added = np.union1d(samples[i], checks[i][low]), True
        if not added:
            break
    grid, boxes = _fourier_grid(1)[0][:, 0], 0
    for i in range(1, n):
        C, F, var, _ = _chain_terms(model, i, grid, side, t)
        proven, used = _certify(C - np.einsum("p,bpij->bij", x[var], F), 1, lo[i:i + 1], hi[i:i + 1], max_boxes - boxes)
        boxes += used
        if not proven:
            return False, boxes
    return True, boxes


def _search_extremes(model, active, lo, hi, sampled):
    """Lower ``sampled[0]`` and raise ``sampled[1]`` (in place) to the extreme eigenvalues of ``M``
    at SEARCH_POINTS points of the box (a Sobol sequence over the ``active`` joints, Sobol 1967),
    refined by a bounded local search (L-BFGS-B, finite-difference gradients) from the best
    three of each."""
    Q = np.tile((lo + hi) / 2.0, (SEARCH_POINTS, 1))
    if active.any():
        Q[:, active] = qmc.scale(qmc.Sobol(np.count_nonzero(active), scramble=False).random(SEARCH_POINTS),
                                 lo[active], hi[active])
    w = np.linalg.eigvalsh(crba(model, Q))
    for k, col, sign in ((0, 0, 1.0), (1, -1, -1.0)):
        value = sign * w[:, col]                                # minimised
        best = [value.min()]
        for start in Q[np.argsort(value)[:3]]:                  # one state a call: no parallel launch
            res = minimize(lambda q: sign * np.linalg.eigvalsh(crba(model, q))[col], start, method="L-BFGS-B",
                           bounds=list(zip(lo, hi)))
            best.append(sign * np.linalg.eigvalsh(crba(model, np.clip(res.x, lo, hi)))[col])
        sampled[k] = sign * min(sign * sampled[k], min(best))


def inertia_bounds(model, lower=None, upper=None, *, rtol: float = 0.01, max_boxes: int = 20000) -> InertiaBounds:
    """Certified bounds of the eigenvalues of ``M(q)`` over a box of joint angles:

        lambda_m 1 <= M(q) <= lambda_M 1    for every q with lower <= q <= upper

    lower, upper: (nv,), radians; default the model's joint limits, ``[-pi, pi]`` where a joint
    has none. Returns :class:`InertiaBounds` ``(lambda_m, lambda_M, sampled_min, sampled_max,
    boxes)``. The bounds hold at every point of the box: by branch and bound over sub-boxes
    (module docstring: exact Fourier coefficients of ``M``, a first-order term exact at the
    boxes' vertices, a Taylor remainder relative to ``M`` at the box centre) and, for a serial
    chain of at least 3 joints that this has not settled within DIRECT_BOXES boxes, by the chain
    certificate (``s (M - t 1)`` as a sum of one term per body, each depending on one joint's
    angle, coupled by constant multipliers). They are within ``rtol`` (relative) of the sampled
    extremes unless ``max_boxes`` runs out first, and then still valid, only wider. More boxes
    never widen them.

    Equivalences: ``sampled_min``, ``sampled_max`` are eigenvalues of ``crba(model, q)`` at
    points of the box, so ``lambda_m <= sampled_min <= sampled_max <= lambda_M``. Revolute
    joints only; the armature is included, as in :func:`robodyn.crba`. Reference: the
    bounded-inertia property, Spong, Hutchinson & Vidyasagar (2006), 7.5.2.
    """
    if is_coupled(model):
        raise not_supported(model, "inertia_bounds", "M(q) after q_m = r q_s + o is a trigonometric polynomial of "
                                                     "a higher degree than the bounds take")
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
    evaluate = partial(_mass_matrix, model)
    c = (lo + hi) / 2.0
    r = np.minimum((hi - lo) / 2.0, np.pi)                      # M is 2 pi periodic: a full turn covers all
    heaps, sampled = {1: [], -1: []}, [np.inf, -np.inf]         # (side * bound, ...): the worst box first
    _push(evaluate, W, active, heaps, sampled, [1, -1], [c, c], [r, r], [low, -high])   # the global bounds hold

    def goal(side):
        extreme = sampled[0] if side > 0 else sampled[1]
        return side * extreme - rtol * abs(extreme)

    chain = rtol > 0 and n >= 3 and np.all(model.parent == np.arange(n) - 1)
    boxes = _branch_and_bound(evaluate, W, active, heaps, sampled, goal, 1,
                              min(max_boxes, DIRECT_BOXES) if chain else max_boxes)
    proven = {}                                                 # side: side * t of a chain certificate
    if chain and any(heaps[side][0][0] < goal(side) for side in heaps) and boxes < max_boxes:
        _search_extremes(model, active & (hi > lo), lo, hi, sampled)
        for side in [side for side in heaps if heaps[side][0][0] < goal(side)]:
            extreme = sampled[0] if side > 0 else sampled[1]
            for fraction in TARGETS:
                t = extreme - side * fraction * rtol * abs(extreme)
                ok, used = _chain_certificate(model, lo, hi, side, t, max_boxes - boxes)
                boxes += used
                if ok:
                    proven[side] = side * t
                    del heaps[side]
                    break
        boxes = _branch_and_bound(evaluate, W, active, heaps, sampled, goal, boxes, max_boxes)
    key = {side: heaps[side][0][0] for side in heaps} | proven
    return InertiaBounds(float(key[1]), float(-key[-1]), float(sampled[0]), float(sampled[1]), boxes)
