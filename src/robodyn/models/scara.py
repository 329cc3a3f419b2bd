"""``scara``: an RRPR SCARA arm, standard DH.

Kinematic structure: the SCARA manipulator of Spong, Hutchinson & Vidyasagar, *Robot
Modeling and Control*, Wiley 2006, chapter 3 (forward kinematics of the SCARA), with the
height ``d1`` of the arm plane above the base added (the book puts frame 0 in that plane):

    link   a_i    alpha_i   d_i          theta_i   joint
    1      a1     0         d1           q1        revolute, vertical axis z0
    2      a2     pi        0            q2        revolute, vertical axis z1
    3      0      0         q3           0         prismatic, along z2 (points DOWN)
    4      0      0         d4 = 0       q4        revolute, tool roll about z3

``q3`` is the downward stroke of the quill below the outer arm. Gravity acts along ``z2``
only, so the gravity torque is zero on joints 1, 2, 4 and ``-(m3 + m4) g`` on joint 3.

The book gives no numbers; these are this library's plausible choices for a SCARA of
0.6 m reach (not a specific product): d1 = 0.4 m, a1 = 0.325 m, a2 = 0.275 m, stroke
0 <= q3 <= 0.21 m, limits q1 in [-105, 105] deg, q2 in [-150, 150] deg,
q4 in [-360, 360] deg. Uniform solid cylinders:

    link 1 (inner arm): m1 = 6 kg,   radius 0.05 m, length a1 along x1, centre (-a1/2, 0, 0)
    link 2 (outer arm): m2 = 4 kg,   radius 0.04 m, length a2 along x2, centre (-a2/2, 0, 0)
    link 3 (quill):     m3 = 1 kg,   radius 0.01 m, length 0.3 m along z3, reaching up from
                        its tip (frame 3): centre (0, 0, -0.15)
    link 4 (flange):    m4 = 0.5 kg, radius 0.04 m, thickness 0.02 m about z4, centre 0
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model
from ..inertia import cylinder

D1, A1, A2 = 0.4, 0.325, 0.275
STROKE = 0.21
QUILL_LENGTH = 0.3
MASSES = (6.0, 4.0, 1.0, 0.5)


def links() -> list[DHLink]:
    """The DH table with the inertial data of the module docstring."""
    m1, m2, m3, m4 = MASSES
    deg = np.pi / 180.0
    return [
        DHLink(a=A1, alpha=0.0, d=D1, mass=m1, com=(-A1 / 2, 0.0, 0.0),
               inertia=cylinder(m1, 0.05, A1, "x"), lower=-105 * deg, upper=105 * deg),
        DHLink(a=A2, alpha=np.pi, d=0.0, mass=m2, com=(-A2 / 2, 0.0, 0.0),
               inertia=cylinder(m2, 0.04, A2, "x"), lower=-150 * deg, upper=150 * deg),
        DHLink(a=0.0, alpha=0.0, d=0.0, theta=0.0, joint="prismatic", mass=m3,
               com=(0.0, 0.0, -QUILL_LENGTH / 2), inertia=cylinder(m3, 0.01, QUILL_LENGTH, "z"),
               lower=0.0, upper=STROKE),
        DHLink(a=0.0, alpha=0.0, d=0.0, mass=m4, inertia=cylinder(m4, 0.04, 0.02, "z"),
               lower=-360 * deg, upper=360 * deg),
    ]


def build() -> Model:
    return from_dh(links(), convention="standard", name="scara")
