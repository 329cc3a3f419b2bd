"""A scene ready to draw, shared by the browser viewer and the renders: the robot's parts
(triangles on bodies) and a playback (the world pose of every body at every sample, computed
once by one batched :func:`robodyn.forward_kinematics` call, with the contact points and
forces of a simulation that has them).
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..coupling import independent_q, joint_tree
from ..errors import RobodynWarning
from ..joints import PLANAR, QUAT_OFFSET
from .geometry import Mesh, VisualShape, decimate, shape_mesh, skeleton, visuals as urdf_visuals


class Part(NamedTuple):
    """One drawable piece: ``name``, ``link``, ``body`` and ``pose`` (4, 4) (geometry frame in
    the body frame) as in :class:`~robodyn.viewer.geometry.VisualShape`; ``mesh`` its
    triangles in the geometry frame."""
    name: str
    link: str
    body: int
    pose: np.ndarray
    mesh: Mesh


def shapes_of(model, visuals=None) -> list[VisualShape]:
    """The shapes to draw: ``visuals`` as :class:`VisualShape` records, or the URDF (path or
    XML text) to read them from (:func:`robodyn.viewer.visuals`); the capsule skeleton
    (:func:`robodyn.viewer.skeleton`) when None or when the URDF has no visual geometry."""
    if visuals is None:
        return skeleton(model)
    if isinstance(visuals, (str, bytes, os.PathLike)):
        visuals = urdf_visuals(visuals, model)
    shapes = list(visuals)
    for k, s in enumerate(shapes):
        if not isinstance(s, VisualShape):
            raise TypeError(f"visuals[{k}]: expected a VisualShape (robodyn.viewer.visuals), got {type(s).__name__}")
        if not -1 <= s.body < model.nbodies:
            raise ValueError(f"visuals[{k}] ({s.name}): body {s.body} is not a body of the model "
                             f"({model.nbodies} bodies)")
    return shapes or skeleton(model)


def parts(model, visuals=None, *, max_faces: int | None = None) -> list[Part]:
    """The parts of :func:`shapes_of` with their triangles (each mesh file read once); with
    ``max_faces``, meshes are decimated (:func:`~robodyn.viewer.geometry.decimate`) so that
    the whole robot has about that many triangles, each part its share by size."""
    cache: dict = {}
    out = []
    for s in shapes_of(model, visuals):
        mesh = shape_mesh(s, cache)
        if mesh is not None and len(mesh.faces):
            out.append(Part(s.name, s.link, s.body, s.pose, mesh))
    total = sum(len(p.mesh.faces) for p in out)
    if max_faces is not None and total > max_faces:
        out = [p._replace(mesh=decimate(p.mesh, max(12, int(max_faces * len(p.mesh.faces) / total))))
               for p in out]
    return out


def neutral_configuration(model) -> np.ndarray:
    """``q`` (nq,) with every joint at zero: identity quaternions, planar angle 0 (a model with
    mimic joints: its independent coordinates)."""
    tree = joint_tree(model)
    q = np.zeros(tree.nq)
    for i in range(tree.nbodies):
        k, jt = tree.idx_q[i], tree.joint_type[i]
        if QUAT_OFFSET[jt] >= 0:
            q[k + QUAT_OFFSET[jt] + 3] = 1.0  # qw, scalar last
        elif jt == PLANAR:
            q[k + 2] = 1.0  # cos t
    return independent_q(model, q)


@dataclass(frozen=True)
class Playback:
    """Samples to show: ``t`` (N,) (s); ``q`` (N, nq); ``body_poses`` (N, nb, 4, 4) the world
    pose of every body; ``com`` (N, 3) the robot's centre of mass (world); with contacts,
    ``contact_names`` (P,), ``contact_points`` (N, P, 3) (world, m: where each pair's force
    acts, see :func:`playback`) and ``contact_forces`` (N, P, 3) (N, world axes), else None."""
    t: np.ndarray
    q: np.ndarray
    body_poses: np.ndarray
    com: np.ndarray
    contact_names: tuple | None = None
    contact_points: np.ndarray | None = None
    contact_forces: np.ndarray | None = None

    def index(self, time: float) -> int:
        """The last sample at or before ``time`` (the first for earlier times)."""
        return int(np.clip(np.searchsorted(self.t, time + 1e-9 * max(1.0, abs(time)), side="right") - 1,
                           0, len(self.t) - 1))

    def force_segments(self, k: int, scale: float, cap: float) -> np.ndarray:
        """Segments (M, 2, 3) drawing the M non-zero contact forces of sample ``k``: from the
        contact point along the force, ``scale`` metres per newton, at most ``cap`` metres."""
        if self.contact_forces is None:
            return np.zeros((0, 2, 3))
        p, f = self.contact_points[k], self.contact_forces[k]
        norm = np.linalg.norm(f, axis=1)
        on = norm > 0
        length = np.minimum(scale * norm[on], cap)
        return np.stack([p[on], p[on] + f[on] * (length / norm[on])[:, None]], axis=1)

    def force_scale(self, model, size: float) -> float:
        """Metres per newton for drawing contact forces on a robot of ``size`` (m): the
        robot's weight is half its size (the largest force is, for a massless model)."""
        weight = model.total_mass * float(np.linalg.norm(model.gravity))
        if weight <= 0 and self.contact_forces is not None:
            weight = 2 * float(np.linalg.norm(self.contact_forces, axis=-1).max())
        return 0.5 * size / weight if weight > 0 else 0.0

    def part_poses(self, parts: list[Part], k: int) -> np.ndarray:
        """World poses (len(parts), 4, 4) of the parts' geometry frames at sample ``k``."""
        T = np.concatenate([self.body_poses[k], np.eye(4)[None]])  # body -1: the world
        return T[[p.body for p in parts]] @ np.stack([p.pose for p in parts])


def load_trajectory(model, trajectory):
    """A :class:`robodyn.Trajectory`, or a path of robodyn's log format (CSV or Parquet,
    :mod:`robodyn.io.log`): read as a trajectory (:meth:`Trajectory.from_csv`, with its
    contact columns) when it has ``v``, ``a`` and ``tau``, else as a log of ``t`` and ``q``.
    Returns an object with ``t`` and ``q`` (and ``contact_*`` for a trajectory)."""
    if not isinstance(trajectory, (str, os.PathLike)):
        if not (hasattr(trajectory, "t") and hasattr(trajectory, "q")):
            raise TypeError(f"trajectory: expected a robodyn.Trajectory or a path, got {type(trajectory).__name__}")
        return trajectory
    from ..io.log import read_log
    from ..simulation.trajectory import Trajectory

    log = read_log(trajectory, model)
    if all(getattr(log, k) is not None for k in ("v", "a", "tau")):
        return Trajectory.from_csv(trajectory, model)
    return log


def playback(model, q=None, trajectory=None, contacts=None) -> Playback:
    """The :class:`Playback` of one configuration ``q`` (nq,) (default: the neutral one) or of
    a ``trajectory`` (see :func:`load_trajectory`), whose body poses and centres of mass are
    computed once for all samples.

    Contact points, for a trajectory with contacts: with ``contacts`` (the
    :class:`robodyn.contact.Contacts` it was simulated with), each pair's sphere's point
    nearest its surface (centre minus radius times the surface normal); without, the origin of
    the link or frame that the pair's name starts with (``"FL_FOOT:sphere@ground"`` ->
    ``FL_FOOT``), exact for point contacts at a frame; pairs whose name names no link of the
    model are left out with a :class:`RobodynWarning`.
    """
    from ..algorithms.com import center_of_mass
    from ..algorithms.kinematics import forward_kinematics

    if trajectory is not None:
        traj = load_trajectory(model, trajectory)
        t, Q = np.asarray(traj.t, dtype=float), np.asarray(traj.q, dtype=float)
    else:
        Q = neutral_configuration(model)[None] if q is None else np.asarray(q, dtype=float)[None]
        t, traj = np.zeros(1), None
    T = forward_kinematics(model, Q)
    com = center_of_mass(model, Q) if model.total_mass > 0 else np.zeros((len(Q), 3))
    names = getattr(traj, "contact_names", None)
    if not names or getattr(traj, "contact_force", None) is None:
        return Playback(t, Q, T, com)
    force, normal = np.asarray(traj.contact_force), np.asarray(traj.contact_normal)
    if contacts is not None:
        points, keep = _packed_points(model, contacts, names, T, normal)
    else:
        points, keep = _named_points(model, names, T)
    return Playback(t, Q, T, com, tuple(names[p] for p in keep), points, force[:, keep])


def _packed_points(model, contacts, names, T, normal):
    (bodies, centers, radii), _, _, packed = contacts.pack(model)
    if tuple(packed) != tuple(names):
        raise ValueError(f"contacts: its pairs {list(packed)[:4]}... are not the trajectory's {list(names)[:4]}...")
    ns = len(contacts.surfaces)
    point = np.arange(len(names)) // ns
    Tb = T[:, bodies[point]]
    center = np.einsum("npij,pj->npi", Tb[..., :3, :3], centers[point]) + Tb[..., :3, 3]
    return center - radii[point][None, :, None] * normal, list(range(len(names)))


def _named_points(model, names, T):
    cols, keep, unknown = [], [], []
    for p, name in enumerate(names):
        link = name.rsplit("@", 1)[0].split(":", 1)[0]
        try:
            b, R, x = model.frame_index(link)
        except ValueError:
            unknown.append(name)
            continue
        cols.append(np.broadcast_to(x, (T.shape[0], 3)) if b < 0 else T[:, b, :3, :3] @ x + T[:, b, :3, 3])
        keep.append(p)
    if unknown:
        warnings.warn(f"contact pairs whose name names no link of the model are not drawn: {unknown}; "
                      "pass contacts= (the simulation's Contacts) to place them", RobodynWarning, stacklevel=3)
    points = np.stack(cols, axis=1) if cols else np.zeros((T.shape[0], 0, 3))
    return points, keep


def nice_step(x: float) -> float:
    """The smallest number of the form 1, 2 or 5 times a power of ten that is >= ``x`` > 0
    (grid cells)."""
    power = 10.0 ** math.floor(math.log10(x))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= x * (1 - 1e-12))


def bounds(parts: list[Part], play: Playback, samples: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """World axis-aligned bounds ``(lo, hi)`` (3,) of the parts (their bounding boxes'
    corners) and of the body origins, over at most ``samples`` evenly spread samples."""
    ks = np.unique(np.linspace(0, len(play.t) - 1, min(samples, len(play.t))).round().astype(int))
    pts = [play.body_poses[ks, :, :3, 3].reshape(-1, 3)]
    if parts:
        lo = np.stack([p.mesh.vertices.min(0) for p in parts])
        hi = np.stack([p.mesh.vertices.max(0) for p in parts])
        pick = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]])
        corners = np.where(pick[None] == 1, hi[:, None], lo[:, None])  # (P, 8, 3)
        poses = np.stack([play.part_poses(parts, k) for k in ks])  # (K, P, 4, 4)
        pts.append((np.einsum("kpij,pcj->kpci", poses[..., :3, :3], corners)
                    + poses[:, :, None, :3, 3]).reshape(-1, 3))
    pts = np.concatenate(pts)
    return pts.min(0), pts.max(0)
