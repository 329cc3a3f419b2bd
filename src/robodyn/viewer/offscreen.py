"""Offscreen renders with matplotlib's 3-D axes (Agg canvas: no display needed): a PNG of one
configuration (:func:`render`) and a GIF or MP4 of a trajectory (:func:`render_video`).

Every triangle of the robot goes into one ``Poly3DCollection`` (depth-sorted as a whole, the
painter's algorithm: Newell, Newell and Sancha, "A solution to the hidden surface problem",
1972), shaded per face by a light from the camera, Lambert's ``ambient + diffuse |n.l|``
(two-sided, as mesh files do not all wind their faces alike); meshes are decimated to a
triangle budget (``max_faces``) to keep matplotlib quick. The axes are equal in x, y and z,
the camera (:class:`~robodyn.viewer.camera.Camera`) is fitted to the robot's extent over
all the frames unless given, and a grid marks the ground plane z = 0 (lower, under a robot
that reaches below it).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .camera import Camera
from .scene import Part, Playback, bounds, nice_step, parts, playback

AMBIENT, DIFFUSE = 0.3, 0.7
ZOOM = 1.6  # matplotlib fits the limits' cube in the axes; the robot's bounding sphere is inscribed in it


def _size(size) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in size)
    except (TypeError, ValueError):
        raise ValueError(f"size: expected (width, height) in pixels, got {size!r}") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192) or (w, h) != tuple(size):
        raise ValueError(f"size: expected two whole numbers of pixels in [16, 8192], got {size!r}")
    return w, h


class Painter:
    """A matplotlib figure of ``size`` pixels drawing ``parts`` of ``model`` at the samples of
    ``play`` from ``camera`` (fitted to the whole playback); :meth:`draw` then :meth:`image`."""

    def __init__(self, model, parts_: list[Part], play: Playback, camera, size, label: str | None = None):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

        self.parts, self.play, self.label = parts_, play, label
        lo, hi = bounds(parts_, play)
        cam = self.camera = Camera.of(camera).fitted(lo, hi)
        w, h = _size(size)
        self.fig = Figure(figsize=(w / 100, h / 100), dpi=100, facecolor="white")
        FigureCanvasAgg(self.fig)
        ax = self.ax = self.fig.add_axes((0, 0, 1, 1), projection="3d")
        ax.set_axis_off()
        ax.computed_zorder = False  # ground, then the robot (sorted within), then the forces
        ax.view_init(elev=cam.elevation, azim=cam.azimuth)
        ax.set_proj_type("persp", focal_length=1 / math.tan(math.radians(cam.fov) / 2))
        half = cam.distance * math.sin(math.radians(cam.fov) / 2)
        target = np.asarray(cam.target)
        ax.set_xlim(target[0] - half, target[0] + half)
        ax.set_ylim(target[1] - half, target[1] + half)
        ax.set_zlim(target[2] - half, target[2] + half)
        ax.set_box_aspect((1, 1, 1), zoom=ZOOM * min(1.0, w / h))
        ground = self._ground(target, half, min(0.0, lo[2]))
        ax.add_collection3d(Line3DCollection(ground, colors=[(0.72, 0.74, 0.78)], linewidths=0.6, zorder=0))
        # every part's vertices together, with the part each belongs to, and the faces renumbered
        offsets = np.cumsum([0] + [len(p.mesh.vertices) for p in parts_])
        self.vertices = np.concatenate([p.mesh.vertices for p in parts_]) if parts_ else np.zeros((0, 3))
        self.owner = np.repeat(np.arange(len(parts_)), np.diff(offsets))
        self.faces = (np.concatenate([p.mesh.faces + o for p, o in zip(parts_, offsets)]) if parts_
                      else np.zeros((0, 3), dtype=np.int64))
        self.colors = np.concatenate([p.mesh.colors for p in parts_]) if parts_ else np.zeros((0, 4))
        eye = cam.eye()
        view = (eye - target) / np.linalg.norm(eye - target)
        right = np.cross([0.0, 0.0, 1.0], view)
        right = right / np.linalg.norm(right) if np.linalg.norm(right) > 1e-9 else np.array([1.0, 0.0, 0.0])
        light = view + 0.6 * np.cross(view, right) + 0.4 * right  # from the camera, above, to its right
        self.light = light / np.linalg.norm(light)
        self.robot = Poly3DCollection([], linewidths=0.25, zorder=1)
        ax.add_collection3d(self.robot, autolim=False)
        self.forces = None
        if play.contact_forces is not None and play.contact_forces.size:
            self.model_size = float(np.max(hi - lo))
            self.force_scale = play.force_scale(model, self.model_size)
            self.forces = Line3DCollection([], colors=[(0.85, 0.1, 0.1)], linewidths=2.0, zorder=2)
            ax.add_collection3d(self.forces, autolim=False)
        self.text = self.fig.text(0.015, 0.015, "", fontsize=9, color="0.25")

    @staticmethod
    def _ground(target, half, z) -> np.ndarray:
        """Segments (K, 2, 3) of a grid at height ``z`` around the target: about 8 cells per view."""
        step = nice_step(half / 4)
        lo = np.floor((target[:2] - 1.5 * half) / step) * step
        hi = np.ceil((target[:2] + 1.5 * half) / step) * step
        xs, ys = np.arange(lo[0], hi[0] + step / 2, step), np.arange(lo[1], hi[1] + step / 2, step)
        lines = [[(x, ys[0], z), (x, ys[-1], z)] for x in xs] + [[(xs[0], y, z), (xs[-1], y, z)] for y in ys]
        return np.array(lines)

    def draw(self, k: int, time: float | None = None) -> None:
        """Pose the robot (and the contact forces) at sample ``k``; the label shows ``time``
        (default: the sample's)."""
        if len(self.parts):
            T = self.play.part_poses(self.parts, k)[self.owner]
            world = np.einsum("vij,vj->vi", T[:, :3, :3], self.vertices) + T[:, :3, 3]
            tri = world[self.faces]
            normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            length = np.linalg.norm(normal, axis=1)
            cosine = np.abs(normal @ self.light) / np.where(length > 0, length, 1.0)
            rgba = self.colors.copy()
            rgba[:, :3] *= (AMBIENT + DIFFUSE * cosine)[:, None]
            self.robot.set_verts(tri)
            self.robot.set_facecolor(rgba)
            self.robot.set_edgecolor(rgba)  # hides the seams between the triangles
        if self.forces is not None:
            self.forces.set_segments(self.play.force_segments(k, self.force_scale, self.model_size))
        if self.label is not None:
            self.text.set_text(f"{self.label}   t = {self.play.t[k] if time is None else time:.2f} s")

    def image(self) -> np.ndarray:
        """The figure as RGB pixels (height, width, 3), uint8."""
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[..., :3].copy()


def render(model, q, path, *, camera=None, size=(800, 600), visuals=None, max_faces: int = 20000) -> Path:
    """Write a PNG of the robot at configuration ``q`` (nq,) (None: every joint at zero).

    ``visuals``: the URDF (path or XML text) the model was loaded from, or records of
    :func:`robodyn.viewer.visuals`; None (or a URDF without visual geometry): the capsule
    skeleton. ``camera``: a :class:`~robodyn.viewer.Camera` or a dict of its fields
    (azimuth, elevation in degrees, distance in m, target (3,), fov in degrees); unset fields
    are fitted to the robot. ``size``: (width, height) in pixels. ``max_faces``: the triangle
    budget of the meshes. Returns the path written (atomically).
    """
    from PIL import Image

    from ..files import atomic_path

    w, h = _size(size)
    painter = Painter(model, parts(model, visuals, max_faces=max_faces), playback(model, q), camera, (w, h))
    painter.draw(0)
    pixels = painter.image()
    with atomic_path(path) as tmp:
        Image.fromarray(pixels).save(tmp, format="PNG")
    return Path(path)


def frame_samples(t: np.ndarray, fps: float) -> np.ndarray:
    """The samples shown by a video at ``fps`` frames per second of samples at times ``t``
    (N,): frame ``j`` shows the last sample at or before ``t[0] + j / fps``, for ``j = 0 ...
    floor((t[-1] - t[0]) fps)`` (real time; a sample may show in several frames)."""
    n = int(math.floor((t[-1] - t[0]) * fps + 1e-9)) + 1
    times = t[0] + np.arange(n) / fps
    return np.clip(np.searchsorted(t, times + 1e-9 * np.maximum(1.0, np.abs(times)), side="right") - 1, 0, len(t) - 1)


def render_video(model, trajectory, path, *, fps: float = 25, camera=None, size=(640, 480), visuals=None,
                 contacts=None, max_faces: int = 8000) -> int:
    """Write a GIF (``.gif``, by Pillow) or an MP4 (``.mp4``, by ffmpeg: the system's, or the
    one of ``pip install robodyn[video]``) of a trajectory, in real time at ``fps`` frames per
    second (see :func:`frame_samples`), with the time in a corner and, for a simulation with contacts,
    the contact forces as red segments (the robot's weight half its size, none longer than
    it; ``contacts``: see
    :func:`robodyn.viewer.scene.playback`). ``trajectory``: a :class:`robodyn.Trajectory`
    or a log file path (CSV or Parquet). ``camera``, ``size``, ``visuals``, ``max_faces`` as
    in :func:`render`; the camera is fitted to the whole motion. Returns the number of frames.
    An unsupported suffix, or MP4 without ffmpeg, is a ``ValueError`` before any work.
    """
    from ..files import atomic_path

    suffix = Path(path).suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"{path}: expected a .gif or .mp4 file name")
    ffmpeg = _ffmpeg(path) if suffix == ".mp4" else None
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps: expected a positive number of frames per second, got {fps!r}")
    w, h = _size(size)
    play = playback(model, trajectory=trajectory, contacts=contacts)
    painter = Painter(model, parts(model, visuals, max_faces=max_faces), play, camera, (w, h), label=model.name)
    samples = frame_samples(play.t, fps)
    with atomic_path(path) as tmp:
        if suffix == ".gif":
            from PIL import Image

            frames = []
            for j, k in enumerate(samples):
                painter.draw(k, play.t[0] + j / fps)
                frames.append(Image.fromarray(painter.image()).quantize(colors=128))
            frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:],
                           duration=max(10, round(1000 / fps)), loop=0)
        else:
            import matplotlib
            from matplotlib.animation import FFMpegWriter

            with matplotlib.rc_context({"animation.ffmpeg_path": ffmpeg}):
                writer = FFMpegWriter(fps=fps)
                with writer.saving(painter.fig, str(tmp), dpi=100):
                    for j, k in enumerate(samples):
                        painter.draw(k, play.t[0] + j / fps)
                        writer.grab_frame()
    return len(samples)


def _ffmpeg(path) -> str:
    """The ffmpeg program that writes ``path``: matplotlib's (``animation.ffmpeg_path``, the
    one on the ``PATH`` by default), else the one the ``imageio-ffmpeg`` package ships
    (``pip install robodyn[video]``); a ``ValueError`` when there is neither."""
    import matplotlib
    from matplotlib.animation import FFMpegWriter

    if FFMpegWriter.isAvailable():
        return matplotlib.rcParams["animation.ffmpeg_path"]
    try:
        import imageio_ffmpeg

        return imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        raise ValueError(f"{path}: writing MP4 needs ffmpeg, which is not installed (pip install "
                         "'robodyn[video]', or apt-get install ffmpeg), or write a .gif") from None
