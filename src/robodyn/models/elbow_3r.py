"""``elbow_3r``: a three-link elbow (articulated) manipulator, standard DH.

Kinematic structure: the elbow manipulator of Spong, Hutchinson & Vidyasagar, *Robot
Modeling and Control*, Wiley 2006, chapter 3 (forward kinematics of the elbow
manipulator): base yaw joint 1 about the vertical ``z0``, then shoulder and elbow pitch
joints 2 and 3 about parallel horizontal axes.

    link   a_i    alpha_i   d_i    theta_i
    1      0      pi/2      d1     q1
    2      a2     0         0      q2
    3      a3     0         0      q3

At ``q = 0`` the arm is stretched horizontally along ``+x0``; ``q2 > 0`` raises it.

The book gives no numbers; these are this library's plausible choices (a table-top arm):
d1 = 0.4 m, a2 = 0.4 m, a3 = 0.35 m, and uniform solid cylinders

    link 1 (column):    m1 = 5 kg,   radius 0.08 m, length d1, vertical (y1 in DH frame 1),
                        centre of mass half way up: (0, -d1/2, 0) in frame 1
    link 2 (upper arm): m2 = 4 kg,   radius 0.04 m, length a2, along x2, centre (-a2/2, 0, 0)
    link 3 (forearm):   m3 = 2 kg,   radius 0.03 m, length a3, along x3, centre (-a3/2, 0, 0)

(standard DH frame ``i`` sits at the distal end of link ``i``, hence the negative offsets).
No joint limits, friction or rotor inertia.
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model
from ..inertia import cylinder

D1, A2, A3 = 0.4, 0.4, 0.35
MASSES = (5.0, 4.0, 2.0)
RADII = (0.08, 0.04, 0.03)


def links() -> list[DHLink]:
    """The DH table with the inertial data of the module docstring."""
    (m1, m2, m3), (r1, r2, r3) = MASSES, RADII
    return [
        DHLink(a=0.0, alpha=np.pi / 2, d=D1, mass=m1, com=(0.0, -D1 / 2, 0.0),
               inertia=cylinder(m1, r1, D1, "y")),
        DHLink(a=A2, alpha=0.0, d=0.0, mass=m2, com=(-A2 / 2, 0.0, 0.0),
               inertia=cylinder(m2, r2, A2, "x")),
        DHLink(a=A3, alpha=0.0, d=0.0, mass=m3, com=(-A3 / 2, 0.0, 0.0),
               inertia=cylinder(m3, r3, A3, "x")),
    ]


def build() -> Model:
    return from_dh(links(), convention="standard", name="elbow_3r")
