"""Panda holding a pose under LQR, pushed at the hand.

    python examples/lqr_panda.py [--plot panda.png]

The built-in Panda holds the pose ``q*`` with the feed-forward ``tau* = g(q*)`` and the
discrete LQR gain ``K`` designed on ``rd.linearize`` (one RK4 step of ``dt``):
``tau = tau* - K [q ⊖ q*; v]`` (clipped at the joints' effort limits by the simulator). A
push of impulse ``p`` (N s, world axes) at the origin of the last link changes the velocity
by ``dv = M^-1 J^T [p; 0]`` (the impulsive form of ``M dv/dt = J^T f``); ``rd.simulate`` runs
the arm from there back to ``q*``, the controller evaluated at every stage of its RK4 steps
(close to the torque held over a step that the design assumes). Reference: Featherstone, RBDA (2008), section 11.1
(impulsive dynamics); Anderson and Moore, *Optimal Control* (1990), ch. 2 (discrete LQR).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.linalg import solve_discrete_are

import robodyn as rd

DT = 0.01
POSE = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])


def lqr_gain(model, q_star, dt: float = DT):
    """``(K, closed-loop eigenvalues)`` at the pose ``q_star`` held by gravity compensation."""
    zero = np.zeros(model.nv)
    A, B = rd.linearize(model, q_star, zero, rd.gravity(model, q_star), dt, "rk4")
    Q = np.diag(np.r_[np.full(model.nv, 100.0), np.full(model.nv, 1.0)])
    R = np.eye(model.nv) * 0.01
    P = solve_discrete_are(A, B, Q, R)
    K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)
    return K, np.linalg.eigvals(A - B @ K)


def run(impulse=(3.0, 0.0, 0.0), duration: float = 3.0):
    """The trajectory after a push of ``impulse`` (N s, world axes) at the last link's origin."""
    model = rd.models.load("panda")
    K, _ = lqr_gain(model, POSE)
    tau_star = rd.gravity(model, POSE)
    hand = model.nbodies - 1
    J = rd.jacobian(model, POSE, hand, frame="local_world_aligned")
    v0 = rd.inverse_mass_matrix(model, POSE) @ J.T @ np.r_[impulse, 0.0, 0.0, 0.0]

    def controller(t, q, v):
        return tau_star - K @ np.concatenate([rd.difference(model, POSE, q), v])

    return rd.simulate(model, POSE, v0, duration, DT, controller, "rk4", progress=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", help="save the joint errors to this image")
    args = parser.parse_args()
    model = rd.models.load("panda")
    _, eig = lqr_gain(model, POSE)
    traj = run()
    err = np.abs(traj.q - POSE).max(axis=1)
    print(f"closed-loop |eigenvalues| max {np.abs(eig).max():.4f}; after the push: largest joint error "
          f"{err.max():.3f} rad, at the end {err[-1]:.2e} rad")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(traj.t, traj.q - POSE, label=list(model.body_joint_names))
        ax.set_xlabel("time (s)")
        ax.set_ylabel("q - q* (rad)")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
