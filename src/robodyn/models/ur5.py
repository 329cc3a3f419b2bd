"""``ur5``: Universal Robots UR5 (CB3), standard DH.

Kinematics, masses and centres of mass: Universal Robots, "DH parameters for calculations
of kinematics and dynamics" (universal-robots.com/articles/ur/application-installation/
dh-parameters-for-calculations-of-kinematics-and-dynamics/), UR5 table; the DH values are
also those of the CB3 user manual ("UR5 serie 3"):

    joint   a (m)      d (m)       alpha (rad)   mass (kg)   centre of mass in frame i (m)
    1       0          0.089159    pi/2          3.7         (0, -0.02561, 0.00193)
    2       -0.425     0           0             8.393       (0.2125, 0, 0.11336)
    3       -0.39225   0           0             2.33        (0.15, 0, 0.0265)
    4       0          0.10915     pi/2          1.219       (0, -0.0018, 0.01634)
    5       0          0.09465     -pi/2         1.219       (0, 0.0018, 0.01634)
    6       0          0.0823      0             0.1879      (0, 0, -0.001159)

``q = 0`` is UR's zero: the arm stretched horizontally along -x0; DH frame 6 is the tool
flange, at (-0.81725, -0.19145, -0.005491) m.

Universal Robots publish no inertia tensors for the UR5. We use the cylinder
approximations of the official ROS 2 description, github.com/UniversalRobots/
Universal_Robots_ROS2_Description, ``config/ur5/physical_parameters.yaml`` (commit
3426d674), ``tensor`` section, unchanged, re-expressed in the DH frames: each link is a
uniform cylinder about its centre of mass whose axis is, in DH frame ``i`` (derived from
that file's ``rotation`` section and its DH-to-URDF mapping of the centres of mass),

    link 1 (shoulder): y1    link 2 (upper arm): x2   link 3 (forearm): x3
    link 4 (wrist 1):  y4    link 5 (wrist 2):   y5   link 6 (wrist 3): z6

with the file's ``izz`` about the axis and ``ixx = iyy`` about the two other directions.
(The file computed the forearm tensor with the older mass 2.275 kg of ``urcontrol.conf``;
it is kept as published.) Joint limits from ``config/ur5/joint_limits.yaml`` of the same
repository (UR5 user manual; UR article "Max. joint torques"): +-2 pi (the elbow +-pi),
velocity pi rad/s, torque 150 N m (joints 1-3) and 28 N m (joints 4-6).
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model
from ..inertia import axisymmetric

# a, d, alpha
DH = [
    (0.0, 0.089159, np.pi / 2),
    (-0.425, 0.0, 0.0),
    (-0.39225, 0.0, 0.0),
    (0.0, 0.10915, np.pi / 2),
    (0.0, 0.09465, -np.pi / 2),
    (0.0, 0.0823, 0.0),
]
MASS = (3.7, 8.393, 2.33, 1.219, 1.219, 0.1879)
COM = (
    (0.0, -0.02561, 0.00193),
    (0.2125, 0.0, 0.11336),
    (0.15, 0.0, 0.0265),
    (0.0, -0.0018, 0.01634),
    (0.0, 0.0018, 0.01634),
    (0.0, 0.0, -0.001159),
)
# ROS 2 description, cylinder approximations: (izz about the axis, ixx = iyy), axis in frame i
CYLINDER = (
    (0.01040625, 0.014972358333333331, "y"),
    (0.0151074, 0.13388583541666665, "x"),
    (0.004095, 0.031216803515624995, "x"),
    (0.0021942, 0.002013889583333333, "y"),
    (0.0021942, 0.0018310395833333333, "y"),
    (0.0001321171875, 8.062475833333332e-05, "z"),
)
POSITION_LIMIT = (2 * np.pi, 2 * np.pi, np.pi, 2 * np.pi, 2 * np.pi, 2 * np.pi)
VELOCITY = np.pi
TORQUE = (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)


def links() -> list[DHLink]:
    """The DH table with UR's masses and centres of mass and ROS's inertias (module doc)."""
    return [
        DHLink(a=a, alpha=alpha, d=d, mass=m, com=c, inertia=axisymmetric(*cyl),
               lower=-lim, upper=lim, velocity=VELOCITY, effort=t)
        for (a, d, alpha), m, c, cyl, lim, t in zip(DH, MASS, COM, CYLINDER, POSITION_LIMIT, TORQUE)
    ]


def build() -> Model:
    return from_dh(links(), convention="standard", name="ur5")
