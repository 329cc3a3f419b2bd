"""Denavit-Hartenberg loader: ``from_dh(links, convention="standard" | "modified") -> Model``.

Standard DH (Denavit-Hartenberg 1955, as in Spong and Corke): link ``i`` carries frame ``i``
at its distal end and ``T_{i-1,i} = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; joint ``i``
moves about ``z_{i-1}``.

Modified DH (Craig 1986): frame ``i`` sits at joint ``i`` and
``T_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``; a :class:`DHLink` then holds
``a = a_{i-1}`` and ``alpha = alpha_{i-1}`` (the convention of Corke's toolbox).

The joint variable adds to the offset: ``theta_i = q_i + offset`` (revolute) or
``d_i = q_i + offset`` (prismatic). Mass, centre of mass and inertia (about the centre of
mass) are given in DH frame ``i``. The model's bodies are ``link1..linkn``; the DH frames are
kept as frames ``frame0`` (the base) to ``framen`` so that ``frame_pose(model, q, "frame3")``
is the DH product ``T_01 T_12 T_23``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..builder import ModelBuilder
from ..model import Model, ModelError


@dataclass(frozen=True)
class DHLink:
    """One row of a DH table plus the link's inertial and joint data (SI units, radians).

    ``armature`` is the rotor inertia reflected to the joint (``G^2 Jm``), ``damping`` viscous
    and ``coulomb`` Coulomb friction at the joint, ``lower``/``upper`` the joint limits.
    """

    a: float
    alpha: float
    d: float
    offset: float = 0.0
    joint: str = "revolute"
    mass: float = 0.0
    com: Sequence[float] = (0.0, 0.0, 0.0)
    inertia: np.ndarray | Sequence = field(default_factory=lambda: np.zeros((3, 3)))
    theta: float = 0.0
    lower: float = -np.inf
    upper: float = np.inf
    armature: float = 0.0
    damping: float = 0.0
    coulomb: float = 0.0
    effort: float = np.inf
    velocity: float = np.inf


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _hom(R=np.eye(3), p=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def dh_transform(link: DHLink, q: float, convention: str = "standard") -> np.ndarray:
    """The 4 x 4 DH transform ``T_{i-1,i}`` of one link at joint value ``q``."""
    theta, d = (q + link.offset, link.d) if link.joint == "revolute" else (link.theta, q + link.offset)
    if convention == "standard":
        return _hom(_rz(theta)) @ _hom(p=(0, 0, d)) @ _hom(p=(link.a, 0, 0)) @ _hom(_rx(link.alpha))
    return _hom(_rx(link.alpha)) @ _hom(p=(link.a, 0, 0)) @ _hom(_rz(theta)) @ _hom(p=(0, 0, d))


def from_dh(links: Sequence[DHLink], convention: str = "standard", gravity=(0.0, 0.0, -9.81),
            name: str = "dh_robot", base: np.ndarray | None = None) -> Model:
    """Model of a serial chain from its DH table (see the module docstring).

    ``base`` (4, 4) places frame 0 in the world (identity by default).
    """
    if convention not in ("standard", "modified"):
        raise ValueError(f"convention must be 'standard' or 'modified', got {convention!r}")
    links = list(links)
    if not links:
        raise ModelError("from_dh: empty DH table")
    b = ModelBuilder(name, gravity=gravity, source=f"DH table ({convention})")
    b.add_link("world")
    T0 = np.eye(4) if base is None else np.asarray(base, dtype=float)
    if T0.shape != (4, 4):
        raise ValueError(f"base: expected shape (4, 4), got {T0.shape}")
    b.add_link("frame0")
    b.add_joint("base_fixed", "fixed", "world", "frame0", xyz=T0[:3, 3], rotation=T0[:3, :3])
    for i, L in enumerate(links, start=1):
        where = f"DH table ({convention}): link {i}"
        if not isinstance(L, DHLink):
            raise ModelError(f"{where}: expected a DHLink, got {type(L).__name__}")
        if L.joint not in ("revolute", "prismatic"):
            raise ModelError(f"{where}: joint must be 'revolute' or 'prismatic', got {L.joint!r}")
        vals = [L.a, L.alpha, L.d, L.offset, L.theta]
        if not np.all(np.isfinite(np.asarray(vals, dtype=float))):
            raise ModelError(f"{where}: DH parameters must be finite, got {vals}")
        # pre: fixed part before the joint motion; post: fixed part after it (see docstring)
        if convention == "standard":
            pre = _hom(_rz(L.offset)) if L.joint == "revolute" else _hom(_rz(L.theta)) @ _hom(p=(0, 0, L.offset))
            post = (_hom(p=(0, 0, L.d)) if L.joint == "revolute" else np.eye(4)) @ _hom(p=(L.a, 0, 0)) @ _hom(_rx(L.alpha))
        else:
            pre = _hom(_rx(L.alpha)) @ _hom(p=(L.a, 0, 0))
            pre = pre @ (_hom(p=(0, 0, L.d)) @ _hom(_rz(L.offset)) if L.joint == "revolute"
                         else _hom(_rz(L.theta)) @ _hom(p=(0, 0, L.offset)))
            post = np.eye(4)
        b.add_link(f"link{i}", where=where)
        b.add_joint(f"joint{i}", L.joint, f"frame{i - 1}", f"link{i}", xyz=pre[:3, 3], rotation=pre[:3, :3],
                    axis=(0, 0, 1), lower=L.lower, upper=L.upper, velocity=L.velocity, effort=L.effort,
                    damping=L.damping, friction=L.coulomb, armature=L.armature, where=where)
        b.add_link(f"frame{i}", mass=L.mass, com=L.com, inertia=L.inertia, where=where)
        b.add_joint(f"frame{i}_fixed", "fixed", f"link{i}", f"frame{i}", xyz=post[:3, 3], rotation=post[:3, :3])
    return b.build()
