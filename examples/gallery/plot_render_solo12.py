"""
A 3-D render: Solo12 standing, and the forces of its feet
=========================================================

``rd.viewer.render`` draws a robot offscreen with matplotlib: the meshes of its URDF's
``<visual>`` elements (here the quadruped Solo12 of example-robot-data) on the bodies they were
merged into, placed by ``rd.forward_kinematics``. The pose is a standing one: the knees bent,
the base lowered until the feet touch the ground. For the picture's physics, the weight is shared by
the four feet: with the base at rest, the contact forces ``f_i`` satisfy the floating base's
six equations ``sum_i f_i = m g`` and ``sum_i p_i x f_i = c x m g`` (centre of mass ``c``);
with vertical forces, three equations for four feet: the least-norm forces. The centre of
mass sits behind the middle of the feet, so the hind feet carry more.
"""

import tempfile
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import robodyn as rd

urdf = rd.models.example_robot_urdf("solo12")
with warnings.catch_warnings():  # <contact> and gazebo elements have no rigid-body dynamics
    warnings.simplefilter("ignore", rd.RobodynWarning)
    model = rd.load_urdf(urdf, floating_base=True)
legs = np.tile([0.0, 0.8, -1.6], 4)  # hip abduction, hip flexion, knee of each leg
q = np.r_[0.0, 0.0, 0.24, 0.0, 0.0, 0.0, 1.0, legs]

feet = [f"{leg}_FOOT" for leg in ("FL", "FR", "HL", "HR")]
q[2] -= np.mean([rd.frame_pose(model, q, f)[2, 3] for f in feet])  # lowered until the feet touch z = 0
p = np.array([rd.frame_pose(model, q, f)[:3, 3] for f in feet])
m, g, c = model.total_mass, 9.81, rd.center_of_mass(model, q)
A = np.vstack([np.ones(4), p[:, 1], p[:, 0]])  # sum f_i, and the moments sum p_i x f_i about x and y
b = np.r_[m * g, c[1] * m * g, c[0] * m * g]
f = np.linalg.lstsq(A, b, rcond=None)[0]
print("foot heights (m):", p[:, 2].round(4), " vertical forces (N):", f.round(3), " weight:", round(m * g, 3))
assert np.allclose(p[:, 2], 0.0, atol=1e-12) and np.allclose(A @ f, b) and np.all(f > 0)

with tempfile.TemporaryDirectory() as tmp:
    png = rd.viewer.render(model, q, Path(tmp) / "solo12.png", visuals=urdf,
                           camera={"azimuth": 30, "elevation": 18})
    image = plt.imread(png)
fig, ax = plt.subplots(figsize=(8, 6))
ax.imshow(image)
ax.set_axis_off()
ax.set_title(f"Solo12, {m:.2f} kg: front feet {f[0]:.2f} N, hind feet {f[2]:.2f} N")
fig.tight_layout()
