"""iLQR swing-up of the double pendulum, with the cost of every iteration.

    python examples/ilqr_double_pendulum.py [--plot ilqr.png]

The double pendulum of ``rd.models`` (two 1 kg point masses on 1 m links, a motor on each
joint, ``q = 0`` upright) starts hanging at rest, ``q = (pi, 0)``, and must reach the upright
equilibrium in ``T = 3 s``. The discrete dynamics are the semi-implicit Euler step of
``rd.simulate`` (``v+ = v + dt aba(q, v, u)``, ``q+ = q + dt v+``; the double pendulum's
effort limits are infinite, so nothing is clipped), linearised along the whole trajectory at
once by ``rd.linearize`` (one batched call per iteration). The cost is
quadratic: ``sum_k (x_k - x*)^T Q (x_k - x*) + u_k^T R u_k`` plus a terminal weight ``Qf``.
Each iteration solves the Riccati recursion backwards (with Levenberg-Marquardt
regularisation of ``Quu``) and rolls the new policy out with a backtracking line search.
Reference: Li and Todorov, "Iterative linear quadratic regulator design for nonlinear
biological movement systems", ICINCO 2004; Tassa, Erez and Todorov, "Synthesis and
stabilization of complex behaviors through online trajectory optimization", IROS 2012.
"""

from __future__ import annotations

import argparse

import numpy as np

import robodyn as rd

DT, HORIZON = 0.01, 300
Q = np.diag([0.0, 0.0, 0.0, 0.0])
R = np.diag([1e-2, 1e-2])
QF = np.diag([1e5, 1e5, 1e4, 1e4])


def rollout(model, x0, U, X=None, K=None, kff=None, alpha=1.0):
    """States (N+1, 2 nv) of the semi-implicit Euler step under ``U`` (N, nv), or under the
    policy ``u_k = U_k + alpha kff_k + K_k (x_k - X_k)``; returns ``(states, inputs)``."""
    n = model.nv
    xs, us = [x0], []
    for k in range(U.shape[0]):
        x = xs[-1]
        u = U[k] if K is None else U[k] + alpha * kff[k] + K[k] @ (x - X[k])
        v = x[n:] + DT * rd.aba(model, x[:n], x[n:], u)
        xs.append(np.concatenate([x[:n] + DT * v, v]))
        us.append(u)
    return np.array(xs), np.array(us)


def cost(X, U, target):
    d = X - target
    return 0.5 * (np.einsum("ki,ij,kj->", d[:-1], Q, d[:-1]) + np.einsum("ki,ij,kj->", U, R, U)
                  + d[-1] @ QF @ d[-1])


def ilqr(model, x0, target, iterations: int = 100, tol: float = 1e-6):
    """``(X, U, costs)``: the optimised trajectory and the cost after each iteration."""
    U = np.zeros((HORIZON, model.nv))
    X, U = rollout(model, x0, U)
    costs, mu = [cost(X, U, target)], 1e-6
    for _ in range(iterations):
        A, B = rd.linearize(model, X[:-1, :model.nv], X[:-1, model.nv:], U, DT,  # (N, 4, 4), (N, 4, 2)
                            "semi_implicit_euler")
        Vx, Vxx = QF @ (X[-1] - target), QF.copy()
        K, kff = np.zeros((HORIZON, model.nv, 2 * model.nv)), np.zeros((HORIZON, model.nv))
        for k in range(HORIZON - 1, -1, -1):
            Qx = Q @ (X[k] - target) + A[k].T @ Vx
            Qu = R @ U[k] + B[k].T @ Vx
            Qxx = Q + A[k].T @ Vxx @ A[k]
            Quu = R + B[k].T @ Vxx @ B[k] + mu * np.eye(model.nv)
            Qux = B[k].T @ Vxx @ A[k]
            kff[k] = -np.linalg.solve(Quu, Qu)
            K[k] = -np.linalg.solve(Quu, Qux)
            Vx = Qx + K[k].T @ Quu @ kff[k] + K[k].T @ Qu + Qux.T @ kff[k]
            Vxx = Qxx + K[k].T @ Quu @ K[k] + K[k].T @ Qux + Qux.T @ K[k]
            Vxx = 0.5 * (Vxx + Vxx.T)
        for alpha in 0.5 ** np.arange(10):
            Xn, Un = rollout(model, x0, U, X, K, kff, alpha)
            c = cost(Xn, Un, target)
            if c < costs[-1]:
                break
        else:  # no step decreased the cost: more regularisation
            mu *= 10.0
            continue
        mu = max(mu / 10.0, 1e-9)
        done = costs[-1] - c < tol * costs[-1]
        X, U = Xn, Un
        costs.append(c)
        if done:
            break
    return X, U, np.array(costs)


def swing_up(iterations: int = 100):
    model = rd.models.load("double_pendulum")
    x0 = np.array([np.pi, 0.0, 0.0, 0.0])  # hanging at rest
    return ilqr(model, x0, np.zeros(4), iterations)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", help="save the cost per iteration and the joint angles to this image")
    args = parser.parse_args()
    X, U, costs = swing_up()
    print(f"{len(costs) - 1} iterations, cost {costs[0]:.4g} -> {costs[-1]:.4g}; final state "
          f"{np.array2string(X[-1], precision=4)}, peak torques {np.array2string(np.abs(U).max(0), precision=1)} N m")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
        ax1.semilogy(costs, "o-")
        ax1.set_xlabel("iteration")
        ax1.set_ylabel("cost")
        t = np.arange(X.shape[0]) * DT
        ax2.plot(t, X[:, :2], label=["shoulder", "elbow"])
        ax2.set_xlabel("time (s)")
        ax2.set_ylabel("angle from upright (rad)")
        ax2.legend()
        fig.tight_layout()
        fig.savefig(args.plot)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
