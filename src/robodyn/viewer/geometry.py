"""What the viewer draws, in the frames of the model's bodies: visual records, mesh files,
primitives as triangles, and the capsule skeleton of a robot without visual geometry.

A :class:`VisualShape` is one piece of geometry fixed to a body of a :class:`~robodyn.Model`:
``pose`` (4, 4) maps the geometry frame to the body frame (URDF ``<visual><origin>``
composed with the placement of the link in the body that fixed joints merged it into, see
:meth:`robodyn.Model.frame_index`), so that its world pose at ``q`` is
``forward_kinematics(model, q)[body] @ pose`` (:func:`visual_poses`). Triangles
(:class:`Mesh`) are in the geometry frame, metres, with one RGBA colour per face.

URDF mesh ``filename``s are resolved as ROS tools resolve them: ``package://pkg/rest`` in
the given ``package_dirs`` (``<dir>/pkg/rest``, or ``<dir>/rest`` when ``<dir>`` is named
``pkg``), then in the folders above the URDF file (the first one named ``pkg``, or holding
``pkg``), then in ``ROS_PACKAGE_PATH``; ``file://`` paths and absolute paths as they are;
relative paths from the URDF's folder (the working directory for XML text).
"""

from __future__ import annotations

import importlib
import math
import os
import re
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..builder import rpy_to_matrix
from ..errors import RobodynWarning
from ..io.urdf import is_xml_text

DEFAULT_RGBA = np.array([0.72, 0.74, 0.78, 1.0])  # geometry the file gives no colour
LINK_RGBA = np.array([0.56, 0.64, 0.74, 1.0])  # skeleton segments
JOINT_RGBA = np.array([0.96, 0.62, 0.22, 1.0])  # skeleton joints
KINDS = ("box", "cylinder", "sphere", "capsule", "ellipsoid", "mesh")


def require(module: str):
    """Import ``module`` (viser, trimesh) or say how to install the viewer's extra."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"robodyn.viewer needs {module}, which is not installed: "
                          'pip install "robodyn[viewer]"') from e


class VisualShape(NamedTuple):
    """One piece of visual geometry on a body.

    ``name``: unique label (``<link>_<k>``, the k-th visual of the link, as Pinocchio names
    its geometry objects); ``link``: the URDF link (or model body) it belongs to; ``body``:
    the body index in the model after fixed-joint merging (-1: fixed to the world); ``pose``
    (4, 4): the geometry frame in the body frame; ``kind``: one of ``KINDS``; ``size``:
    ``(radius,)`` for a sphere, ``(radius, length)`` along the local z axis for a cylinder or
    a capsule (length between the two sphere centres), the three edges of a box, the three
    semi-axes of an ellipsoid, ``()`` for a mesh; ``mesh``: the resolved mesh file (or
    None); ``scale`` (3,): the mesh's scale per axis; ``rgba`` (4,) in [0, 1], or None: the
    mesh file's own colours (else grey)."""
    name: str
    link: str
    body: int
    pose: np.ndarray
    kind: str
    size: tuple
    mesh: Path | None
    scale: np.ndarray
    rgba: np.ndarray | None


def homogeneous(R, p) -> np.ndarray:
    """The 4 x 4 matrix of the rigid motion ``x -> R x + p``."""
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def visuals(source, model=None, *, floating_base: bool = False, package_dirs=()) -> list[VisualShape]:
    """The visual geometry of a URDF file (path) or XML string, on the bodies of ``model``
    (an MJCF file or string: its geoms, :func:`mjcf_visuals`).

    ``model``: the model loaded from the same source (default: ``load_urdf(source,
    floating_base)``); every link is mapped to the body a fixed joint merged it into with its
    placement there. ``package_dirs``: folders that hold the ``package://`` packages (see
    the module docstring). The XML is read by :func:`robodyn.io.urdf.read_visuals` (the
    URDF loader's hardened reader, with its size and depth limits). A visual that cannot be
    drawn (unknown geometry, missing mesh file, a link the model does not have) is left out
    with a :class:`RobodynWarning` naming the link (and the file).
    """
    from ..io.urdf import load_urdf, read_visuals

    if is_mjcf(source):
        return mjcf_visuals(source, model)
    if model is None:
        model = _quietly(load_urdf, source, floating_base=floating_base)
    base = Path.cwd() if is_xml_text(source) or isinstance(source, bytes) else Path(source).resolve().parent
    out, count = [], {}
    for v in read_visuals(source):
        k = count[v.link] = count.get(v.link, -1) + 1
        try:
            b, R, p = model.frame_index(v.link)
        except ValueError:
            warnings.warn(f"{v.where}: link {v.link!r} is not in the model; its visual is not drawn",
                          RobodynWarning, stacklevel=2)
            continue
        mesh = None
        if v.kind == "mesh":
            mesh = resolve_mesh(v.filename, base, package_dirs)
            if mesh is None:
                warnings.warn(f"{v.where}: mesh file {v.filename!r} of link {v.link!r} not found; "
                              "this visual is not drawn", RobodynWarning, stacklevel=2)
                continue
        pose = homogeneous(R, p) @ homogeneous(rpy_to_matrix(v.rpy), v.xyz)
        out.append(VisualShape(f"{v.link}_{k}", v.link, int(b), pose, v.kind, tuple(v.size), mesh,
                               np.asarray(v.scale, dtype=float), v.rgba))
    return out


def _quietly(load, *args, **kwargs):
    """``load(*args, **kwargs)`` without its warnings: what a loader ignores is no news for a drawing."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        return load(*args, **kwargs)


def is_mjcf(source) -> bool:
    """Whether ``source`` is MJCF: text (or a file ending in ``.xml`` or ``.mjcf``) whose
    first element is ``<mujoco>``."""
    if isinstance(source, bytes):
        source = source[:4096].decode("utf-8", "replace")
    elif not is_xml_text(source):
        if not str(source).lower().endswith((".xml", ".mjcf")):
            return False
        try:  # a URDF may be saved as .xml too: its first element decides
            with open(source, "rb") as f:
                source = f.read(4096).decode("utf-8", "replace")
        except OSError:
            return True  # the MJCF reader names the file it cannot read
    first = re.search(r"<\s*([A-Za-z_][\w.:-]*)", re.sub(r"<\?.*?\?>|<!--.*?-->", "", source, flags=re.S))
    return first is not None and first.group(1) == "mujoco"


def mjcf_visuals(source, model=None) -> list[VisualShape]:
    """The geoms of an MJCF file (path) or XML string as :class:`VisualShape` records on the
    bodies of ``model`` (default: ``load_mjcf(source)``), read by
    :func:`robodyn.io.mjcf.read_mjcf_visuals` (the geoms MuJoCo shows by default, named by
    their ``name`` or ``<body>_<k>``); a geom whose body the model lacks or whose mesh file is
    missing is left out with a :class:`RobodynWarning`."""
    from ..io.mjcf import load_mjcf, read_mjcf_visuals

    if model is None:
        model = _quietly(load_mjcf, source)
    out = []
    for g in read_mjcf_visuals(source):
        try:
            b, R, p = (-1, np.eye(3), np.zeros(3)) if g.link == "world" else model.frame_index(g.link)
        except ValueError:
            warnings.warn(f"{g.where}: body {g.link!r} is not in the model; its geom is not drawn", RobodynWarning,
                          stacklevel=2)
            continue
        mesh = None if g.filename is None else Path(g.filename)
        if mesh is not None and not mesh.is_file():
            warnings.warn(f"{g.where}: mesh file {g.filename!r} not found; this geom is not drawn", RobodynWarning,
                          stacklevel=2)
            continue
        out.append(VisualShape(g.name, g.link, int(b), homogeneous(R, p) @ homogeneous(g.R, g.p), g.kind, g.size,
                               mesh, g.scale, g.rgba))
    return out


def resolve_mesh(filename: str, base: Path, package_dirs=()) -> Path | None:
    """The existing file a URDF mesh ``filename`` names (``package://``, ``file://``,
    absolute or relative to ``base``, the URDF's folder), or None when there is none."""
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        roots = [Path(d) for d in package_dirs]
        roots += [base, *base.parents]
        roots += [Path(d) for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
        for root in roots:
            for candidate in (root / rest if root.name == package else None, root / package / rest):
                if candidate is not None and candidate.is_file():
                    return candidate
        return None
    path = Path(filename[len("file://"):] if filename.startswith("file://") else filename)
    path = path if path.is_absolute() else base / path
    return path if path.is_file() else None


def skeleton(model) -> list[VisualShape]:
    """The capsule skeleton of a model: a capsule from each body's origin (its joint) to the
    joint of each child (in the body frame), one from a leaf body's origin to its centre of
    mass, one from the world origin to each root joint, and a sphere at every joint. The radius
    is a tenth of the median segment length (1.6 times that for the joints)."""
    segments = []  # (body, name, start, end) in the body frame
    for i in range(model.nbodies):
        par = int(model.parent[i])
        segments.append((par, model.link_names[par] if par >= 0 else "world", np.zeros(3), model.X_tree_p[i]))
        mass = model.theta[i, 0]
        if mass > 0 and not np.any(model.parent == i):
            segments.append((i, model.link_names[i], np.zeros(3), model.theta[i, 1:4] / mass))
    lengths = [np.linalg.norm(e - s) for _, _, s, e in segments]
    nonzero = [x for x in lengths if x > 1e-9]
    radius = 0.1 * float(np.median(nonzero)) if nonzero else 0.05
    out, count = [], {}
    for (b, name, s, e), length in zip(segments, lengths):
        if length <= 1e-9:
            continue
        k = count[name] = count.get(name, -1) + 1
        pose = homogeneous(_z_to(e - s), (s + e) / 2)
        out.append(VisualShape(f"{name}_segment{k}", name, b, pose, "capsule", (radius, length), None,
                               np.ones(3), LINK_RGBA))
    for i in range(model.nbodies):
        out.append(VisualShape(f"{model.link_names[i]}_joint", model.link_names[i], i, np.eye(4), "sphere",
                               (1.6 * radius,), None, np.ones(3), JOINT_RGBA))
    return out


def _z_to(d) -> np.ndarray:
    """A rotation whose z axis is the direction of ``d`` (3,)."""
    z = np.asarray(d, dtype=float) / np.linalg.norm(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def visual_poses(model, shapes, q) -> np.ndarray:
    """World poses (..., len(shapes), 4, 4) of the geometry frames at ``q`` (..., nq):
    ``oMi[body] @ pose`` with ``oMi`` from :func:`robodyn.forward_kinematics` (one batched
    call), the identity for geometry fixed to the world."""
    from ..algorithms.kinematics import forward_kinematics

    T = forward_kinematics(model, q)
    poses = np.stack([s.pose for s in shapes]) if shapes else np.zeros((0, 4, 4))
    bodies = np.array([s.body for s in shapes], dtype=int)
    world = np.broadcast_to(np.eye(4), T.shape[:-3] + (1, 4, 4))
    frames = np.concatenate([T, world], axis=-3)[..., bodies, :, :]  # body -1 is the appended identity
    return frames @ poses


class Mesh(NamedTuple):
    """Triangles: ``vertices`` (n, 3) (m, in the geometry frame), ``faces`` (m, 3) vertex
    indices (counter-clockwise seen from outside), ``colors`` (m, 4) RGBA in [0, 1]."""
    vertices: np.ndarray
    faces: np.ndarray
    colors: np.ndarray


def shape_mesh(shape: VisualShape, cache: dict | None = None, resolution: int = 24) -> Mesh | None:
    """The triangles of a shape: a mesh file read by trimesh (STL, OBJ, DAE, ...; ``cache``
    maps files already read to their :class:`Mesh`) and scaled, or a tessellated primitive
    (``resolution`` segments around). Colours: the shape's ``rgba``, else the file's own,
    else ``DEFAULT_RGBA``. None, with a :class:`RobodynWarning` naming the file and the link,
    when the file cannot be read."""
    if shape.kind == "mesh":
        cache = {} if cache is None else cache
        if shape.mesh not in cache:
            try:
                cache[shape.mesh] = load_mesh_file(shape.mesh)
            except ImportError:
                raise
            except Exception as e:  # noqa: BLE001 - the parsers of mesh formats fail in many ways
                cache[shape.mesh] = None
                warnings.warn(f"mesh file {shape.mesh} of link {shape.link!r} cannot be read "
                              f"({type(e).__name__}: {e}); it is not drawn", RobodynWarning, stacklevel=2)
        mesh = cache[shape.mesh]
        if mesh is None:
            return None
        faces = mesh.faces if np.prod(shape.scale) > 0 else mesh.faces[:, ::-1]  # a mirror turns faces inside out
        mesh = Mesh(mesh.vertices * shape.scale, faces, mesh.colors)
    elif shape.kind == "box":
        mesh = _box(np.asarray(shape.size, dtype=float))
    elif shape.kind in ("cylinder", "capsule", "sphere"):
        mesh = _revolution(shape.kind, shape.size, resolution)
    elif shape.kind == "ellipsoid":  # the unit sphere stretched along its axes
        mesh = _revolution("sphere", (1.0,), resolution)
        mesh = mesh._replace(vertices=mesh.vertices * np.asarray(shape.size, dtype=float))
    else:
        raise ValueError(f"{shape.name}: unknown geometry kind {shape.kind!r}; expected one of {KINDS}")
    if shape.rgba is not None:
        mesh = mesh._replace(colors=np.broadcast_to(np.asarray(shape.rgba, dtype=float), (len(mesh.faces), 4)))
    return mesh


def load_mesh_file(path) -> Mesh:
    """The triangles of a mesh file (every part of a scene, placed by the file's node
    transforms), with each part's colour (its material's main colour, or its face colours),
    ``DEFAULT_RGBA`` where the file has none. Needs trimesh (and pycollada for DAE); MuJoCo's
    own ``.msh`` files are read here (:func:`load_msh`)."""
    if Path(path).suffix.lower() == ".msh":
        return load_msh(path)
    trimesh = require("trimesh")
    loaded = trimesh.load(str(path))
    parts = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    vertices, faces, colors, offset = [], [], [], 0
    for part in parts:
        if not isinstance(part, trimesh.Trimesh) or len(part.faces) == 0:
            continue
        vertices.append(np.asarray(part.vertices, dtype=float))
        faces.append(np.asarray(part.faces, dtype=np.int64) + offset)
        colors.append(_part_colors(part))
        offset += len(part.vertices)
    if not faces:
        raise ValueError("no triangles in the file")
    return Mesh(np.concatenate(vertices), np.concatenate(faces), np.concatenate(colors))


def load_msh(path) -> Mesh:
    """The triangles of MuJoCo's legacy binary mesh file (``.msh``): four little-endian int32
    counts (vertices, normals, texture coordinates, faces), then float32 vertices (nv, 3),
    normals (nn, 3), texture coordinates (nt, 2) and int32 vertex indices of the faces (nf,
    3); grey. ValueError when the size does not match the header, an index is out of range,
    or there are no faces (MuJoCo would draw the convex hull)."""
    data = Path(path).read_bytes()
    if len(data) < 16:
        raise ValueError(f"{len(data)} bytes: a .msh file starts with a 16-byte header")
    nv, nn, nt, nf = (int(n) for n in np.frombuffer(data[:16], "<i4"))
    floats = 3 * nv + 3 * nn + 2 * nt
    if min(nv, nn, nt, nf) < 0 or len(data) != 16 + 4 * (floats + 3 * nf):
        raise ValueError(f"{len(data)} bytes do not hold the {nv} vertices, {nn} normals, {nt} texture "
                         f"coordinates and {nf} faces of its header")
    if nf == 0:
        raise ValueError("no triangles in the file")
    vertices = np.frombuffer(data, "<f4", 3 * nv, offset=16).reshape(nv, 3).astype(float)
    faces = np.frombuffer(data, "<i4", 3 * nf, offset=16 + 4 * floats).reshape(nf, 3).astype(np.int64)
    if faces.min() < 0 or faces.max() >= nv:
        raise ValueError(f"a face index outside the {nv} vertices")
    return Mesh(vertices, faces, np.tile(DEFAULT_RGBA, (nf, 1)))


def _part_colors(part) -> np.ndarray:
    """(m, 4) RGBA in [0, 1] of one trimesh part's faces."""
    visual = part.visual
    material = getattr(visual, "material", None)
    if visual.kind == "texture" and material is not None and getattr(material, "main_color", None) is not None:
        return np.broadcast_to(np.asarray(material.main_color, dtype=float) / 255.0, (len(part.faces), 4))
    if visual.kind in ("face", "vertex"):
        return np.asarray(visual.face_colors, dtype=float) / 255.0
    return np.broadcast_to(DEFAULT_RGBA, (len(part.faces), 4))


def _box(size: np.ndarray) -> Mesh:
    """A box of edges ``size`` (3,) centred at the origin: 8 corners, 12 outward triangles."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    faces = []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for s in (-1, 1):
            quad = []
            for u, w in ((-1, -1), (1, -1), (1, 1), (-1, 1)):  # counter-clockwise about +a
                corner = np.zeros(3)
                corner[a], corner[b], corner[c] = s, u, w
                quad.append(int(np.flatnonzero((signs == corner).all(1))[0]))
            if s < 0:
                quad.reverse()
            faces += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    return Mesh(signs * size / 2, np.array(faces, dtype=np.int64), np.broadcast_to(DEFAULT_RGBA, (12, 4)))


def _revolution(kind: str, size: tuple, n: int) -> Mesh:
    """A sphere ``(radius,)``, cylinder or capsule ``(radius, length)`` about the z axis, as
    the surface swept by a profile (radius r(s), height z(s)) from the bottom to the top pole."""
    r = float(size[0])
    half = 0.5 * float(size[1]) if len(size) > 1 else 0.0
    if kind == "cylinder":
        prof_r, prof_z = np.array([0.0, r, r, 0.0]), np.array([-half, -half, half, half])
    else:
        lat = np.linspace(-np.pi / 2, np.pi / 2, max(n // 2, 4) + 1)
        prof_r, prof_z = r * np.cos(lat), r * np.sin(lat)
        prof_r[[0, -1]] = 0.0
        if kind == "capsule":  # the equator twice, the lower hemisphere at -half, the upper at +half
            low = lat <= 0
            prof_r = np.concatenate([prof_r[low], prof_r[~low | (lat == 0)]])
            prof_z = np.concatenate([prof_z[low] - half, prof_z[~low | (lat == 0)] + half])
    angle = 2 * np.pi * np.arange(n) / n
    rings = len(prof_r)
    vertices = np.stack([np.outer(prof_r, np.cos(angle)), np.outer(prof_r, np.sin(angle)),
                         np.repeat(prof_z[:, None], n, axis=1)], axis=-1).reshape(-1, 3)
    j, i = np.meshgrid(np.arange(rings - 1), np.arange(n), indexing="ij")
    a, b = j * n + i, j * n + (i + 1) % n  # ring j, this and the next angle
    c, d = b + n, a + n  # the same on ring j + 1
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    tri = vertices[faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    faces = faces[area > 1e-12 * max(r, half, 1e-12) ** 2]  # the poles' collapsed triangles
    return Mesh(vertices, faces, np.broadcast_to(DEFAULT_RGBA, (len(faces), 4)))


def decimate(mesh: Mesh, max_faces: int) -> Mesh:
    """At most ``max_faces`` triangles by vertex clustering (Rossignac and Borrel, "Multi-
    resolution 3D approximations for rendering complex scenes", 1993): vertices are merged
    per cell of a grid, coarser until few enough triangles survive; degenerate and repeated
    triangles are dropped, the survivors keep their colours."""
    if len(mesh.faces) <= max_faces:
        return mesh
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    extent = float((hi - lo).max()) or 1.0
    cells = 256.0
    for _ in range(12):
        ijk = np.floor((mesh.vertices - lo) / (extent / cells)).astype(np.int64)
        n = int(cells) + 2
        _, cluster, sizes = np.unique((ijk[:, 0] * n + ijk[:, 1]) * n + ijk[:, 2], return_inverse=True,
                                      return_counts=True)
        faces = cluster.reshape(-1)[mesh.faces]
        keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
        a, b, c = np.sort(faces, axis=1).T
        _, first = np.unique((a * len(sizes) + b) * len(sizes) + c, return_index=True)
        unique = np.zeros(len(faces), dtype=bool)
        unique[first] = True
        keep &= unique
        if keep.sum() <= max_faces or cells <= 2:
            break
        # a surface's triangles grow as the square of the grid's resolution
        cells = max(2.0, math.floor(cells * min(0.9, 0.95 * math.sqrt(max_faces / keep.sum()))))
    vertices = np.zeros((len(sizes), 3))
    np.add.at(vertices, cluster.reshape(-1), mesh.vertices)
    return Mesh(vertices / sizes[:, None], faces[keep], np.asarray(mesh.colors)[keep])
