"""``panda``: Franka Emika Panda, 7 revolute joints, modified DH (Craig).

Kinematics and limits: Franka Emika, "Robot and interface specifications" / control
parameters documentation (frankaemika.github.io/docs/control_parameters.html), the
modified DH table (``a`` and ``alpha`` are ``a_{i-1}``, ``alpha_{i-1}``, as in
:class:`robodyn.DHLink`):

    joint   a (m)     d (m)    alpha (rad)
    1       0         0.333    0
    2       0         0        -pi/2
    3       0         0.316    pi/2
    4       0.0825    0        pi/2
    5       -0.0825   0.384    -pi/2
    6       0         0        pi/2
    7       0.088     0        pi/2
    flange  0         0.107    0          (fixed)

The flange is the extra frame ``"flange"`` (``Tz(0.107)`` from ``frame7``); at ``q = 0``
it sits at (0.088, 0, 0.926) m with its z axis pointing down. Position limits
q_min = (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973) rad,
q_max = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973) rad, velocity limits
(2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61) rad/s and torque limits
(87, 87, 87, 87, 12, 12, 12) N m, from the same page.

Dynamics: C. Gaz, M. Cognetti, A. Oliva, P. Robuffo Giordano, A. De Luca, "Dynamic
identification of the Franka Emika Panda robot with retrieval of feasible parameters using
penalty-based optimization", IEEE Robotics and Automation Letters 4(4), 2019,
pp. 4147-4154, supplementary material tables VIII and IX, as typed in the authors'
repository github.com/marcocognetti/FrankaEmikaPandaDynModel, file
``matlab/ConvertDynPars2VREP/DynPars2VREP.m`` (commit 04d453de): link masses, centres of
mass in the (modified DH) link frame ``i``, and inertia tensors about the centre of mass
with axes parallel to frame ``i`` (that script applies the parallel-axis theorem to them,
``GeneralizedSteiner``), given as ``[Ixx, Ixy, Ixz, Iyy, Iyz, Izz]``. That is what
:class:`robodyn.DHLink` expects, so they are used unchanged; all seven satisfy
robodyn's consistency checks (the paper retrieves physically feasible parameters). Link 1's
centre of mass along its axis is not identifiable (it does not enter the dynamics) and
is 0 in the paper. The friction model of the paper (a sigmoid per joint) has no
counterpart in robodyn's viscous + Coulomb model and is not included; no armature.
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model
from ._common import inertia_from_upper, with_frame

# a_{i-1}, d_i, alpha_{i-1}
DH = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -np.pi / 2),
    (0.0, 0.316, np.pi / 2),
    (0.0825, 0.0, np.pi / 2),
    (-0.0825, 0.384, -np.pi / 2),
    (0.0, 0.0, np.pi / 2),
    (0.088, 0.0, np.pi / 2),
]
FLANGE = 0.107
Q_MIN = (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973)
Q_MAX = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973)
VELOCITY = (2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100)
TORQUE = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)

# Gaz et al. 2019: mass (kg), centre of mass (m), inertia about it [Ixx, Ixy, Ixz, Iyy, Iyz, Izz]
MASS = (4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 7.35522e-01)
COM = (
    (3.875e-03, 2.081e-03, 0.0),
    (-3.141e-03, -2.872e-02, 3.495e-03),
    (2.7518e-02, 3.9252e-02, -6.6502e-02),
    (-5.317e-02, 1.04419e-01, 2.7454e-02),
    (-1.1953e-02, 4.1065e-02, -3.8437e-02),
    (6.0149e-02, -1.4117e-02, -1.0517e-02),
    (1.0517e-02, -4.252e-03, 6.1597e-02),
)
INERTIA = (
    (7.0337e-01, -1.3900e-04, 6.7720e-03, 7.0661e-01, 1.9169e-02, 9.1170e-03),
    (7.9620e-03, -3.9250e-03, 1.0254e-02, 2.8110e-02, 7.0400e-04, 2.5995e-02),
    (3.7242e-02, -4.7610e-03, -1.1396e-02, 3.6155e-02, -1.2805e-02, 1.0830e-02),
    (2.5853e-02, 7.7960e-03, -1.3320e-03, 1.9552e-02, 8.6410e-03, 2.8323e-02),
    (3.5549e-02, -2.1170e-03, -4.0370e-03, 2.9474e-02, 2.2900e-04, 8.6270e-03),
    (1.9640e-03, 1.0900e-04, -1.1580e-03, 4.3540e-03, 3.4100e-04, 5.4330e-03),
    (1.2516e-02, -4.2800e-04, -1.1960e-03, 1.0027e-02, -7.4100e-04, 4.8150e-03),
)


def links() -> list[DHLink]:
    """The modified DH table with Gaz et al.'s inertial parameters (module docstring)."""
    return [
        DHLink(a=a, alpha=alpha, d=d, mass=m, com=c, inertia=inertia_from_upper(*I),
               lower=lo, upper=hi, velocity=v, effort=t)
        for (a, d, alpha), m, c, I, lo, hi, v, t in zip(DH, MASS, COM, INERTIA, Q_MIN, Q_MAX, VELOCITY, TORQUE)
    ]


def build() -> Model:
    model = from_dh(links(), convention="modified", name="panda")
    return with_frame(model, "flange", "frame7", (0.0, 0.0, FLANGE))
