"""The camera shared by the browser viewer and the renders."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np


@dataclass(frozen=True)
class Camera:
    """Where a view looks from, in world coordinates (z up).

    ``azimuth`` (degrees): the direction of the eye seen from the target, about the world z
    axis from the x axis (0: looking along -x, from the front of a robot facing +x; 90: from
    its left); ``elevation`` (degrees): the eye's angle above the x-y plane; ``distance`` (m)
    from the target to the eye, None: fitted so that the robot's bounding sphere fills the
    view; ``target`` (3,) the point looked at, None: the centre of the robot's bounding box
    (over the whole trajectory); ``fov`` (degrees) the vertical field of view. The eye is at
    ``target + distance (cos e cos a, cos e sin a, sin e)``.

    Give a :class:`Camera` or a dict of some of these fields (``{"azimuth": 90}``).
    """

    azimuth: float = 35.0
    elevation: float = 20.0
    distance: float | None = None
    target: tuple | None = None
    fov: float = 45.0

    @classmethod
    def of(cls, camera) -> "Camera":
        """``camera`` as a :class:`Camera`: None (the default), a Camera, or a dict of fields."""
        if camera is None:
            return cls()
        if isinstance(camera, Camera):
            return camera
        if isinstance(camera, dict):
            unknown = set(camera) - {f.name for f in fields(cls)}
            if unknown:
                raise ValueError(f"camera: unknown fields {sorted(unknown)}; known: {[f.name for f in fields(cls)]}")
            return cls(**camera)
        raise TypeError(f"camera: expected a robodyn.viewer.Camera or a dict, got {type(camera).__name__}")

    def fitted(self, lo, hi) -> "Camera":
        """This camera with ``target`` and ``distance`` filled in for the world bounds ``lo``,
        ``hi`` (3,): the box's centre, and the distance at which its bounding sphere fits the
        field of view (with a 5 % margin)."""
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        for name in ("azimuth", "elevation", "fov"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"camera.{name}: expected a finite number, got {getattr(self, name)}")
        if not 0 < self.fov < 180:
            raise ValueError(f"camera.fov: expected degrees in (0, 180), got {self.fov}")
        target = (lo + hi) / 2 if self.target is None else np.asarray(self.target, dtype=float)
        if target.shape != (3,) or not np.all(np.isfinite(target)):
            raise ValueError(f"camera.target: expected 3 finite numbers, got {self.target!r}")
        radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
        distance = 1.05 * radius / math.sin(math.radians(self.fov) / 2) if self.distance is None else self.distance
        if not (math.isfinite(distance) and distance > 0):
            raise ValueError(f"camera.distance: expected a positive distance (m), got {self.distance}")
        return replace(self, target=tuple(float(x) for x in target), distance=float(distance))

    def eye(self) -> np.ndarray:
        """The eye's world position (3,) (a fitted camera: ``target`` and ``distance`` set)."""
        a, e = math.radians(self.azimuth), math.radians(self.elevation)
        direction = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
        return np.asarray(self.target, dtype=float) + self.distance * direction
