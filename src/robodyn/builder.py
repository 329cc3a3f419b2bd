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

import warnings
from dataclasses import dataclass, field

import numpy as np

from . import joints as J
from .errors import RobodynWarning
from .model import (Model, ModelError, check_inertial_parameters, consistent_inertial_parameters,
                    inertial_parameters_from, inertial_parameters_in_parent)

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


@dataclass
class LinkEntry:
    """A link as added: its 10 inertial parameters and where it was defined."""

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
    """A joint as added: type, parent and child links, placement, axis, limits."""

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


class ModelBuilder:
    """Collects links and joints, then :meth:`build` returns the immutable :class:`Model`."""

    def __init__(self, name: str = "robot", gravity=(0.0, 0.0, -9.81), source: str = "<model>",
                 physical: str = "error"):
        """``physical="error"`` rejects unphysical link inertias with a :class:`ModelError`;
        ``physical="warn"`` keeps them as given and warns (for descriptions known to carry
        such values, e.g. some published URDFs)."""
        if physical not in ("error", "warn"):
            raise ValueError(f"physical must be 'error' or 'warn', got {physical!r}")
        self.physical = physical
        self.name = name
        self.gravity = np.asarray(gravity, dtype=float)
        self.source = source
        self._links: dict[str, LinkEntry] = {}
        self._joints: list[JointEntry] = []

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

    def _check_body(self, theta, name: str, links: list[LinkEntry]) -> None:
        """Check the merged body ``name`` (``theta``), made of ``links``; raise (or warn, with
        ``physical="warn"``) naming each link and what it carries."""
        where = f"{self.source}: body {name!r}"
        if len(links) > 1:
            where += f" (links {', '.join(repr(k.name) for k in links)} merged by fixed joints)"
        try:
            check_inertial_parameters(theta, where)
            return
        except ModelError as e:
            message = str(e)
        parts = []
        for k in links:
            m, h = k.theta[0], k.theta[1:4]
            com = (h / m).round(6).tolist() if m > 0 else "-"
            place = k.where[len(self.source) + 2:] if k.where.startswith(f"{self.source}: ") else k.where
            issue = k.issue() if len(links) > 1 else ""
            alone = issue[len(k.where) + 2:] if issue else ""
            parts.append(f"{place}: mass {m:.6g}, com {com}" + (f", alone: {alone}" if alone else ""))
        message += "; made of " + "; ".join(parts)
        if self.physical == "warn":
            warnings.warn(f"{message}; kept as given (physical='warn')", RobodynWarning, stacklevel=3)
        else:
            raise ModelError(f"{message} (load with physical='warn' to keep it anyway)")

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
        if type in ("continuous", "free", "spherical", "planar"):
            lower, upper = -np.inf, np.inf
        limits = dict(lower=float(lower), upper=float(upper), velocity=float(velocity),
                      effort=float(effort), damping=float(damping), friction=float(friction),
                      armature=float(armature), stiffness=float(stiffness), spring_reference=float(spring_reference))
        finite = ("damping", "friction", "armature", "stiffness")
        for k, val in limits.items():
            if np.isnan(val):
                raise ModelError(f"{where}: {k} is NaN")
            if k == "spring_reference" and not np.isfinite(val):
                raise ModelError(f"{where}: spring_reference must be finite, got {val}")
            if k not in ("lower", "upper", "spring_reference") and (val < 0 or (k in finite and not np.isfinite(val))):
                raise ModelError(f"{where}: {k} must be finite and >= 0, got {val}")
        if (stiffness or spring_reference) and type in ("free", "spherical", "planar", "fixed"):
            raise ModelError(f"{where}: joint springs on a {type} joint; only joints of one dof have them")
        if limits["lower"] > limits["upper"]:
            raise ModelError(f"{where}: lower limit {lower} exceeds upper limit {upper}")
        if not np.isfinite(pitch) or (pitch != 0 and type != "helical"):
            raise ModelError(f"{where}: pitch {pitch} on a {type} joint (only a helical joint has a finite pitch)")
        self._joints.append(JointEntry(name, type, parent, child, R, p, ax, limits, where, float(pitch)))

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
            shown = "; ".join(self._links[r].where for r in roots[:5]) + ("; ..." if len(roots) > 5 else "")
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
        shown = "; ".join(jt.where for jt in cycle[:5]) + ("; ..." if len(cycle) > 5 else "")
        links = [jt.child for jt in cycle]
        return f"{self.source}: the joints form a cycle through links {links[:5]}{' ...' if len(links) > 5 else ''} ({shown})"

    def build(self, floating_base: bool = False) -> Model:
        """The :class:`Model`; a floating base adds a free joint ``root_joint`` at the root."""
        root, children = self._check_graph()
        pitch: list[float] = []
        parent, jtype, axis, XR, Xp, theta = [], [], [], [], [], []
        names, jnames, dofs = [], [], []
        frames: list[tuple[str, int, np.ndarray, np.ndarray]] = []

        def new_body(par, code, ax, R, p, name, jname, lim, h=0.0):
            pitch.append(h)
            parent.append(par)
            jtype.append(code)
            axis.append(ax)
            XR.append(R)
            Xp.append(p)
            theta.append(np.zeros(10))
            names.append(name)
            jnames.append(jname)
            dofs.extend([lim] * int(J.NV[code]))
            return len(parent) - 1

        free = dict(lower=-np.inf, upper=np.inf, velocity=np.inf, effort=np.inf, damping=0.0, friction=0.0, armature=0.0,
                    stiffness=0.0, spring_reference=0.0)
        if floating_base:
            b = new_body(-1, J.FREE, np.zeros(3), np.eye(3), np.zeros(3), root, "root_joint", free)
            place = {root: (b, np.eye(3), np.zeros(3))}
        else:
            place = {root: (-1, np.eye(3), np.zeros(3))}
            frames.append((root, -1, np.eye(3), np.zeros(3)))
        order = [root]
        stack = list(reversed(children[root]))
        while stack:
            jt = stack.pop()
            b, R, p = place[jt.parent]
            Rj, pj = R @ jt.R, p + R @ jt.p
            if jt.type == "fixed":
                place[jt.child] = (b, Rj, pj)
                frames.append((jt.child, b, Rj, pj))
            elif jt.type == "free" and b >= 0:
                raise ModelError(
                    f"{jt.where}: a free joint must attach to the world, but its parent link "
                    f"{jt.parent!r} moves with body {names[b]!r}"
                )
            else:
                nb = new_body(b, JOINT_TYPES[jt.type], jt.axis, Rj, pj, jt.child, jt.name, jt.limits, jt.pitch)
                place[jt.child] = (nb, np.eye(3), np.zeros(3))
            order.append(jt.child)
            stack.extend(reversed(children[jt.child]))
        members: list[list[LinkEntry]] = [[] for _ in theta]
        for link in order:
            b, R, p = place[link]
            if b < 0:
                continue  # carried by the fixed world
            theta[b] += inertial_parameters_in_parent(R, p, self._links[link].theta)
            members[b].append(self._links[link])
        suspect = ~consistent_inertial_parameters(np.reshape(theta, (-1, 10))) if theta else []
        for i in np.flatnonzero(suspect):
            self._check_body(theta[i], names[i], members[i])

        def col(key):
            return np.array([d[key] for d in dofs], dtype=float)

        nb = len(parent)
        return Model(
            parent=parent, joint_type=jtype, joint_axis=np.reshape(axis, (nb, 3)), joint_pitch=pitch,
            X_tree_R=np.reshape(XR, (nb, 3, 3)), X_tree_p=np.reshape(Xp, (nb, 3)),
            theta=np.reshape(theta, (nb, 10)), link_names=names, body_joint_names=jnames, physical=self.physical,
            gravity=self.gravity, lower=col("lower"), upper=col("upper"),
            velocity_limit=col("velocity"), effort_limit=col("effort"), damping=col("damping"),
            coulomb=col("friction"), armature=col("armature"), stiffness=col("stiffness"),
            spring_reference=col("spring_reference"), frame_names=[f[0] for f in frames], frame_body=[f[1] for f in frames],
            frame_R=np.reshape([f[2] for f in frames], (len(frames), 3, 3)),
            frame_p=np.reshape([f[3] for f in frames], (len(frames), 3)), name=self.name,
        )
