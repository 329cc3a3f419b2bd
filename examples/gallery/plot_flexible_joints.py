"""
Elastic joints: link and motor angles under composite control
=============================================================

Spong's elastic-joint model (1987): each motor, of inertia ``B``, drives its link through a
spring of stiffness ``K``,

    M(q) q'' + C(q, v) v + g(q) = K (theta - q),        B theta'' + K (theta - q) = u.

The double pendulum of ``rd.models`` moves along a quintic under the composite
(singular-perturbation) law of Spong, Khorasani and Kokotovic (1987):
``u = u_s + Kv (v - theta')``, ``u_s`` the computed torque of the rigid robot with the
motors' inertia. The motors lead the links by the springs' stretch ``theta - q = z / K``,
which carries the torque the links need; the links follow the rigid robot's critically damped
error dynamics up to ``O(1 / K)``. The last figure shows why the fast term is there: with the
rigid law alone, the elastic mode grows.
"""

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd
from robodyn import actuators

model = rd.models.load("double_pendulum")
q0, q1, B, K = np.array([0.4, -0.3]), np.array([-0.2, 0.5]), np.array([0.05, 0.05]), 2e3
reference = rd.control.quintic(q0, q1, 1.0)
theta0 = q0 + rd.gravity(model, q0) / K  # the springs hold the links still at the start
law = actuators.composite_tracking(model, reference, B, kp=100.0, kd=20.0, kv=2.0)
run = rd.simulate(model, q0, np.zeros(2), 1.5, 2e-4, controller=actuators.FlexibleJoints(model, K, B, law,
                                                                                          theta0=theta0),
                  integrator="rk4")
theta = run.controller_state[:, :2]
q_d = np.array([reference(t)[0] for t in run.t])
print("largest link tracking error:", np.abs(run.q - q_d).max(), "rad")
assert np.abs(run.q - q_d).max() < 1e-3

# %%
# The springs' torque ``K (theta - q)`` is the torque the links receive: nearly at rest at the end it
# equals gravity's, so the motors stay ``g(q1) / K`` ahead.
assert np.allclose(K * (theta[-1] - run.q[-1]), rd.gravity(model, run.q[-1]), rtol=1e-2, atol=5e-3)

rigid = rd.control.ComputedTorque(model.replace(armature=B), reference, 100.0, 20.0)
alone = actuators.FlexibleJoints(model, K, B, lambda t, q, v, th, thd: rigid(t, q, v), theta0=theta0)
ring = rd.simulate(model, q0, np.zeros(2), 0.6, 2e-4, controller=alone, integrator="rk4")

fig, axes = plt.subplots(3, 1, figsize=(7, 7.5))
for j in range(2):
    axes[0].plot(run.t, run.q[:, j], label=f"link q{j + 1}")
    axes[0].plot(run.t, theta[:, j], "--", label=f"motor theta{j + 1}")
axes[0].set_ylabel("angle (rad)")
axes[0].legend(fontsize=8, ncol=2)
axes[1].plot(run.t, 1e3 * (theta - run.q))
axes[1].set_ylabel("stretch theta - q (mrad)")
axes[2].plot(ring.t, 1e3 * (ring.controller_state[:, :2] - ring.q))
axes[2].set_ylabel("stretch, rigid law alone (mrad)")
axes[2].set_xlabel("t (s)")
fig.tight_layout()
