r"""
The acrobot balanced by LQR on ``rd.linearize``
===============================================

The double pendulum of ``rd.models`` (two point masses of 1 kg on massless links of 1 m,
``q = 0`` upright) with a motor at the elbow only is the acrobot (Spong, "The swing up
control problem for the Acrobot", IEEE Control Systems, 1995). The shoulder is made
unactuated by an effort limit of 0: the simulator clips its torque to zero, and
``rd.linearize`` gives it a zero column of ``B``.

``rd.linearize(model, q, v, tau, dt)`` is the exact derivative of one step of
``rd.simulate`` (RK4 by default), :math:`\delta x_{k+1} = A\,\delta x_k + B\,\delta u_k`. At
the upright equilibrium this is the RK4 step of the continuous linearisation

.. math::

   \delta\ddot q = M(0)^{-1} \left(-\frac{\partial g}{\partial q}(0)\, \delta q + \delta\tau\right),
   \quad M(0) = \begin{bmatrix} 5 & 2 \\ 2 & 1 \end{bmatrix}, \quad
   \frac{\partial g}{\partial q}(0) = -9.81 \begin{bmatrix} 3 & 1 \\ 1 & 1 \end{bmatrix},

so :math:`A = \sum_{k=0}^{4} (h A_c)^k / k!` exactly. The discrete LQR gain (Anderson and
Moore, *Optimal Control: Linear Quadratic Methods*, 1990) from the discrete algebraic
Riccati equation puts the closed loop's eigenvalues inside the unit circle, and the
nonlinear robot, pushed, comes back upright.
"""

import math

import matplotlib.pyplot as plt
import numpy as np
from scipy.linalg import solve_discrete_are

import robodyn as rd

acrobot = rd.models.load("double_pendulum").replace(effort_limit=[0.0, np.inf])
dt = 0.01
upright = np.zeros(2)
A, B = rd.linearize(acrobot, upright, upright, upright, dt)  # x = [q ⊖ q*, v], u = tau
assert np.all(B[:, 0] == 0.0)  # the shoulder has no motor

# %%
# The closed form: the double pendulum's mass matrix and gravity stiffness at the top, and
# the fourth-order Taylor polynomials of RK4.
M0 = np.array([[5.0, 2.0], [2.0, 1.0]])
K_gravity = 9.81 * np.array([[3.0, 1.0], [1.0, 1.0]])  # -dg/dq at q = 0
Ac = np.block([[np.zeros((2, 2)), np.eye(2)], [np.linalg.solve(M0, K_gravity), np.zeros((2, 2))]])
Bc = np.vstack([np.zeros((2, 2)), np.linalg.inv(M0)]) * [0.0, 1.0]  # elbow only
hA = dt * Ac
powers = [np.linalg.matrix_power(hA, k) for k in range(5)]
A_book = sum(P / math.factorial(k) for k, P in enumerate(powers))
B_book = dt * sum(P / math.factorial(k + 1) for k, P in enumerate(powers[:4])) @ Bc
print(f"|A - A_book| = {np.abs(A - A_book).max():.1e}, |B - B_book| = {np.abs(B - B_book).max():.1e}")
assert np.allclose(A, A_book, rtol=0, atol=1e-13) and np.allclose(B, B_book, rtol=0, atol=1e-15)


# %%
# And against the simulator itself: central differences of one ``rd.simulate`` step.
def step(x, u):
    """One step of the simulator from x = [q, v] under the joint forces u held over dt."""
    traj = rd.simulate(acrobot, x[:2], x[2:], dt, dt, controller=lambda t, q, v: u)
    return np.concatenate([traj.q[-1], traj.v[-1]])


h = 1e-6
A_fd = np.column_stack([(step(h * e, upright) - step(-h * e, upright)) / (2 * h) for e in np.eye(4)])
B_fd = np.column_stack([(step(np.zeros(4), h * e) - step(np.zeros(4), -h * e)) / (2 * h) for e in np.eye(2)])
print(f"|A - A_fd| = {np.abs(A - A_fd).max():.1e}, |B - B_fd| = {np.abs(B - B_fd).max():.1e}")
assert np.allclose(A, A_fd, rtol=0, atol=1e-8) and np.allclose(B, B_fd, rtol=0, atol=1e-8)

# %%
# Discrete LQR on the elbow's column: ``u = -K x`` minimises
# :math:`\sum x_k^T Q x_k + u_k^T R u_k`. Upright, the open loop has an eigenvalue far
# outside the unit circle; the closed loop's are all inside.
Q, R = np.diag([10.0, 10.0, 1.0, 1.0]), np.array([[1.0]])
B_elbow = B[:, 1:]
P = solve_discrete_are(A, B_elbow, Q, R)
K = np.linalg.solve(R + B_elbow.T @ P @ B_elbow, B_elbow.T @ P @ A)
A_closed = A - B_elbow @ K
open_loop, closed_loop = np.linalg.eigvals(A), np.linalg.eigvals(A_closed)
print("K =", K.round(2), "\n|eigenvalues| open loop:", np.abs(open_loop).round(4),
      "closed loop:", np.abs(closed_loop).round(4))
assert np.abs(open_loop).max() > 1.05 and np.abs(closed_loop).max() < 0.99
assert np.allclose(A.T @ P @ A - P - A.T @ P @ B_elbow @ K + Q, 0.0, atol=1e-7 * np.abs(P).max())  # the DARE


# %%
# A push, simulated as a digital controller would run: measure the state, compute the elbow
# torque, hold it for one step of the nonlinear simulator. The response follows the linear
# prediction :math:`x_k = (A - BK)^k x_0`, and closer and closer for smaller pushes: the
# difference shrinks as the cube of the push, the double pendulum having no quadratic terms
# about the top (its dynamics are odd in ``(q, v)`` there).
def run(x0, steps=600):
    x, states, torques = np.asarray(x0, dtype=float), [], []
    for _ in range(steps):
        states.append(x)
        torques.append(-(K @ x)[0])
        x = step(x, np.array([0.0, torques[-1]]))
    states.append(x)
    return np.array(states), np.array(torques)


push = np.array([0.0, 0.0, 0.05, -0.02])  # an impulse: initial joint velocities (rad/s)
x_sim, u_sim = run(push)
x_lin = np.array([np.linalg.matrix_power(A_closed, k) @ push for k in range(len(x_sim))])
t = dt * np.arange(len(x_sim))
print(f"largest angles {np.abs(x_sim[:, :2]).max(axis=0).round(3)} rad, peak elbow torque "
      f"{np.abs(u_sim).max():.2f} N m, final |x| {np.abs(x_sim[-1]).max():.1e}")
assert np.abs(x_sim[-1]).max() < 1e-5  # back upright, at rest
relative = []
for scale in (0.1, 0.01):
    small = run(scale * push, steps=150)[0]  # the largest differences come in the first 1.5 s
    relative.append(np.abs(small - scale * x_lin[:151]).max() / np.abs(small).max())
print("difference from the linear prediction, relative: push x 0.1:", f"{relative[0]:.1e},", "x 0.01:",
      f"{relative[1]:.1e}")
assert relative[0] < 1e-2 and relative[1] < relative[0] / 50

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [1.6, 1]})
for j, color in enumerate(("C0", "C1")):
    ax1.plot(t, x_sim[:, j], color=color, label=("shoulder", "elbow")[j] + " (simulated)")
    ax1.plot(t, x_lin[:, j], "--", color="k", lw=0.8)
ax1.plot([], [], "k--", lw=0.8, label="linear prediction")
ax1.set_xlabel("t (s)")
ax1.set_ylabel("angle from upright (rad)")
ax1.set_title("Recovery from a push")
ax1.legend(fontsize=8)
inset = ax1.inset_axes([0.6, 0.12, 0.37, 0.3])
inset.plot(t[:-1], u_sim, color="C2", lw=0.8)
inset.set_title("elbow torque (N m)", fontsize=7)
inset.tick_params(labelsize=6)
circle = np.exp(1j * np.linspace(0, 2 * np.pi, 200))
ax2.plot(circle.real, circle.imag, color="0.6", lw=0.8)
ax2.plot(open_loop.real, open_loop.imag, "x", color="C3", label="open loop, eig(A)")
ax2.plot(closed_loop.real, closed_loop.imag, "o", color="C0", label="closed loop, eig(A - BK)")
ax2.set_aspect("equal")
ax2.set_xlim(0.88, 1.08)
ax2.set_ylim(-0.1, 0.1)
ax2.set_title("Eigenvalues (unit circle in grey)")
ax2.legend(fontsize=8, loc="lower left")
fig.tight_layout()
