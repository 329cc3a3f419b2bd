"""A symplectic integrator for robots: the Störmer-Verlet method in momentum form.

With the momenta ``p = M(q) v`` and ``H(q, p) = p^T M(q)^-1 p / 2 + U(q)``, one step of
``dt = h`` is (Hairer, Lubich & Wanner, *Geometric Numerical Integration* (2006), VI.3,
eq. 3.4: the generalized leapfrog for non-separable Hamiltonians)

    p_1/2 = p_n + h/2 (F(q_n, p_1/2) + Q_n)                   implicit in p_1/2
    q_n+1 = q_n + h/2 (M(q_n)^-1 + M(q_n+1)^-1) p_1/2          implicit in q_n+1
    p_n+1 = p_1/2 + h/2 (F(q_n+1, p_1/2) + Q_n+1)              implicit in p_n+1 when Q depends on v

with ``F(q, p) = -dH/dq = C(q, v)^T v - g(q)`` at ``v = M(q)^-1 p`` (``C`` the
Christoffel-consistent Coriolis matrix, so that ``C^T v = dT/dq`` at constant ``v``) and
``Q`` the non-conservative joint forces (the clipped command, friction, external wrenches:
``M a + C v + g`` for the acceleration ``a`` of the dynamics), evaluated at the ends of the
step (Lagrange-d'Alembert). The implicit stages are solved by fixed-point iteration to
``TOL``. Without forcing the method is symplectic and time-reversible and of second order:
the energy error stays bounded, with no drift, over any number of steps, where explicit
methods drift (the semi-implicit Euler step in velocity form is not symplectic when ``M``
depends on ``q``). Fixed-base models of 1-dof joints (``nq == nv``); a controller's internal
state, if any, is advanced by an explicit Euler step. Runs from Python (about 0.3 ms per step
for a two-link arm).
"""

from __future__ import annotations

import numpy as np

from ..algorithms.coriolis import coriolis_matrix
from ..algorithms.crba import crba
from ..algorithms.rnea import rnea
from ..algorithms.terms import gravity

TOL = 1e-13          # relative change at which the fixed-point iterations stop
MAX_ITERATIONS = 50


def _fixed_point(update, x, what: str, t: float):
    for _ in range(MAX_ITERATIONS):
        new = update(x)
        if np.abs(new - x).max() <= TOL * max(1.0, np.abs(new).max()):
            return new
        x = new
    raise RuntimeError(f"symplectic step at t = {t}: the {what} did not converge in {MAX_ITERATIONS} iterations; "
                       "lower dt")


def run_symplectic(plant, law, q0, v0, dt, t, Q, V, Z, A, T, bar):
    """Fill the samples ``Q, V, Z, A, T`` (see ``simulate``) by Störmer-Verlet steps."""
    model = plant.model
    nv, nz = V.shape[1], Z.shape[1]
    n = Q.shape[0] - 1
    zero, thetadot, zdot = np.zeros(nv), np.empty(nv), np.empty(nz)
    Q[0], V[0] = q0, v0
    every = max(1, n // 100)
    h = 0.5 * dt

    def forcing(s):
        """The non-conservative joint forces ``Q = M a + C v + g`` at sample ``s`` (filling
        ``A[s]``, ``T[s]`` and the controller state's rate)."""
        plant.derivative(t[s], Q[s], zero, V[s], law, Z[s], T[s], thetadot, A[s], zdot)
        plant.keep(s)
        return rnea(model, Q[s], V[s], A[s], friction=False)

    def kick(q, Minv, g, base):
        """``p -> base + h F(q, p)``, ``F = C(q, v)^T v - g`` at ``v = M^-1 p``."""
        def update(p):
            v = Minv @ p
            return base + h * (coriolis_matrix(model, q, v).T @ v - g)
        return update

    Qnc = forcing(0)
    M = crba(model, Q[0])
    Minv = np.linalg.inv(M)
    for s in range(n):
        q, v = Q[s], V[s]
        p = M @ v
        p_half = _fixed_point(kick(q, Minv, gravity(model, q), p + h * Qnc), p, "half kick", t[s])
        v_half = Minv @ p_half
        Q[s + 1] = _fixed_point(lambda qn: q + h * (v_half + np.linalg.solve(crba(model, qn), p_half)),
                                q + dt * v_half, "drift", t[s])
        M = crba(model, Q[s + 1])
        Minv = np.linalg.inv(M)
        Z[s + 1] = Z[s] + dt * zdot
        base = kick(Q[s + 1], Minv, gravity(model, Q[s + 1]), p_half)(p_half)  # p_1/2 + h F(q_n+1, p_1/2)

        def end(p1, s=s):
            V[s + 1] = Minv @ p1
            return base + h * forcing(s + 1)

        V[s + 1] = Minv @ _fixed_point(end, base, "forcing at the end of the step", t[s])
        Qnc = forcing(s + 1)  # at the final velocity: A[s + 1], T[s + 1] and the next step's forcing
        if s % every == 0:
            bar.update(s)
