"""Build a :class:`Model` from links and joints (the graph form every loader produces).

The builder checks the graph (duplicate or missing names, several roots, two parents, cycles,
all without recursion), orders the bodies depth first (children in the order their joints
were added, as URDF parsers do), merges fixed joints into their parent body with the
parallel-axis theorem and keeps every merged link as a frame.

Physical consistency (mass, positive semi-definite inertia about the centre of mass, triangle
inequality, no inertia without mass) is checked on the bodies the dynamics uses, after the
merge: a placeholder link (a massless ``base`` with a tiny inertia, a foot frame with an inertia
and no mass) that a fixed joint merges into a consistent body is fine, as are links welded to
the world. A body that fails names every link merged into it and what each one carries. Links
are checked alone only for what no merge can repair: non-finite values, an asymmetric inertia,
a negative mass.

Links are added with :meth:`ModelBuilder.add_link` (mass, centre of mass, 3 x 3 inertia about
it: see :mod:`robodyn.inertia`), joints with :meth:`ModelBuilder.add_joint` (types
``revolute``, ``continuous``, ``prismatic``, ``helical``, ``fixed``, ``planar``,
``spherical``, ``free`` and ``universal``). The root is the one link without a parent; a
joint whose parent is ``"world"`` attaches to the world without an ``add_link("world")``.

Example::

    b = ModelBuilder("arm")
    b.add_link("link1", mass=1.0, com=(0.5, 0, 0), inertia=np.diag([0, 0.1, 0.1]))
    b.add_joint("j1", "revolute", "world", "link1", axis=(0, 0, 1))
    model = b.build()
"""

from __future__ import annotations

import math
import operator
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import joints as J
from .errors import RobodynWarning, user_stacklevel
from .model import (Model, ModelError, check_inertial_parameters, consistent_inertial_parameters,
                    inertial_parameters_from, repair_note, repaired_inertial_parameters)

WORLD = "world"  # a joint's parent link of this name needs no add_link: the fixed root
JOINT_TYPES = {"revolute": J.REVOLUTE, "continuous": J.REVOLUTE, "prismatic": J.PRISMATIC, "free": J.FREE,
               "spherical": J.SPHERICAL, "helical": J.HELICAL, "planar": J.PLANAR, "fixed": None}


def rpy_to_matrix(rpy) -> np.ndarray:
    """Rotation of URDF roll-pitch-yaw angles: extrinsic X-Y-Z, ``R = Rz(y) Ry(p) Rx(r)``."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


def _rpy_matrices(rpy) -> np.ndarray:
    """:func:`rpy_to_matrix` of many angle triples ``rpy`` (n, 3) at once, (n, 3, 3): the same
    operations, element for element."""
    rpy = np.asarray(rpy, dtype=float).reshape(-1, 3)
    (cr, cp, cy), (sr, sp, sy) = np.cos(rpy).T, np.sin(rpy).T
    R = np.empty((rpy.shape[0], 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr
    R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr
    R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = -sp, cp * sr, cp * cr
    return R


def _matvec(A, x) -> np.ndarray:
    """``A[k] @ x[k]`` for every k, (n, 3): the matrix-vector product of NumPy for one pair."""
    return (A @ x[:, :, None])[:, :, 0]


def _dot(x, y) -> np.ndarray:
    """``x[k] @ y[k]`` for every k, (n,): the dot product of NumPy for one pair."""
    return (x[:, None, :] @ y[:, :, None])[:, 0, 0]


def _parameters_from(mass, com, inertia_com) -> np.ndarray:
    """:func:`~robodyn.model.inertial_parameters_from` of n bodies at once, (n, 10): ``mass``
    (n,), ``com`` (n, 3), ``inertia_com`` (n, 3, 3); the same operations, body for body."""
    m, c = mass[:, None, None], com
    Io = inertia_com + m * (_dot(c, c)[:, None, None] * np.eye(3) - c[:, :, None] * c[:, None, :])
    h = mass[:, None] * c
    return np.column_stack([mass, h, Io[:, 0, 0], Io[:, 0, 1], Io[:, 1, 1], Io[:, 0, 2], Io[:, 1, 2], Io[:, 2, 2]])


def _parameters_in_parent(R, p, theta) -> np.ndarray:
    """:func:`~robodyn.model.inertial_parameters_in_parent` of n bodies at once, (n, 10): ``R``
    (n, 3, 3), ``p`` (n, 3), ``theta`` (n, 10); the same operations, body for body."""
    n = theta.shape[0]
    m = theta[:, 0]
    hr = _matvec(R, theta[:, 1:4])
    Io = theta[:, [4, 5, 7, 5, 6, 8, 7, 8, 9]].reshape(n, 3, 3)
    s = _dot(2.0 * p, hr) + m * _dot(p, p)
    I = (R @ Io @ R.transpose(0, 2, 1) - p[:, :, None] * hr[:, None, :] - hr[:, :, None] * p[:, None, :]
         + s[:, None, None] * np.eye(3) - m[:, None, None] * (p[:, :, None] * p[:, None, :]))
    h = hr + m[:, None] * p
    return np.column_stack([m, h, I[:, 0, 0], I[:, 0, 1], I[:, 1, 1], I[:, 0, 2], I[:, 1, 2], I[:, 2, 2]])


@dataclass
class LinkEntry:
    """A link as added: its 10 inertial parameters and where it was defined. ``where`` is text,
    or an object whose ``str`` is that text (a loader's, made only when a message needs it);
    ``theta`` is None for a link added by :meth:`ModelBuilder._add_link_values` until
    :meth:`ModelBuilder.build`."""

    name: str
    theta: np.ndarray
    where: str

    def issue(self) -> str:
        """Why the link alone is not a consistent rigid body ("" if it is); asked only when
        the body it merges into fails."""
        try:
            check_inertial_parameters(self.theta, self.where)
            return ""
        except ModelError as e:
            return str(e)


@dataclass
class JointEntry:
    """A joint as added: type, parent and child links, placement, axis, limits (``R``, ``p``
    and ``axis`` are None for a joint added by :meth:`ModelBuilder._add_joint_values` until
    :meth:`ModelBuilder.build`; ``where`` as in :class:`LinkEntry`)."""

    name: str
    type: str
    parent: str
    child: str
    R: np.ndarray
    p: np.ndarray
    axis: np.ndarray
    limits: dict = field(default_factory=dict)
    where: str = ""
    pitch: float = 0.0


_FREE_LIMITS = dict(lower=-np.inf, upper=np.inf, velocity=np.inf, effort=np.inf, damping=0.0, friction=0.0,
                    armature=0.0, stiffness=0.0, spring_reference=0.0)
_LIMIT_KEYS = tuple(_FREE_LIMITS)
_limit_values = operator.itemgetter(*_LIMIT_KEYS)


class ModelBuilder:
    """Collects links and joints, then :meth:`build` returns the immutable :class:`Model`."""

    def __init__(self, name: str = "robot", gravity=(0.0, 0.0, -9.81), source: str = "<model>",
                 physical: str = "error"):
        """``physical="error"`` rejects unphysical link inertias with a :class:`ModelError`;
        ``physical="warn"`` keeps them as given and warns (for descriptions known to carry
        such values, e.g. some published URDFs); ``physical="repair"`` makes each such body
        consistent and warns by how much (:func:`robodyn.model.repaired_inertial_parameters`:
        negative principal moments raised to 0, then MuJoCo's ``balanceinertia`` rule)."""
        if physical not in ("error", "warn", "repair"):
            raise ValueError(f"physical must be 'error', 'warn' or 'repair', got {physical!r}")
        self.physical = physical
        self.name = name
        self.gravity = np.asarray(gravity, dtype=float)
        self.source = source
        self._links: dict[str, LinkEntry] = {}
        self._joints: list[JointEntry] = []
        # links and joints added from plain numbers, whose arrays build() computes at once
        self._pending_links: list[tuple] = []
        self._pending_joints: list[tuple] = []

    def add_link(self, name: str, mass: float = 0.0, com=(0.0, 0.0, 0.0), inertia=None,
                 inertia_rotation=None, where: str | None = None) -> None:
        """A rigid body: ``mass`` (kg), ``com`` (3,) in the link frame, ``inertia`` (3, 3) about
        the centre of mass in axes rotated by ``inertia_rotation`` from the link frame
        (applied as ``R I R^T``)."""
        where = where or f"{self.source}: link {name!r}"
        if name in self._links:
            raise ModelError(f"{where}: duplicate link name {name!r} (first defined at {self._links[name].where})")
        mass = float(mass)
        com = np.asarray(com, dtype=float).reshape(3)
        Ic = np.zeros((3, 3)) if inertia is None else np.asarray(inertia, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(Ic)) or not np.isfinite(mass) or not np.all(np.isfinite(com)):
            raise ModelError(f"{where}: mass, centre of mass and inertia must be finite")
        if np.abs(Ic - Ic.T).max() > 1e-9 * max(np.abs(Ic).max(), 1e-300):
            raise ModelError(f"{where}: inertia matrix is not symmetric")
        if inertia_rotation is not None:
            Rr = np.asarray(inertia_rotation, dtype=float)
            Ic = Rr @ Ic @ Rr.T
        if mass < 0:
            raise ModelError(f"{where}: negative mass {mass}")
        self._links[name] = LinkEntry(name, inertial_parameters_from(mass, com, Ic), where)

    def _add_link_values(self, name: str, mass: float, com: tuple, inertia: tuple | None, rpy: tuple | None,
                         where) -> None:
        """:meth:`add_link` from finite floats (a loader's fast path): ``com`` (x, y, z),
        ``inertia`` ``(ixx, ixy, ixz, iyy, iyz, izz)`` or None, its axes rotated by the
        roll-pitch-yaw angles ``rpy`` (``rotation=rpy_to_matrix(rpy)``) or None; ``where`` text
        or an object formatting to it. The same checks and, in :meth:`build`, bit for bit the
        same parameters as :meth:`add_link` (finite and symmetric by construction)."""
        if name in self._links:
            raise ModelError(f"{where}: duplicate link name {name!r} (first defined at {self._links[name].where})")
        if mass < 0:
            raise ModelError(f"{where}: negative mass {mass}")
        entry = LinkEntry(name, None, where)
        self._links[name] = entry
        self._pending_links.append((entry, mass, com, inertia, rpy))

    def _check_body(self, theta, name: str, links: list[LinkEntry]) -> np.ndarray:
        """Check the merged body ``name`` (``theta``), made of ``links``; raise (or warn, with
        ``physical="warn"``) naming each link and what it carries. Returns its parameters:
        ``theta``, or with ``physical="repair"`` the repaired ones."""
        where = f"{self.source}: body {name!r}"
        if len(links) > 1:
            where += f" (links {', '.join(repr(k.name) for k in links)} merged by fixed joints)"
        try:
            check_inertial_parameters(theta, where)
            return theta
        except ModelError as e:
            message = str(e)
        parts = []
        for k in links:
            m, h = k.theta[0], k.theta[1:4]
            com = (h / m).round(6).tolist() if m > 0 else "-"
            k_where = str(k.where)
            place = k_where[len(self.source) + 2:] if k_where.startswith(f"{self.source}: ") else k_where
            issue = k.issue() if len(links) > 1 else ""
            alone = issue[len(k_where) + 2:] if issue else ""
            parts.append(f"{place}: mass {m:.6g}, com {com}" + (f", alone: {alone}" if alone else ""))
        message += "; made of " + "; ".join(parts)
        if self.physical == "repair":
            repaired, before, after = repaired_inertial_parameters(theta)
            warnings.warn(f"{where}: {repair_note(before, after, theta[0])}; it was: {message[len(where) + 2:]}",
                          RobodynWarning, stacklevel=user_stacklevel())
            return repaired
        if self.physical == "warn":
            warnings.warn(f"{message}; kept as given (physical='warn')", RobodynWarning, stacklevel=3)
            return theta
        raise ModelError(f"{message} (load with physical='warn' to keep it anyway, or physical='repair' to "
                         "repair it)")

    def add_joint(self, name: str, type: str, parent: str, child: str, xyz=(0.0, 0.0, 0.0),
                  rpy=(0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0), *, rotation=None, lower=-np.inf,
                  upper=np.inf, velocity=np.inf, effort=np.inf, damping=0.0, friction=0.0,
                  armature=0.0, stiffness=0.0, spring_reference=0.0, pitch: float = 0.0, axis2=None,
                  where: str | None = None) -> None:
        """A joint from ``parent`` to ``child``; its frame is at ``xyz``/``rpy`` (or ``rotation``)
        in the parent link frame and the child frame coincides with it at ``q = 0``.

        ``type`` is ``revolute``, ``continuous``, ``prismatic``, ``helical`` (a screw: rotation
        about ``axis`` with a translation ``pitch`` metres per radian along it), ``fixed``,
        ``planar`` (``q = [x, y, cos t, sin t]``: the child moves in the joint frame's x-y
        plane and turns about its z axis), ``spherical`` (a ball
        joint: ``q = [qx, qy, qz, qw]`` rotates the child in the joint frame) or ``free`` (a
        6-dof joint, whose parent link must be the root or welded to it: its configuration
        ``[x, y, z, qx, qy, qz, qw]`` places the child in the joint frame).

        ``universal`` (a Cardan joint): a rotation ``q1`` about ``axis``, then ``q2`` about
        ``axis2`` in the turned frame, ``R = Rot(axis, q1) Rot(axis2, q2)`` as Pinocchio's
        ``JointModelUniversal``. It is built exactly as two revolute joints ``name[1]`` and
        ``name[2]`` on a massless cross link ``child:name``; the limits, damping, friction,
        armature and springs may be scalars or pairs.

        ``stiffness`` and ``spring_reference``: a joint spring ``tau = stiffness (q -
        spring_reference)`` that the actuator works against (joints of one dof)."""
        where = where or f"{self.source}: joint {name!r}"
        if type == "universal":
            return self._add_universal(name, parent, child, xyz, rpy, axis, axis2, rotation, where,
                                       dict(lower=lower, upper=upper, velocity=velocity, effort=effort,
                                            damping=damping, friction=friction, armature=armature,
                                            stiffness=stiffness, spring_reference=spring_reference))
        if type not in JOINT_TYPES:
            raise ModelError(f"{where}: unknown joint type {type!r}; supported: {sorted([*JOINT_TYPES, 'universal'])}")
        rot = np.asarray(rpy if rotation is None else rotation, dtype=float)
        p = np.asarray(xyz, dtype=float).reshape(3)
        ax = np.asarray(axis, dtype=float).reshape(3)
        for what, a in (("origin", np.concatenate([p, rot.ravel()])), ("axis", ax)):
            if not np.all(np.isfinite(a)):
                raise ModelError(f"{where}: {what} is not finite")
        R = rpy_to_matrix(rot) if rotation is None else rot
        if type in ("free", "spherical", "planar"):
            ax = np.zeros(3)
        elif type != "fixed":
            n = np.linalg.norm(ax)
            if n < 1e-12:
                raise ModelError(f"{where}: joint axis is zero")
            ax = ax / n
        limits = self._limits(type, where, lower, upper, velocity, effort, damping, friction, armature, stiffness,
                              spring_reference)
        if not np.isfinite(pitch) or (pitch != 0 and type != "helical"):
            raise ModelError(f"{where}: pitch {pitch} on a {type} joint (only a helical joint has a finite pitch)")
        self._joints.append(JointEntry(name, type, parent, child, R, p, ax, limits, where, float(pitch)))

    def _add_joint_values(self, name: str, type: str, parent: str, child: str, xyz: tuple, rpy: tuple,
                          axis: tuple, where, **limits) -> None:
        """:meth:`add_joint` from finite floats (a loader's fast path): ``xyz``, ``rpy`` and
        ``axis`` triples, the limits as keywords (floats); ``where`` text or an object
        formatting to it. The same checks and errors, in the same order, and in :meth:`build`
        bit for bit the same placement and axis as :meth:`add_joint`."""
        if type not in JOINT_TYPES:  # universal (which needs axis2) or unknown: add_joint says so
            return self.add_joint(name, type, parent, child, xyz, rpy, axis, where=where, **limits)
        if type in ("free", "spherical", "planar"):
            mode = "zero"
        elif type == "fixed":
            mode = "raw"
        else:
            mode = "unit"
            a0, a1, a2 = axis
            if a0 * a0 + a1 * a1 + a2 * a2 < 1e-20 and np.linalg.norm(np.array(axis)) < 1e-12:
                raise ModelError(f"{where}: joint axis is zero")
        checked = self._limits(type, where, **limits)
        entry = JointEntry(name, type, parent, child, None, None, None, checked, where, 0.0)
        self._joints.append(entry)
        self._pending_joints.append((entry, xyz, rpy, axis, mode))

    @staticmethod
    def _limits(type, where, lower=-np.inf, upper=np.inf, velocity=np.inf, effort=np.inf, damping=0.0,
                friction=0.0, armature=0.0, stiffness=0.0, spring_reference=0.0) -> dict:
        """The checked limits, friction, armature and spring of a joint (:meth:`add_joint`)."""
        if type in ("continuous", "free", "spherical", "planar"):
            lower, upper = -np.inf, np.inf
        limits = dict(lower=float(lower), upper=float(upper), velocity=float(velocity),
                      effort=float(effort), damping=float(damping), friction=float(friction),
                      armature=float(armature), stiffness=float(stiffness), spring_reference=float(spring_reference))
        lo, hi, vel, eff, damp, fric, arm, stiff, ref = limits.values()
        inf = math.inf
        ordinary = (lo == lo and hi == hi and vel >= 0 and eff >= 0 and 0 <= damp < inf and 0 <= fric < inf
                    and 0 <= arm < inf and 0 <= stiff < inf and -inf < ref < inf)  # the checks below pass
        finite = ("damping", "friction", "armature", "stiffness")
        for k, val in () if ordinary else limits.items():
            if math.isnan(val):
                raise ModelError(f"{where}: {k} is NaN")
            if k == "spring_reference" and not math.isfinite(val):
                raise ModelError(f"{where}: spring_reference must be finite, got {val}")
            if k not in ("lower", "upper", "spring_reference") and (val < 0
                                                                   or (k in finite and not math.isfinite(val))):
                raise ModelError(f"{where}: {k} must be finite and >= 0, got {val}")
        if (stiffness or spring_reference) and type in ("free", "spherical", "planar", "fixed"):
            raise ModelError(f"{where}: joint springs on a {type} joint; only joints of one dof have them")
        if limits["lower"] > limits["upper"]:
            raise ModelError(f"{where}: lower limit {lower} exceeds upper limit {upper}")
        return limits

    def _add_universal(self, name, parent, child, xyz, rpy, axis, axis2, rotation, where, options) -> None:
        if axis2 is None:
            raise ModelError(f"{where}: a universal joint needs axis2")
        a1, a2 = (np.asarray(a, dtype=float).reshape(3) for a in (axis, axis2))
        n1, n2 = np.linalg.norm(a1), np.linalg.norm(a2)
        if not (np.all(np.isfinite(a1)) and np.all(np.isfinite(a2)) and n1 > 0 and n2 > 0):
            raise ModelError(f"{where}: universal joint axes must be finite and non-zero, got {a1.tolist()}, {a2.tolist()}")
        if np.linalg.norm(np.cross(a1 / n1, a2 / n2)) < 1e-9:
            raise ModelError(f"{where}: universal joint axes {a1.tolist()} and {a2.tolist()} are parallel")
        try:
            split = [{k: float(np.broadcast_to(np.asarray(v, dtype=float), (2,))[j]) for k, v in options.items()}
                     for j in (0, 1)]
        except ValueError:
            raise ModelError(f"{where}: universal joint limits and friction must be scalars or pairs") from None
        cross = f"{child}:{name}"
        self.add_link(cross, where=where)
        self.add_joint(f"{name}[1]", "revolute", parent, cross, xyz, rpy, a1, rotation=rotation, where=where, **split[0])
        self.add_joint(f"{name}[2]", "revolute", cross, child, axis=a2, where=where, **split[1])

    # ---------------------------------------------------------------------------------
    def _check_graph(self) -> tuple[str, dict[str, list[JointEntry]]]:
        """Return the root link and the child joints of each link, or raise ModelError. A
        parent link ``"world"`` that was not added is the implicit, massless root."""
        if WORLD not in self._links and any(jt.parent == WORLD for jt in self._joints):
            self._links[WORLD] = LinkEntry(WORLD, np.zeros(10), f"{self.source}: link 'world' (implicit: the root)")
        if not self._links:
            raise ModelError(f"{self.source}: no links")
        seen_joint: dict[str, JointEntry] = {}
        parent_joint: dict[str, JointEntry] = {}
        children: dict[str, list[JointEntry]] = {name: [] for name in self._links}
        for jt in self._joints:
            if jt.name in seen_joint:
                raise ModelError(f"{jt.where}: duplicate joint name {jt.name!r} (first at {seen_joint[jt.name].where})")
            seen_joint[jt.name] = jt
            for role, link in (("parent", jt.parent), ("child", jt.child)):
                if link not in self._links:
                    raise ModelError(f"{jt.where}: {role} link {link!r} does not exist")
            if jt.parent == jt.child:
                raise ModelError(f"{jt.where}: joint connects link {jt.child!r} to itself")
            if jt.child in parent_joint:
                raise ModelError(
                    f"{jt.where}: link {jt.child!r} has two parents (joints "
                    f"{parent_joint[jt.child].name!r} and {jt.name!r})"
                )
            parent_joint[jt.child] = jt
            children[jt.parent].append(jt)
        roots = [name for name in self._links if name not in parent_joint]
        if len(roots) > 1:
            shown = "; ".join(str(self._links[r].where) for r in roots[:5]) + ("; ..." if len(roots) > 5 else "")
            raise ModelError(f"{self.source}: several root links {roots[:5]} ({shown}); a robot is one tree")
        # every link has at most one parent, so links unreachable from the root lie on cycles
        reached, stack = set(roots), list(roots)
        while stack:
            for jt in children[stack.pop()]:
                reached.add(jt.child)
                stack.append(jt.child)
        if len(reached) != len(self._links):
            raise ModelError(self._cycle_message(next(n for n in self._links if n not in reached), parent_joint))
        return roots[0], children

    def _cycle_message(self, link: str, parent_joint: dict[str, JointEntry]) -> str:
        """Name the joints of the cycle upstream of ``link`` (which is not reachable from a root)."""
        path, seen = [], {}
        while link not in seen:  # walk parents; every link on the way has exactly one
            seen[link] = len(path)
            path.append(parent_joint[link])
            link = path[-1].parent
        cycle = path[seen[link]:][::-1]
        shown = "; ".join(str(jt.where) for jt in cycle[:5]) + ("; ..." if len(cycle) > 5 else "")
        links = [jt.child for jt in cycle]
        return f"{self.source}: the joints form a cycle through links {links[:5]}{' ...' if len(links) > 5 else ''} ({shown})"

    def _materialize(self) -> None:
        """The inertial parameters of the links, and the rotation, position and axis of the
        joints, added from plain numbers since the last build, all at once: the operations of
        :meth:`add_link` and :meth:`add_joint`, stacked (NumPy's products of one pair and of a
        stack give the same bits)."""
        links, joints = self._pending_links, self._pending_joints
        self._pending_links, self._pending_joints = [], []
        turned = [k for k, item in enumerate(links) if item[4] is not None]
        # the rotations of the inertias and of the joints, all at once
        R = _rpy_matrices([links[k][4] for k in turned] + [item[2] for item in joints])
        if links:
            entries, mass, com, inertia, _ = zip(*links)
            n = len(entries)
            Ic = np.zeros((n, 3, 3))
            full = [k for k in range(n) if inertia[k] is not None]
            if full:
                Ic[full] = np.array([inertia[k] for k in full])[:, [0, 1, 2, 1, 3, 4, 2, 4, 5]].reshape(-1, 3, 3)
            if turned:
                Rr = R[:len(turned)]
                Ic[turned] = Rr @ Ic[turned] @ Rr.transpose(0, 2, 1)
            theta = _parameters_from(np.array(mass, dtype=float), np.array(com, dtype=float).reshape(n, 3), Ic)
            for entry, row in zip(entries, theta):
                entry.theta = row
        if joints:
            entries, xyz, _, axis, mode = zip(*joints)
            n = len(entries)
            p = np.array(xyz, dtype=float).reshape(n, 3)
            ax = np.array(axis, dtype=float).reshape(n, 3)
            unit = [k for k in range(n) if mode[k] == "unit"]
            if unit:
                ax[unit] = ax[unit] / np.sqrt(_dot(ax[unit], ax[unit]))[:, None]
            ax[[k for k in range(n) if mode[k] == "zero"]] = 0.0
            for entry, Rk, pk, ak in zip(entries, R[len(turned):], p, ax):
                entry.R, entry.p, entry.axis = Rk, pk, ak

    def build(self, floating_base: bool = False) -> Model:
        """The :class:`Model`; a floating base adds a free joint ``root_joint`` at the root."""
        root, children = self._check_graph()
        self._materialize()

        # Pass 1: bodies and frames in depth-first order (children in the order added). Every
        # link lies in a body; a link that a fixed joint carries is placed in its body's frame
        # by that joint (``carrier``), the others are their body's origin.
        body_of: dict[str, int] = {root: 0 if floating_base else -1}
        carrier: dict[str, int] = {root: -1}  # link -> the position in ``visited`` of its fixed joint
        body_joint: list[int] = [-1] if floating_base else []  # each body's joint (position in ``visited``)
        names = [root] if floating_base else []
        frames: list[tuple[str, int, int]] = [] if floating_base else [(root, -1, -1)]
        visited: list[JointEntry] = []
        order = [root]
        stack = list(reversed(children[root]))
        while stack:
            jt = stack.pop()
            k = len(visited)
            visited.append(jt)
            b = body_of[jt.parent]
            if jt.type == "fixed":
                body_of[jt.child], carrier[jt.child] = b, k
                frames.append((jt.child, b, k))
            elif jt.type == "free" and b >= 0:
                raise ModelError(
                    f"{jt.where}: a free joint must attach to the world, but its parent link "
                    f"{jt.parent!r} moves with body {names[b]!r}"
                )
            else:
                body_of[jt.child], carrier[jt.child] = len(names), -1
                body_joint.append(k)
                names.append(jt.child)
            order.append(jt.child)
            stack.extend(reversed(children[jt.child]))

        # Pass 2: each joint's frame in its parent link's body, R @ R_joint and p + R @ p_joint
        # with (R, p) the placement of the parent link, computed level by level of fixed joints
        nj = len(visited)
        Rj, pj = np.empty((nj, 3, 3)), np.empty((nj, 3))
        if nj:
            R_in = np.array([jt.R for jt in visited], dtype=float).reshape(nj, 3, 3)
            p_in = np.array([jt.p for jt in visited], dtype=float).reshape(nj, 3)
            src = [carrier[jt.parent] for jt in visited]
            level = [0] * nj
            for k, s in enumerate(src):
                if s >= 0:
                    level[k] = level[s] + 1
            by_level: list[list[int]] = [[] for _ in range(max(level) + 1)]
            for k, lv in enumerate(level):
                by_level[lv].append(k)
            for ks in by_level:
                s = [src[k] for k in ks]
                if s[0] < 0:  # the parent link is its body's origin (level 0)
                    R, p = np.eye(3), np.zeros((len(ks), 3))
                else:
                    R, p = Rj[s], pj[s]
                Rj[ks] = R @ R_in[ks]
                pj[ks] = p + _matvec(np.broadcast_to(R, (len(ks), 3, 3)), p_in[ks])

        # Pass 3: the inertial parameters of each body, its links moved into its frame and
        # summed in depth-first order
        nb = len(names)
        on_body = [link for link in order if body_of[link] >= 0]  # links carried by the fixed world are left out
        members: list[list[LinkEntry]] = [[] for _ in range(nb)]
        for link in on_body:
            members[body_of[link]].append(self._links[link])
        theta = np.zeros((nb, 10))
        if on_body:
            m = len(on_body)
            R, p = np.empty((m, 3, 3)), np.zeros((m, 3))
            R[:] = np.eye(3)
            moved = [i for i, link in enumerate(on_body) if carrier[link] >= 0]
            if moved:
                R[moved] = Rj[[carrier[on_body[i]] for i in moved]]
                p[moved] = pj[[carrier[on_body[i]] for i in moved]]
            t = np.array([self._links[link].theta for link in on_body], dtype=float).reshape(m, 10)
            terms = _parameters_in_parent(R, p, t)
            # theta[b] += term, link after link (np.add.at adds in index order, unbuffered)
            np.add.at(theta, [body_of[link] for link in on_body], terms)
        suspect = ~consistent_inertial_parameters(theta) if nb else []
        for i in np.flatnonzero(suspect):
            theta[i] = self._check_body(theta[i], names[i], members[i])

        # The model's arrays: bodies (X_tree, axis, limits per dof) and frames
        jtype, parent, axis, pitch, jnames, dofs = [], [], [], [], [], []
        for k in body_joint:
            if k < 0:  # the floating base
                code, par, ax, h, jname, lim = J.FREE, -1, np.zeros(3), 0.0, "root_joint", _FREE_LIMITS
            else:
                jt = visited[k]
                code, par, ax, h = JOINT_TYPES[jt.type], body_of[jt.parent], jt.axis, jt.pitch
                jname, lim = jt.name, jt.limits
            jtype.append(code)
            parent.append(par)
            axis.append(ax)
            pitch.append(h)
            jnames.append(jname)
            dofs.extend([lim] * int(J.NV[code]))
        moving = [k for k in body_joint if k >= 0]
        X_R = np.empty((nb, 3, 3))
        X_p = np.empty((nb, 3))
        if floating_base:
            X_R[0], X_p[0] = np.eye(3), np.zeros(3)
        X_R[nb - len(moving):], X_p[nb - len(moving):] = Rj[moving], pj[moving]
        nf = len(frames)
        frame_R, frame_p = np.empty((nf, 3, 3)), np.zeros((nf, 3))
        frame_R[:] = np.eye(3)
        placed = [f for f in range(nf) if frames[f][2] >= 0]  # all but the root's frame
        by = [frames[f][2] for f in placed]
        frame_R[placed], frame_p[placed] = Rj[by], pj[by]
        columns = np.array(list(map(_limit_values, dofs)), dtype=float).reshape(len(dofs), 9)
        col = dict(zip(_LIMIT_KEYS, columns.T))
        return Model(
            parent=parent, joint_type=jtype, joint_axis=np.reshape(axis, (nb, 3)), joint_pitch=pitch,
            X_tree_R=X_R, X_tree_p=X_p, theta=theta, link_names=names, body_joint_names=jnames,
            physical="error" if self.physical == "repair" else self.physical,  # repaired above
            gravity=self.gravity, lower=col["lower"], upper=col["upper"],
            velocity_limit=col["velocity"], effort_limit=col["effort"], damping=col["damping"],
            coulomb=col["friction"], armature=col["armature"], stiffness=col["stiffness"],
            spring_reference=col["spring_reference"], frame_names=[f[0] for f in frames],
            frame_body=[f[1] for f in frames], frame_R=frame_R, frame_p=frame_p, name=self.name,
        )
