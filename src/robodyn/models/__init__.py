"""Built-in robots: ``load(name)`` and ``names()``.

    import robodyn as rd
    model = rd.models.load("panda")
    rd.models.names()   # ['pendulum', 'double_pendulum', ..., 'ur5']

=================  ===  ======  =========  ===========================================================
name               dof  joints  DH         source of the numbers (full citations in each module)
=================  ===  ======  =========  ===========================================================
pendulum           1    R       standard   point mass 1 kg at 1 m, ``q = 0`` upright (:mod:`.planar`)
double_pendulum    2    RR      standard   two point masses 1 kg at 1 m, ``q = 0`` upright
planar_2r          2    RR      standard   thin rods 10 kg / 5 kg, 1 m, vertical plane; Murray-Li-Sastry
                                           1994 and Spong et al. 2006 textbook arm
elbow_3r           3    RRR     standard   Spong et al. 2006 elbow manipulator; numbers ours
                                           (:mod:`.elbow_3r`)
scara              4    RRPR    standard   Spong et al. 2006 SCARA; numbers ours (:mod:`.scara`)
puma560            6    6R      standard   Corke & Armstrong-Helouvry 1994, via Corke's Robotics
                                           Toolbox ``Puma560`` (:mod:`.puma560`)
panda              7    7R      modified   Franka Emika DH and limits; Gaz et al., IEEE RA-L 2019
                                           dynamics (:mod:`.panda`)
ur5                6    6R      standard   Universal Robots DH, masses, centres of mass; ROS 2
                                           ur_description inertias (:mod:`.ur5`)
=================  ===  ======  =========  ===========================================================

Every robot is a :func:`robodyn.from_dh` chain: bodies ``link1..linkn``, joints
``joint1..jointn`` and DH frames ``frame0..framen`` (``panda`` adds ``flange``). SI units,
radians, gravity ``(0, 0, -9.81)``. Models are immutable, so ``load`` builds each robot
once and returns the same object afterwards.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Callable

from ..model import Model
from . import elbow_3r, panda, planar, puma560, scara, ur5

_BUILDERS: dict[str, Callable[[], Model]] = {
    "pendulum": planar.pendulum,
    "double_pendulum": planar.double_pendulum,
    "planar_2r": planar.planar_2r,
    "elbow_3r": elbow_3r.build,
    "scara": scara.build,
    "puma560": puma560.build,
    "panda": panda.build,
    "ur5": ur5.build,
}


def names() -> list[str]:
    """Names of the built-in robots, in the order of the table above."""
    return list(_BUILDERS)


def load(name: str) -> Model:
    """The built-in robot ``name`` (see :func:`names`); ``ValueError`` for an unknown name."""
    if not isinstance(name, str) or name not in _BUILDERS:
        raise ValueError(f"unknown built-in robot {name!r}; known: {', '.join(names())}")
    return _build(name)


@lru_cache(maxsize=None)
def _build(name: str) -> Model:
    return _BUILDERS[name]()


__all__ = ["load", "names", "example_robot_urdf"]


def example_robot_urdf(name: str):
    """The path of ``<name>.urdf`` in the robots of example-robot-data, when that package is
    installed (its wheel puts them under ``<site-packages>/cmeel.prefix/share/example-robot-data/
    robots``) and exactly one file has that name; else None. ``robodyn view solo12`` and the
    other commands find a robot by this name."""
    import site
    import sysconfig
    from pathlib import Path

    roots = {sysconfig.get_paths()[k] for k in ("purelib", "platlib")} | set(site.getsitepackages())
    for root in sorted(roots):
        robots = Path(root) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if robots.is_dir():
            hits = sorted(robots.glob(f"*/*/{name}.urdf"))
            if len(hits) == 1:
                return hits[0]
    return None
