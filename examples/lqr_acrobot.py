"""LQR stabilisation of the acrobot upright, from ``rd.linearize``, simulated after a push.

    python examples/lqr_acrobot.py [--plot acrobot.png]

The double pendulum of ``rd.models`` (two 1 kg point masses on 1 m links, ``q = 0`` upright)
with a motor on the elbow only: the acrobot, modelled by an effort limit of 0 at the shoulder
(the simulator clips the shoulder's torque to 0, and ``rd.linearize`` gives its column of
``B`` as 0). The upright equilibrium ``(q, v) = 0`` needs no torque. ``rd.linearize`` gives
the discrete-time ``(A, B)`` of one RK4 step of ``dt``; the elbow's column of ``B`` is the
acrobot's input. The controller is evaluated at every stage of the simulator's RK4 steps,
close to (not exactly) the torque held over a step that the design assumes. The discrete
algebraic Riccati equation gives the gain ``K`` of ``u = -K [q ⊖ q*; v]``, and ``rd.simulate``
runs the nonlinear robot from a push (an initial velocity) under that law. Reference: Spong,
"The swing up control problem for the Acrobot", IEEE Control Systems 1995 (the acrobot);
Anderson and Moore, *Optimal Control: Linear Quadratic Methods* (1990), ch. 2 (discrete LQR).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.linalg import solve_discrete_are

import robodyn as rd

DT = 0.01
Q_WEIGHTS = np.diag([10.0, 10.0, 1.0, 1.0])
R_WEIGHT = np.array([[1.0]])


def acrobot():
    """The double pendulum without a shoulder motor (effort limit 0)."""
    return rd.models.load("double_pendulum").replace(effort_limit=[0.0, np.inf])


def lqr_gain(model, dt: float = DT):
    """``(K, closed-loop eigenvalues)`` of the acrobot's discrete LQR at the upright equilibrium."""
    x0 = np.zeros(model.nv)
    A, B = rd.linearize(model, x0, x0, x0, dt, "rk4")
    B = B[:, 1:]  # the elbow only (the shoulder's column is 0)
    P = solve_discrete_are(A, B, Q_WEIGHTS, R_WEIGHT)
    K = np.linalg.solve(R_WEIGHT + B.T @ P @ B, B.T @ P @ A)
    return K, np.linalg.eigvals(A - B @ K)


def run(push=(0.05, -0.02), duration: float = 8.0):
    """The trajectory of the acrobot under LQR after the push ``v0 = push`` (rad/s)."""
    model = acrobot()
    K, _ = lqr_gain(model)
    upright = np.zeros(model.nq)

    def controller(t, q, v):
        x = np.concatenate([rd.difference(model, upright, q), v])
        return np.array([0.0, -(K @ x)[0]])

    return rd.simulate(model, upright, np.asarray(push, dtype=float), duration, DT, controller, "rk4",
                       progress=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plot", help="save the joint angles and the elbow torque to this image")
    args = parser.parse_args()
    model = acrobot()
    K, eig = lqr_gain(model)
    print(f"K = {np.array2string(K[0], precision=2)}; closed-loop |eigenvalues| max {np.abs(eig).max():.4f}")
    traj = run()
    print(f"after the push: largest angle {np.abs(traj.q).max():.3f} rad, final angles "
          f"{np.array2string(traj.q[-1], precision=5)} rad, peak elbow torque {np.abs(traj.tau[:, 1]).max():.1f} N m")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
        ax1.plot(traj.t, traj.q, label=["shoulder", "elbow"])
        ax1.set_ylabel("angle from upright (rad)")
        ax1.legend()
        ax2.plot(traj.t, traj.tau[:, 1])
        ax2.set_ylabel("elbow torque (N m)")
        ax2.set_xlabel("time (s)")
        fig.tight_layout()
        fig.savefig(args.plot)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
