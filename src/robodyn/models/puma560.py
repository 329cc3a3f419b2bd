"""``puma560``: Unimation PUMA 560, standard DH, with the Armstrong/Corke dynamics.

Source of every number: P. Corke, Robotics Toolbox for Python, file
``roboticstoolbox/models/DH/Puma560.py`` (github.com/petercorke/robotics-toolbox-python,
commit 078064ded7a20389f87f0b903bd6cddc3d53d8ea), whose references are

* P. Corke and B. Armstrong-Helouvry, "A search for consensus among model parameters
  reported for the PUMA 560 robot", Proc. IEEE ICRA, San Diego, 1994, pp. 1608-1613
  (kinematic and dynamic parameters; D3 = 150.05 mm after Lee, AKB86 and Tarn), and
* Wang and Chen, "A combined optimization method for solving the inverse kinematics
  problem", IEEE Trans. Robotics and Automation 7(4), 1991, p. 489 ff. (joint limits).

``TABLE`` below copies that file: DH ``d, a, alpha`` (the base height 0.672 m from the
mounting surface to the shoulder is in ``d1``, as there); link mass ``m``; centre of mass
``r`` in DH frame ``i``; inertia about the centre of mass in frame ``i`` as
``[Lxx, Lyy, Lzz, Lxy, Lyz, Lxz]``; motor inertia ``Jm``; gear ratio ``G``; motor viscous
friction ``B`` and Coulomb friction ``Tc = [Tc+, Tc-]`` (applied for qd > 0 and qd < 0);
joint limits in degrees. ``q = 0`` is Corke's ``qz`` (the "L" pose: upper arm
horizontal along +x, forearm vertical); the wrist centre is then at
(0.4521, -0.15005, 1.1038) m.

Motor quantities are reflected to the joint (link side) exactly as Corke's ``Link.friction``
and ``rne`` do: armature ``G^2 Jm``, viscous friction ``G^2 B``, Coulomb friction
``|G| Tc``. robodyn has one symmetric Coulomb level per joint, so
``coulomb = |G| (Tc+ + |Tc-|) / 2``, the mean of Corke's two directions.

Two changes make the published set a physically consistent rigid-body model, which
robodyn requires (``ModelError`` otherwise); both are exact or tiny:

1. Link 1 has ``m = 0`` (Armstrong et al. found no value; it does not enter the dynamics)
   but ``Lyy = 0.35 kg m^2``: a massless body cannot have inertia. Frame 1's ``y`` axis is
   joint 1's axis, and link 1 only turns about that fixed axis, so its inertia adds a
   constant to ``M[0, 0]`` exactly like rotor inertia: it is added to joint 1's armature
   (``0.35 + G1^2 Jm1``) and link 1 is massless. Joint torques and ``M`` are unchanged;
   only switching armature off also drops these 0.35 kg m^2.
2. Link 3's principal moments (0.066, 0.086, 0.0125) violate the triangle inequality
   ``Lxx + Lzz >= Lyy`` (0.0785 < 0.086). ``Lzz``, the inertia about the forearm axis
   ``z3`` (never excited by joints 2 and 3, which turn link 3 about ``y3``; it enters only
   through joint 1's motion), is raised to ``Lyy - Lxx = 0.020`` (``LINK3_LZZ``), the
   smallest consistent value.
"""

from __future__ import annotations

import numpy as np

from ..io.dh import DHLink, from_dh
from ..model import Model

BASE_HEIGHT = 0.672
# d, a, alpha, m, r, I = [Lxx, Lyy, Lzz, Lxy, Lyz, Lxz], Jm, G, B, Tc = [Tc+, Tc-], qlim (deg)
TABLE = [
    dict(d=BASE_HEIGHT, a=0.0, alpha=np.pi / 2, m=0.0, r=(0.0, 0.0, 0.0), I=(0.0, 0.35, 0.0, 0.0, 0.0, 0.0),
         Jm=200e-6, G=-62.6111, B=1.48e-3, Tc=(0.395, -0.435), qlim=(-160.0, 160.0)),
    dict(d=0.0, a=0.4318, alpha=0.0, m=17.4, r=(-0.3638, 0.006, 0.2275), I=(0.13, 0.524, 0.539, 0.0, 0.0, 0.0),
         Jm=200e-6, G=107.815, B=0.817e-3, Tc=(0.126, -0.071), qlim=(-45.0, 225.0)),
    dict(d=0.15005, a=0.0203, alpha=-np.pi / 2, m=4.8, r=(-0.0203, -0.0141, 0.070),
         I=(0.066, 0.086, 0.0125, 0.0, 0.0, 0.0),
         Jm=200e-6, G=-53.7063, B=1.38e-3, Tc=(0.132, -0.105), qlim=(-225.0, 45.0)),
    dict(d=0.4318, a=0.0, alpha=np.pi / 2, m=0.82, r=(0.0, 0.019, 0.0), I=(1.8e-3, 1.3e-3, 1.8e-3, 0.0, 0.0, 0.0),
         Jm=33e-6, G=76.0364, B=71.2e-6, Tc=(11.2e-3, -16.9e-3), qlim=(-110.0, 170.0)),
    dict(d=0.0, a=0.0, alpha=-np.pi / 2, m=0.34, r=(0.0, 0.0, 0.0), I=(0.3e-3, 0.4e-3, 0.3e-3, 0.0, 0.0, 0.0),
         Jm=33e-6, G=71.923, B=82.6e-6, Tc=(9.26e-3, -14.5e-3), qlim=(-100.0, 100.0)),
    dict(d=0.0, a=0.0, alpha=0.0, m=0.09, r=(0.0, 0.0, 0.032), I=(0.15e-3, 0.15e-3, 0.04e-3, 0.0, 0.0, 0.0),
         Jm=33e-6, G=76.686, B=36.7e-6, Tc=(3.96e-3, -10.5e-3), qlim=(-266.0, 266.0)),
]
LINK1_LYY = TABLE[0]["I"][1]  # moved into joint 1's armature (change 1)
LINK3_LZZ = 0.020  # replaces 0.0125 (change 2)


def _inertia(L) -> np.ndarray:
    """3 x 3 matrix of Corke's ``[Lxx, Lyy, Lzz, Lxy, Lyz, Lxz]``."""
    xx, yy, zz, xy, yz, xz = L
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def links() -> list[DHLink]:
    """The DH table with dynamics reflected to the joints (see the module docstring)."""
    inertias = [_inertia(row["I"]) for row in TABLE]
    inertias[0] = np.zeros((3, 3))
    inertias[2][2, 2] = LINK3_LZZ
    out = []
    for i, (row, I) in enumerate(zip(TABLE, inertias)):
        G, (tc_pos, tc_neg) = row["G"], row["Tc"]
        armature = G**2 * row["Jm"] + (LINK1_LYY if i == 0 else 0.0)
        out.append(DHLink(
            a=row["a"], alpha=row["alpha"], d=row["d"], mass=row["m"], com=row["r"], inertia=I,
            lower=np.deg2rad(row["qlim"][0]), upper=np.deg2rad(row["qlim"][1]), armature=armature,
            damping=G**2 * row["B"], coulomb=abs(G) * (tc_pos + abs(tc_neg)) / 2.0,
        ))
    return out


def build() -> Model:
    return from_dh(links(), convention="standard", name="puma560")
