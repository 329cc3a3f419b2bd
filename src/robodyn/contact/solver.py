"""The contact problem of one time step and its solver, compiled.

Model: velocity-level time stepping (Moreau 1988; Jean 1999; Stewart & Trinkle 1996), the
scheme of Bullet, ODE, Pinocchio 3's constraint solvers and, with a softened cone, MuJoCo.
Over a step of ``dt`` from ``(q, v)``, the impulses ``P_c = dt lambda_c`` (normal ``P_n``,
tangential ``P_t``) of the contacts change the velocity::

    M (v+ - v) = dt (tau - h(q, v)) + J^T P         (h = C v + g + friction: ``rnea(q, v, 0)``)
    v+ = v_f + M^-1 J^T P,     v_f = v + dt M^-1 (tau - h)
    u+ = J v+ = J v_f + G P,   G = J M^-1 J^T        (the Delassus matrix)

with, for every contact, in its frame (normal ``n`` out of the surface, tangents ``t1, t2``):

- unilateral normal impulse: ``0 <= P_n  _|_  u_n+ - b_n >= 0`` (Signorini at velocity
  level), the target ``b_n`` being ``-phi / dt`` for a gap ``phi > 0`` (the point may
  close the gap in this step but not cross it: no penetration, no early stop), a bounded
  push-out ``min(beta (-phi) / dt, v_max)`` for a penetration, and Newton's impact law
  ``u_n+ >= -e u_n-`` when the point approaches faster than ``bounce_speed``;
- Coulomb friction in the circular cone (not a pyramid): ``|P_t| <= mu P_n``; sticking
  (``u_t+ = 0``) inside the cone, sliding against the motion (``P_t = -mu P_n u_t+/|u_t+|``)
  on its boundary (maximal dissipation).

Then ``q+ = q ⊞ dt v+`` (semi-implicit Euler on the configuration manifold), the free and
planar joints' linear velocities (coordinates in the turning child frame) stepped by their
classical acceleration and turned into the next frame, so that a rolling or spinning body
keeps its speed (``simulation._contact_step.moving_frame_terms``).

Solver (:func:`solve`): ADMM on the cone complementarity problem with De Saxce's correction
``sigma = u + (mu |u_t|, 0, 0)`` (Carpentier et al., "From compliant to rigid contact
simulation: a unified and efficient approach", RSS 2024; Pinocchio's ``ADMMContactSolver``),
whose fixed points are exactly Coulomb's law, warm-started from the previous step's impulses;
when redundant contacts (four corners of a face) make it crawl, an active-set polish
(:func:`polish`). The residual (:func:`coulomb_residual`) is the largest velocity error of
Coulomb's law in m/s.

``G`` is formed from the Cholesky factor of ``M = L L^T``: ``Y = L^-1 J^T``, ``G = Y^T Y``,
and ``M^-1 J^T P = L^-T (Y P)``.
"""

from __future__ import annotations

import numpy as np

from .._jit import inline
from ..algorithms.dense import backward, cholesky, forward
from ..layout import IV, NDOF, PARENT

# ``settings`` entries (see ``geometry.Contacts``)
MAX_ITERATIONS, TOLERANCE, STABILIZATION, MAX_CORRECTION, BOUNCE_SPEED, MARGIN = range(6)
SETTINGS_SIZE = 6

# ADMM's settings (Pinocchio's defaults): over-relaxation, the initial penalty
# ``sqrt(L m) (L / m)^RHO_POWER`` and its factor ``(L / m)^RHO_POWER_FACTOR`` when the primal
# and dual residuals differ by more than ``RATIO_PRIMAL_DUAL``
TAU, RHO_POWER, RHO_POWER_FACTOR, RATIO_PRIMAL_DUAL = 0.5, 0.2, 0.05, 3.0
# ADMM iterations before the first active-set polish, and the polish's rounds per active set
POLISH_AFTER, POLISH_ROUNDS = 100, 40

# ``surfaces`` table columns (one row per surface, see ``geometry.Contacts.pack``): the kind,
# Coulomb's mu and Newton's e, then a plane's unit normal and height (``n . x <= height`` is
# solid), a box's centre, rotation (row-major, box to world) and half edges, or a sphere
# moving with a body: its centre in the body's frame, its radius and the body's index
KIND, FRICTION, RESTITUTION, NORMAL, HEIGHT, CENTER, ROTATION, HALF = 0, 1, 2, 3, 6, 3, 7, 16
RADIUS, BODY = 6, 7
SURFACE_COLUMNS = 19
PLANE, BOX, BODY_SPHERE = 0, 1, 2

# ``info`` entries of a step: the sweeps used, the last sweep's residual, the contacts solved
ITERATIONS, RESIDUAL, ACTIVE = range(3)
INFO_SIZE = 3


@inline
def surface_distance(row, x, radius, n, oR, op, y):
    """Signed distance (m) from the sphere of centre ``x`` (world) and ``radius`` to the solid
    surface of the table row ``row``, and the surface's outward unit normal at the nearest
    point into ``n`` (3,). A box: the nearest point of its surface from the centre taken in
    the box's frame (clamped to the half edges outside, the nearest face inside). A sphere on
    a body (world placements ``oR``, ``op``): along the line of the centres, its surface
    point facing ``x`` into ``y`` (3,)."""
    if row[KIND] == BODY_SPHERE:
        b = int(row[BODY])
        c0, c1, c2 = row[CENTER], row[CENTER + 1], row[CENTER + 2]
        for r in range(3):
            y[r] = op[b, r] + oR[b, r, 0] * c0 + oR[b, r, 1] * c1 + oR[b, r, 2] * c2
        d0, d1, d2 = x[0] - y[0], x[1] - y[1], x[2] - y[2]
        d = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if d > 0.0:
            n[0], n[1], n[2] = d0 / d, d1 / d, d2 / d
        else:  # concentric: any direction
            n[0], n[1], n[2] = 0.0, 0.0, 1.0
        for r in range(3):
            y[r] += row[RADIUS] * n[r]
        return d - row[RADIUS] - radius
    if row[KIND] == PLANE:
        for r in range(3):
            n[r] = row[NORMAL + r]
        return n[0] * x[0] + n[1] * x[1] + n[2] * x[2] - row[HEIGHT] - radius
    d0, d1, d2 = x[0] - row[CENTER], x[1] - row[CENTER + 1], x[2] - row[CENTER + 2]
    p0 = row[ROTATION] * d0 + row[ROTATION + 3] * d1 + row[ROTATION + 6] * d2  # R^T (x - c)
    p1 = row[ROTATION + 1] * d0 + row[ROTATION + 4] * d1 + row[ROTATION + 7] * d2
    p2 = row[ROTATION + 2] * d0 + row[ROTATION + 5] * d1 + row[ROTATION + 8] * d2
    h0, h1, h2 = row[HALF], row[HALF + 1], row[HALF + 2]
    e0, e1, e2 = p0 - min(max(p0, -h0), h0), p1 - min(max(p1, -h1), h1), p2 - min(max(p2, -h2), h2)
    out = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    if out > 0.0:
        b0, b1, b2, phi = e0 / out, e1 / out, e2 / out, out - radius
    else:  # the centre inside: out through the nearest face
        g0, g1, g2 = h0 - abs(p0), h1 - abs(p1), h2 - abs(p2)
        b0, b1, b2 = 0.0, 0.0, 0.0
        if g0 <= g1 and g0 <= g2:
            b0, depth = (1.0 if p0 >= 0.0 else -1.0), g0
        elif g1 <= g2:
            b1, depth = (1.0 if p1 >= 0.0 else -1.0), g1
        else:
            b2, depth = (1.0 if p2 >= 0.0 else -1.0), g2
        phi = -depth - radius
    for r in range(3):  # R b
        n[r] = row[ROTATION + 3 * r] * b0 + row[ROTATION + 3 * r + 1] * b1 + row[ROTATION + 3 * r + 2] * b2
    return phi


@inline
def contact_frame(n, F):
    """``F`` (3, 3): rows ``n``, ``t1``, ``t2`` (a right-handed orthonormal frame)."""
    a = 0 if abs(n[0]) <= abs(n[1]) and abs(n[0]) <= abs(n[2]) else (1 if abs(n[1]) <= abs(n[2]) else 2)
    d = n[a]
    t0, t1, t2 = -d * n[0], -d * n[1], -d * n[2]
    if a == 0:
        t0 += 1.0
    elif a == 1:
        t1 += 1.0
    else:
        t2 += 1.0
    s = 1.0 / np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    t0, t1, t2 = t0 * s, t1 * s, t2 * s
    for r in range(3):
        F[0, r] = n[r]
    F[1, 0], F[1, 1], F[1, 2] = t0, t1, t2
    F[2, 0] = n[1] * t2 - n[2] * t1
    F[2, 1] = n[2] * t0 - n[0] * t2
    F[2, 2] = n[0] * t1 - n[1] * t0


@inline
def point_rows(ints, oS, b, x, F, rows, sign):
    """``rows`` (3, nv) ``+= sign`` times the frame ``F``'s rows times the Jacobian of the
    velocity of the world point ``x`` moving with body ``b``: column ``k`` of that Jacobian is
    ``oS_k[:3] + oS_k[3:] x x`` (``oS`` the world-frame motion subspace columns)."""
    j = b
    while j >= 0:
        for k in range(ints[j, IV], ints[j, IV] + ints[j, NDOF]):
            w0, w1, w2 = oS[k, 3], oS[k, 4], oS[k, 5]
            c0 = oS[k, 0] + w1 * x[2] - w2 * x[1]
            c1 = oS[k, 1] + w2 * x[0] - w0 * x[2]
            c2 = oS[k, 2] + w0 * x[1] - w1 * x[0]
            for r in range(3):
                rows[r, k] += sign * (F[r, 0] * c0 + F[r, 1] * c1 + F[r, 2] * c2)
        j = ints[j, PARENT]


@inline
def delassus(L, Jc, m, Y, G):
    """``Y[:, :3m] = L^-1 Jc[:3m]^T`` and ``G[:3m, :3m] = Y^T Y = Jc M^-1 Jc^T``."""
    nv = L.shape[0]
    for r in range(3 * m):
        for i in range(nv):
            s = Jc[r, i]
            for k in range(i):
                s -= L[i, k] * Y[k, r]
            Y[i, r] = s / L[i, i]
    gram(Y, nv, 3 * m, G)


@inline
def gram(A, rows, cols, out):
    """``out[:cols, :cols] = A[:rows, :cols]^T A[:rows, :cols]`` (symmetric)."""
    for r in range(cols):
        for c in range(r + 1):
            s = 0.0
            for i in range(rows):
                s += A[i, r] * A[i, c]
            out[r, c] = s
            out[c, r] = s


@inline
def project_cone(mu, n, t1, t2):
    """The projection of ``(n, t1, t2)`` on the friction cone ``|t| <= mu n``."""
    t = np.sqrt(t1 * t1 + t2 * t2)
    if t <= mu * n:
        return n, t1, t2
    if mu * t <= -n:
        return 0.0, 0.0, 0.0
    a = (mu * t + n) / (mu * mu + 1.0)
    s = mu * a / t
    return a, s * t1, s * t2


@inline
def project_dual_cone(mu, n, t1, t2):
    """The projection of ``(n, t1, t2)`` on the dual cone ``mu |t| <= n`` (a half-space for ``mu = 0``)."""
    t = np.sqrt(t1 * t1 + t2 * t2)
    if mu * t <= n:
        return n, t1, t2
    if t <= -mu * n:
        return 0.0, 0.0, 0.0
    b = (t + mu * n) / (1.0 + mu * mu)
    s = b / t
    return mu * b, s * t1, s * t2


@inline
def coulomb_residual(G, g, mu, m, P, w):
    """How far the impulses ``P`` (3m,) (in the cones) are from Coulomb's law, in m/s: with
    ``w = G P + g`` (the contact velocities minus their targets, written to ``w``) and
    De Saxce's shifted velocity ``sigma = (w_n + mu |w_t|, w_t)``, the largest over the
    contacts of the distance of ``sigma`` from the dual cone and of its complementarity with
    ``P``: ``|sigma|`` when ``P`` lies inside the cone (sticking: no motion), the component of
    ``sigma`` along ``P`` on its boundary (sliding against the force), each weighted by
    ``|P_c| / max_c |P_c|`` (a contact that carries nothing may do anything)."""
    n = 3 * m
    for r in range(n):
        s = g[r]
        for j in range(n):
            s += G[r, j] * P[j]
        w[r] = s
    scale = 0.0
    for c in range(m):
        r = 3 * c
        scale = max(scale, np.sqrt(P[r] * P[r] + P[r + 1] * P[r + 1] + P[r + 2] * P[r + 2]))
    res = 0.0
    for c in range(m):
        r = 3 * c
        sn = w[r] + mu[c] * np.sqrt(w[r + 1] * w[r + 1] + w[r + 2] * w[r + 2])
        pn, p1, p2 = project_dual_cone(mu[c], sn, w[r + 1], w[r + 2])
        res = max(res, np.sqrt((sn - pn) ** 2 + (w[r + 1] - p1) ** 2 + (w[r + 2] - p2) ** 2))
        norm = np.sqrt(P[r] * P[r] + P[r + 1] * P[r + 1] + P[r + 2] * P[r + 2])
        if norm > 0.0:
            if np.sqrt(P[r + 1] * P[r + 1] + P[r + 2] * P[r + 2]) < mu[c] * P[r] * (1.0 - 1e-9):
                comp = np.sqrt(sn * sn + w[r + 1] * w[r + 1] + w[r + 2] * w[r + 2]) * norm
            else:
                comp = abs(sn * P[r] + w[r + 1] * P[r + 1] + w[r + 2] * P[r + 2])
            res = max(res, comp / scale)
    return res


@inline
def _factor(G, A, n, prox):
    """``A[:n, :n] = chol(G + prox I)``; False unless positive definite."""
    for r in range(n):
        for c in range(n):
            A[r, c] = G[r, c]
        A[r, r] += prox
    return cholesky(A[:n, :n])


@inline
def admm(G, g, mu, m, P, max_iterations, tolerance, ws):
    """ADMM on the cone complementarity problem (Carpentier et al. 2024; Pinocchio's
    ``ADMMContactSolver``) from the impulses ``P`` (3m,), written back: at most
    ``max_iterations``, until :func:`coulomb_residual` is at most ``tolerance``. ``ws``: the
    scratch of :func:`solve`. Returns ``(iterations, residual)``."""
    A, _, V = ws
    n = 3 * m
    x, y, z, rhs, xp, yp, w = V[0, :n], V[1, :n], V[2, :n], V[3, :n], V[4, :n], V[5, :n], V[6, :n]
    L = 0.0  # the largest eigenvalue of G, bounded by its largest absolute row sum (Gershgorin)
    for r in range(n):
        s = 0.0
        for j in range(n):
            s += abs(G[r, j])
        L = max(L, s)
    prox_mu = 1e-6 * L
    cond = L / prox_mu
    rho = np.sqrt(L * prox_mu) * cond ** RHO_POWER
    increment = cond ** RHO_POWER_FACTOR
    for c in range(m):
        r = 3 * c
        y[r], y[r + 1], y[r + 2] = project_cone(mu[c], P[r], P[r + 1], P[r + 2])
    for r in range(n):
        x[r] = y[r]
    res = coulomb_residual(G, g, mu, m, y, w)
    for c in range(m):  # z: the shifted velocity, in the dual cone
        r = 3 * c
        sn = w[r] + mu[c] * np.sqrt(w[r + 1] * w[r + 1] + w[r + 2] * w[r + 2])
        z[r], z[r + 1], z[r + 2] = project_dual_cone(mu[c], sn, w[r + 1], w[r + 2])
    it = 0
    factored = _factor(G, A, n, prox_mu + TAU * rho)
    while res > tolerance and it < max_iterations and factored:
        it += 1
        tr = TAU * rho
        for c in range(m):
            r = 3 * c
            shift = mu[c] * np.sqrt(z[r + 1] * z[r + 1] + z[r + 2] * z[r + 2])
            for k in range(r, r + 3):
                rhs[k] = -g[k] + tr * y[k] + prox_mu * x[k] + z[k]
                xp[k], yp[k] = x[k], y[k]
            rhs[r] -= shift
        forward(A[:n, :n], rhs)
        backward(A[:n, :n], rhs)
        primal, dual = 0.0, 0.0
        for c in range(m):
            r = 3 * c
            y[r], y[r + 1], y[r + 2] = project_cone(mu[c], rhs[r] - z[r] / tr, rhs[r + 1] - z[r + 1] / tr,
                                                    rhs[r + 2] - z[r + 2] / tr)
            for k in range(r, r + 3):
                x[k] = rhs[k]
                z[k] -= tr * (x[k] - y[k])
                primal = max(primal, abs(x[k] - y[k]))
                dual = max(dual, abs(tr * (y[k] - yp[k]) + prox_mu * (x[k] - xp[k])))
        res = coulomb_residual(G, g, mu, m, y, w)
        if primal > RATIO_PRIMAL_DUAL * dual:
            rho *= increment
            factored = _factor(G, A, n, prox_mu + TAU * rho)
        elif dual > RATIO_PRIMAL_DUAL * primal:
            rho /= increment
            factored = _factor(G, A, n, prox_mu + TAU * rho)
    for r in range(n):
        P[r] = y[r]
    return it, res


@inline
def _active_set_step(G, g, mu, m, Q, sep, ws):
    """One step of the active-set polish: with the contacts flagged in ``sep`` apart
    (``P_c = 0``), those inside their cone sticking (``u_c = 0``) and the others sliding
    against their current tangential velocity ``d`` (``u_n = 0``, ``P_t = mu P_n d``), the
    least-squares solution of these linear equations (redundant contacts make them
    singular), projected on the cones, into ``Q``."""
    A, N, V = ws
    n = 3 * m
    w, b = V[7, :n], V[8, :n]
    for r in range(n):
        s = g[r]
        for j in range(n):
            s += G[r, j] * Q[j]
        w[r] = s
        b[r] = 0.0
        for j in range(n):
            A[r, j] = 0.0
    for c in range(m):
        r = 3 * c
        t = np.sqrt(Q[r + 1] * Q[r + 1] + Q[r + 2] * Q[r + 2])
        if sep[c] > 0.0:
            for k in range(r, r + 3):
                A[k, k] = 1.0
        elif t < mu[c] * Q[r] * (1.0 - 1e-6):
            for k in range(r, r + 3):
                b[k] = -g[k]
                for j in range(n):
                    A[k, j] = G[k, j]
        else:
            b[r] = -g[r]
            for j in range(n):
                A[r, j] = G[r, j]
            wt = np.sqrt(w[r + 1] * w[r + 1] + w[r + 2] * w[r + 2])
            d1, d2 = 0.0, 0.0
            if wt > 0.0:
                d1, d2 = -w[r + 1] / wt, -w[r + 2] / wt
            elif t > 0.0:
                d1, d2 = Q[r + 1] / t, Q[r + 2] / t
            A[r + 1, r + 1], A[r + 1, r] = 1.0, -mu[c] * d1
            A[r + 2, r + 2], A[r + 2, r] = 1.0, -mu[c] * d2
    gram(A, n, n, N)  # N = A^T A + eps I, rhs = A^T b
    trace = 0.0
    for r in range(n):
        trace += N[r, r]
        s = 0.0
        for k in range(n):
            s += A[k, r] * b[k]
        w[r] = s
    for r in range(n):
        N[r, r] += 1e-14 * trace / n + 1e-300
    if not cholesky(N[:n, :n]):
        return False
    forward(N[:n, :n], w)
    backward(N[:n, :n], w)
    for c in range(m):
        r = 3 * c
        Q[r], Q[r + 1], Q[r + 2] = project_cone(mu[c], w[r], w[r + 1], w[r + 2])
    return True


@inline
def polish(G, g, mu, m, P, residual, tolerance, ws):
    """Active-set polish of impulses ``P`` near a solution whose iterations stall, as when
    redundant contacts (a box's face) must shift their load between them, a motion the
    contact velocities do not see: for ``k = 0, 1, ...`` the ``k`` contacts separating
    fastest set apart, rounds of :func:`_active_set_step` (the sliding directions updated
    each round) while the residual falls. Keeps the best impulses in ``P``; returns their
    residual."""
    _, _, V = ws
    n = 3 * m
    w0, Q, best, sep, w = V[9, :n], V[10, :n], V[11, :n], V[12, :n], V[6, :n]
    coulomb_residual(G, g, mu, m, P, w0)
    for r in range(n):
        best[r] = P[r]
        sep[r] = 0.0
    for k in range(m + 1):
        if k > 0:  # set apart the separating contact with the largest normal velocity
            pick, fastest = -1, 0.0
            for c in range(m):
                if sep[c] == 0.0 and w0[3 * c] > fastest:
                    pick, fastest = c, w0[3 * c]
            if pick < 0:
                break
            sep[pick] = 1.0
        for r in range(n):
            Q[r] = P[r]
        previous = np.inf
        for _ in range(POLISH_ROUNDS):
            if not _active_set_step(G, g, mu, m, Q, sep, ws):
                break
            res = coulomb_residual(G, g, mu, m, Q, w)
            if res < residual:
                residual = res
                for r in range(n):
                    best[r] = Q[r]
            if res <= tolerance or res > 0.7 * previous:
                break
            previous = res
        if residual <= tolerance:
            break
    for r in range(n):
        P[r] = best[r]
    return residual


@inline
def solve(G, g, mu, m, P, max_iterations, tolerance, info, ws):
    """The impulses ``P`` (3m,) of ``m`` contacts (read as the warm start, written) such that
    ``P`` lies in the friction cones and ``u = G P + g`` satisfies Coulomb's law with De
    Saxce's shift (see the module docstring): ADMM (:func:`admm`), and when it has not
    converged after ``POLISH_AFTER`` iterations an active-set polish (:func:`polish`), then
    ADMM again from there up to ``max_iterations`` and a last polish. ``g``: the free contact
    velocities minus the normal targets; ``ws = (A, N, V)``: (3m, 3m), (3m, 3m) and
    (13, 3m) scratch. Writes ``info[ITERATIONS]`` and ``info[RESIDUAL]``
    (:func:`coulomb_residual`, m/s)."""
    it, res = admm(G, g, mu, m, P, min(max_iterations, POLISH_AFTER), tolerance, ws)
    if res > tolerance:
        res = polish(G, g, mu, m, P, res, tolerance, ws)
    if res > tolerance and it < max_iterations:
        more, res = admm(G, g, mu, m, P, max_iterations - it, tolerance, ws)
        it += more
        if res > tolerance:
            res = polish(G, g, mu, m, P, res, tolerance, ws)
    info[ITERATIONS] = it
    info[RESIDUAL] = res
