"""Contact geometry: shapes fixed on the robot's bodies and the static surfaces of the world.

Shapes on a body (``body``: a link or frame name, or a body index; positions in the
coordinates of that link or frame, metres):

- :class:`Sphere` ``(body, radius, center)``; :class:`Point` is a sphere of radius 0 (a
  foot's sole point, a tool tip);
- :class:`Box` ``(body, size, center, rpy)``: its eight corners;
- :class:`Capsule` ``(body, radius, length, center, rpy)``: a segment along the local ``z``
  axis with a sphere at each end.

Against a plane, each shape touches the world only at those points and spheres, so the
reduction is exact, not an approximation: a box's nearest points to a plane include a corner
and a capsule's an end.

World surfaces: :class:`Plane` ``(normal, height, friction, restitution)``, the half-space
``normal . x <= height`` being solid (the ground is ``Plane()``; an incline, a wall are
planes with other normals), and :class:`StaticBox` ``(size, center, rpy, friction,
restitution)``, an obstacle (a table, a step) that spheres touch at the nearest point of its
surface, and :class:`BodySphere` ``(body, radius, center, friction, restitution)``, a sphere
moving with a body of the model (contact between bodies). Friction (Coulomb coefficient ``mu``, isotropic) and
restitution (Newton's coefficient ``e``) belong to the surface.

:class:`Contacts` gathers the shapes, the surfaces and the solver's settings; it is what
:func:`robodyn.simulate` takes as ``contacts=``. Every pair (point or sphere, surface) is
one potential contact, named ``"<shape>@<surface>"``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..builder import rpy_to_matrix


def _finite(name: str, x, shape) -> np.ndarray:
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers, got {x!r}") from None
    if a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or Inf: {a.tolist()}")
    a.flags.writeable = False
    return a


def _positive(name: str, x, zero: bool = False) -> float:
    x = float(_finite(name, x, ()))
    if x < 0 or (x == 0 and not zero):
        raise ValueError(f"{name}: must be {'>= 0' if zero else '> 0'}, got {x}")
    return x


def _edges(name: str, size) -> np.ndarray:
    """A box's three edge lengths, each > 0."""
    size = _finite(name, size, (3,))
    if np.any(size <= 0):
        raise ValueError(f"{name}: every edge must be > 0, got {size.tolist()}")
    return size


def _set_coefficients(surface) -> None:
    """Check and set a surface's ``friction`` (Coulomb's ``mu >= 0``) and ``restitution``
    (Newton's ``0 <= e <= 1``)."""
    cls = type(surface).__name__
    object.__setattr__(surface, "friction", _positive(f"{cls}.friction", surface.friction, zero=True))
    e = _positive(f"{cls}.restitution", surface.restitution, zero=True)
    if e > 1:
        raise ValueError(f"{cls}.restitution: must lie in [0, 1], got {e}")
    object.__setattr__(surface, "restitution", e)


def _body(name: str, body):
    if isinstance(body, bool) or not isinstance(body, (str, int, np.integer)):
        raise ValueError(f"{name}: expected a link or frame name or a body index, got {body!r}")
    return body if isinstance(body, str) else int(body)


@dataclass(frozen=True, eq=False)
class Sphere:
    """A sphere of ``radius`` (m) centred at ``center`` (3,) in the coordinates of ``body``."""

    body: str | int
    radius: float
    center: np.ndarray = (0.0, 0.0, 0.0)
    name: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "body", _body("Sphere.body", self.body))
        object.__setattr__(self, "radius", _positive("Sphere.radius", self.radius))
        object.__setattr__(self, "center", _finite("Sphere.center", self.center, (3,)))

    def spheres(self):
        """``([(center, radius)], [label])`` in the body's coordinates."""
        return [(self.center, self.radius)], [""]


@dataclass(frozen=True, eq=False)
class Point:
    """The point ``point`` (3,) of ``body`` (a sphere of radius 0): a sole, a tool tip."""

    body: str | int
    point: np.ndarray = (0.0, 0.0, 0.0)
    name: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "body", _body("Point.body", self.body))
        object.__setattr__(self, "point", _finite("Point.point", self.point, (3,)))

    def spheres(self):
        return [(self.point, 0.0)], [""]


@dataclass(frozen=True, eq=False)
class Box:
    """A box of edge lengths ``size`` (3,) (m), centred at ``center`` and rotated by ``rpy``
    (URDF's extrinsic X-Y-Z angles) in the coordinates of ``body``: its eight corners."""

    body: str | int
    size: np.ndarray
    center: np.ndarray = (0.0, 0.0, 0.0)
    rpy: np.ndarray = (0.0, 0.0, 0.0)
    name: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "body", _body("Box.body", self.body))
        object.__setattr__(self, "center", _finite("Box.center", self.center, (3,)))
        object.__setattr__(self, "rpy", _finite("Box.rpy", self.rpy, (3,)))
        object.__setattr__(self, "size", _edges("Box.size", self.size))

    def spheres(self):
        c, R = self.center, rpy_to_matrix(self.rpy)
        signs = [(sx, sy, sz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        corners = [c + R @ (0.5 * self.size * np.array(s)) for s in signs]
        labels = ["[" + "".join("+" if v > 0 else "-" for v in s) + "]" for s in signs]
        return [(x, 0.0) for x in corners], labels


@dataclass(frozen=True, eq=False)
class Capsule:
    """A capsule: the segment of ``length`` (m) along the local ``z`` axis, centred at
    ``center`` and rotated by ``rpy`` in the coordinates of ``body``, swept by a sphere of
    ``radius``; against planes, the spheres at its two ends."""

    body: str | int
    radius: float
    length: float
    center: np.ndarray = (0.0, 0.0, 0.0)
    rpy: np.ndarray = (0.0, 0.0, 0.0)
    name: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "body", _body("Capsule.body", self.body))
        object.__setattr__(self, "center", _finite("Capsule.center", self.center, (3,)))
        object.__setattr__(self, "rpy", _finite("Capsule.rpy", self.rpy, (3,)))
        object.__setattr__(self, "radius", _positive("Capsule.radius", self.radius))
        object.__setattr__(self, "length", _positive("Capsule.length", self.length, zero=True))

    def spheres(self):
        c, R = self.center, rpy_to_matrix(self.rpy)
        h = 0.5 * self.length * R[:, 2]
        return [(c - h, self.radius), (c + h, self.radius)], ["[-]", "[+]"]


@dataclass(frozen=True, eq=False)
class Plane:
    """The static half-space ``normal^T x <= height`` (world coordinates), its surface a
    plane: the ground by default. ``friction``: Coulomb's ``mu >= 0``; ``restitution``:
    Newton's ``0 <= e <= 1`` (0: impacts are inelastic)."""

    normal: np.ndarray = (0.0, 0.0, 1.0)
    height: float = 0.0
    friction: float = 1.0
    restitution: float = 0.0
    name: str = "ground"

    def __post_init__(self):
        n = np.array(_finite("Plane.normal", self.normal, (3,)))
        norm = np.linalg.norm(n)
        if norm < 1e-9:
            raise ValueError(f"Plane.normal: must not be zero, got {n.tolist()}")
        n /= norm
        n.flags.writeable = False
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "height", float(_finite("Plane.height", self.height, ())))
        _set_coefficients(self)


@dataclass(frozen=True, eq=False)
class StaticBox:
    """A box fixed in the world (an obstacle, a table, a step): edge lengths ``size`` (3,),
    centred at ``center`` and rotated by ``rpy`` (extrinsic X-Y-Z) in world coordinates; solid
    inside. ``friction``, ``restitution`` as :class:`Plane`'s. Spheres and points touch it at
    the nearest point of its surface (faces, edges, corners)."""

    size: np.ndarray
    center: np.ndarray = (0.0, 0.0, 0.0)
    rpy: np.ndarray = (0.0, 0.0, 0.0)
    friction: float = 1.0
    restitution: float = 0.0
    name: str = "box"

    def __post_init__(self):
        object.__setattr__(self, "size", _edges("StaticBox.size", self.size))
        object.__setattr__(self, "center", _finite("StaticBox.center", self.center, (3,)))
        object.__setattr__(self, "rpy", _finite("StaticBox.rpy", self.rpy, (3,)))
        _set_coefficients(self)


@dataclass(frozen=True, eq=False)
class BodySphere:
    """A sphere of ``radius`` centred at ``center`` in the coordinates of ``body`` (a link or
    frame of the same model), as a surface the robot's shapes touch: an object held or
    pushed (a ball on a free joint), a part of the robot another part may hit. ``friction``,
    ``restitution`` as :class:`Plane`'s. The pair's force acts on the shape's body; the
    sphere's body takes the opposite force. A shape on the sphere's own body is never paired
    with it."""

    body: str | int
    radius: float
    center: np.ndarray = (0.0, 0.0, 0.0)
    friction: float = 1.0
    restitution: float = 0.0
    name: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "body", _body("BodySphere.body", self.body))
        object.__setattr__(self, "radius", _positive("BodySphere.radius", self.radius))
        object.__setattr__(self, "center", _finite("BodySphere.center", self.center, (3,)))
        _set_coefficients(self)
        if self.name is None:
            object.__setattr__(self, "name", f"{self.body}:sphere")


def _surface_row(s, model) -> np.ndarray:
    """The row of ``solver``'s surface table for a :class:`Plane`, :class:`StaticBox` or
    :class:`BodySphere` (on ``model``)."""
    from ..algorithms.jacobian import moving_frame
    from . import solver as S

    row = np.zeros(S.SURFACE_COLUMNS)
    row[S.FRICTION], row[S.RESTITUTION] = s.friction, s.restitution
    if isinstance(s, BodySphere):
        b, R, p = moving_frame(model, s.body)
        row[S.KIND], row[S.RADIUS], row[S.BODY] = S.BODY_SPHERE, s.radius, b
        row[S.CENTER:S.CENTER + 3] = p + R @ s.center
    elif isinstance(s, Plane):
        row[S.KIND] = S.PLANE
        row[S.NORMAL:S.NORMAL + 3], row[S.HEIGHT] = s.normal, s.height
    else:
        row[S.KIND] = S.BOX
        row[S.CENTER:S.CENTER + 3] = s.center
        row[S.ROTATION:S.ROTATION + 9] = rpy_to_matrix(s.rpy).ravel()
        row[S.HALF:S.HALF + 3] = 0.5 * s.size
    return row


SHAPES = (Sphere, Point, Box, Capsule)
SURFACES = (Plane, StaticBox, BodySphere)


@dataclass(frozen=True, eq=False)
class Contacts:
    """Shapes on the robot, static surfaces, and the settings of the contact solver.

    ``shapes``: :class:`Sphere`, :class:`Point`, :class:`Box`, :class:`Capsule`;
    ``surfaces``: :class:`Plane`, :class:`StaticBox`, :class:`BodySphere` (default: the ground
    ``z = 0`` with ``mu = 1``).

    Solver settings (see :mod:`robodyn.contact.solver`): ``tolerance`` (m/s) the residual
    at which a step's solve stops (the largest velocity error of Coulomb's law, see
    ``solver.coulomb_residual``); ``max_iterations`` per step; ``warn_above`` (m/s): steps
    whose residual stays above it (at ``max_iterations``) are reported in a warning
    (every step's residual is in the trajectory: a few impacts of redundant contacts, as a
    box's face landing while it slides, stall a little above the tolerance);
    ``stabilization`` the fraction of a penetration removed per step (Baumgarte-like, at
    velocity level) and ``max_correction`` (m/s) its largest separating speed, so that a deep
    penetration at the start does not explode; ``bounce_speed`` (m/s) the approach speed
    below which impacts are inelastic whatever the restitution (a body comes to rest);
    ``margin`` (m) the distance under which a pair enters the solver before it touches.
    """

    shapes: tuple = ()
    surfaces: tuple = field(default_factory=lambda: (Plane(),))
    tolerance: float = 1e-10
    max_iterations: int = 1000
    warn_above: float = 1e-6
    stabilization: float = 0.2
    max_correction: float = 0.5
    bounce_speed: float = 0.05
    margin: float = 1e-3

    def __post_init__(self):
        shapes = tuple(self.shapes) if isinstance(self.shapes, (list, tuple)) else (self.shapes,)
        for k, s in enumerate(shapes):
            if not isinstance(s, SHAPES):
                raise ValueError(f"Contacts.shapes[{k}]: expected a Sphere, Point, Box or Capsule, got {s!r}")
        surfaces = tuple(self.surfaces) if isinstance(self.surfaces, (list, tuple)) else (self.surfaces,)
        for k, s in enumerate(surfaces):
            if not isinstance(s, SURFACES):
                raise ValueError(f"Contacts.surfaces[{k}]: expected a Plane, StaticBox or BodySphere, got {s!r}")
        if not shapes or not surfaces:
            raise ValueError("Contacts: needs at least one shape and one surface")
        object.__setattr__(self, "shapes", shapes)
        object.__setattr__(self, "surfaces", surfaces)
        for key in ("tolerance", "max_correction", "margin", "warn_above"):
            object.__setattr__(self, key, _positive(f"Contacts.{key}", getattr(self, key)))
        for key in ("stabilization", "bounce_speed"):
            object.__setattr__(self, key, _positive(f"Contacts.{key}", getattr(self, key), zero=True))
        if self.stabilization > 1:
            raise ValueError(f"Contacts.stabilization: must lie in [0, 1], got {self.stabilization}")
        if isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, (int, np.integer)) \
                or self.max_iterations < 1:
            raise ValueError(f"Contacts.max_iterations: expected an integer >= 1, got {self.max_iterations!r}")

    def pack(self, model):
        """The kernel arrays of these contacts on ``model``: ``(points, surfaces, settings, names)``.

        ``points`` = ``(body (np,) int64, center (np, 3) in the body frame, radius (np,))``;
        ``surfaces`` (ns, ``solver.SURFACE_COLUMNS``), one row per surface; ``settings``
        (``SETTINGS_SIZE``,); ``names``: one per pair, point-major (pair ``p ns + s``).
        """
        from ..algorithms.jacobian import moving_frame

        bodies, centers, radii, labels = [], [], [], []
        for k, s in enumerate(self.shapes):
            try:
                b, R, p = moving_frame(model, s.body)
            except (KeyError, ValueError, IndexError) as e:
                raise ValueError(f"Contacts.shapes[{k}]: {e}") from None
            base = s.name or (s.body if isinstance(s.body, str) else model.link_names[b]) \
                + f":{type(s).__name__.lower()}"
            for (c, r), lab in zip(*s.spheres()):
                bodies.append(b)
                centers.append(p + R @ c)
                radii.append(r)
                labels.append(base + lab)
        rows = []
        for k, s in enumerate(self.surfaces):
            try:
                rows.append(_surface_row(s, model))
            except (KeyError, ValueError, IndexError) as e:
                raise ValueError(f"Contacts.surfaces[{k}]: {e}") from None
        surf = np.array(rows)
        settings = np.array([self.max_iterations, self.tolerance, self.stabilization, self.max_correction,
                             self.bounce_speed, self.margin], dtype=float)
        names = tuple(f"{lab}@{s.name}" for lab in labels for s in self.surfaces)
        if len(set(names)) != len(names):
            raise ValueError("Contacts: two contact pairs have the same name; name the shapes (name=...) apart")
        return (np.array(bodies, dtype=np.int64), np.array(centers, dtype=float).reshape(-1, 3),
                np.array(radii, dtype=float)), surf, settings, names


def shapes_from_urdf(source, links=None, *, cylinders: str = "capsule", meshes: str = "skip") -> list:
    """The contact shapes of the ``<collision>`` elements of a URDF.

    ``source`` is a file path or an XML string. The shapes sit on the links (or the frames
    that fixed joints merge them into) that carry them: spheres,
    boxes, and cylinders as capsules of the same radius and overall length (``cylinders=
    "capsule"``, rounded ends; ``"error"`` refuses them). Meshes are not read: ``meshes="skip"``
    leaves them out with one warning naming their links, ``"error"`` refuses them. ``links``:
    None (every link) or the names of the links to read (the feet, say). Each shape is named
    ``<link>:<geometry><k>`` (``k`` its rank on the link)."""
    import warnings

    from ..errors import ModelError, RobodynWarning
    from ..io.urdf import read_collisions

    if cylinders not in ("capsule", "error") or meshes not in ("skip", "error"):
        raise ValueError(f"cylinders: 'capsule' or 'error', meshes: 'skip' or 'error'; got {cylinders!r}, {meshes!r}")
    shapes, skipped, rank = [], [], {}
    wanted = None if links is None else set(links)
    for c in read_collisions(source):
        if wanted is not None and c.link not in wanted:
            continue
        k = rank[c.link] = rank.get(c.link, -1) + 1
        name = f"{c.link}:{c.kind}{k}"
        if c.kind == "sphere":
            shapes.append(Sphere(c.link, c.size[0], c.xyz, name=name))
        elif c.kind == "box":
            shapes.append(Box(c.link, c.size, c.xyz, c.rpy, name=name))
        elif c.kind == "cylinder":
            if cylinders == "error":
                raise ModelError(f"{c.where}: a cylinder (cylinders='error'); use cylinders='capsule'")
            radius, length = c.size
            shapes.append(Capsule(c.link, radius, max(length - 2 * radius, 0.0), c.xyz, c.rpy, name=name))
        elif meshes == "error":
            raise ModelError(f"{c.where}: a mesh ({c.filename}) is not read as a contact shape")
        else:
            skipped.append(c.link)
    if skipped:
        warnings.warn(f"shapes_from_urdf: {len(skipped)} mesh collision geometries not read (links "
                      f"{', '.join(dict.fromkeys(skipped))}); give their contact shapes in code", RobodynWarning,
                      stacklevel=2)
    return shapes
