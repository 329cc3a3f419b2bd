"""The browser viewer: a viser scene (three.js in the browser, driven from Python over a
websocket) of the robot, with a trajectory player.

Scene tree: ``/robot/<body>`` one frame per body, posed in the world at every sample, holding
its visual parts at their fixed pose in the body frame (so a time step only moves ``nb``
frames); ``/fixed`` the geometry fixed to the world; ``/ground`` a grid on z = 0 (lower,
under a robot that reaches below it); ``/world_axes``; ``/com`` the centre of mass;
``/contacts`` the contact points and forces.
"""

from __future__ import annotations

import math
import re
import threading
import time

import numpy as np

from .camera import Camera
from .geometry import require
from .scene import Playback, bounds, nice_step, parts, playback

FORCE_RGB = (220, 30, 30)
COM_RGB = (30, 30, 30)


class Viewer:
    """A running viewer (returned by :func:`show`): ``server`` the ``viser.ViserServer``,
    ``url`` where to open it, ``playback`` the :class:`~robodyn.viewer.scene.Playback`
    shown, ``bodies`` the scene frames of the bodies (viser handles, one per body: add your
    own objects under ``bodies[i].name``, or hide one with ``.visible = False``), ``world``
    the frame of the geometry fixed to the world, ``slider`` the time slider (a viser GUI
    handle, seconds) and ``play_button``, or None for a single configuration.
    :meth:`show_sample` poses the robot; :meth:`stop` ends the server."""

    def __init__(self, server, play: Playback, bodies, world, com_marker, contact_points, contact_forces,
                 force_scale):
        self.server, self.playback = server, play
        self.url = f"http://localhost:{server.get_port()}"
        self.bodies, self.world = bodies, world
        self._com, self._force_scale = com_marker, force_scale
        self._contact_points, self._contact_forces = contact_points, contact_forces
        self.slider = self.play_button = None
        self.sample = 0
        self.playing = False
        self._stopped = threading.Event()
        self._player = None

    def show_sample(self, k: int) -> None:
        """Pose every body (and the centre of mass, the contacts) at sample ``k``."""
        vtf = require("viser.transforms")
        play = self.playback
        self.sample = k = int(k)
        T = play.body_poses[k]
        with self.server.atomic():
            for handle, pose in zip(self.bodies, T):
                handle.wxyz = vtf.SO3.from_matrix(pose[:3, :3]).wxyz
                handle.position = pose[:3, 3]
            if self._com is not None:
                self._com.position = play.com[k]
            if self._contact_forces is not None:
                segments = play.force_segments(k, *self._force_scale)
                self._contact_points.visible = self._contact_forces.visible = len(segments) > 0
                if len(segments):
                    self._contact_points.points = segments[:, 0]
                    self._contact_forces.points = segments

    def add_player(self) -> None:
        """Add the time slider (seconds), a play/pause button and a speed factor (done by
        :func:`show` for a trajectory); playing runs in a thread that moves the slider in real
        time (times the speed), looping."""
        gui, t = self.server.gui, self.playback.t
        step = float(np.median(np.diff(t)))
        self.slider = gui.add_slider("time (s)", min=float(t[0]), max=float(t[-1]), step=step,
                                     initial_value=float(t[0]))
        self.play_button = gui.add_button("Play")
        speed = gui.add_slider("speed", min=0.1, max=4.0, step=0.1, initial_value=1.0)
        self.slider.on_update(lambda _: self.show_sample(self.playback.index(self.slider.value)))

        @self.play_button.on_click
        def _(_):
            self.playing = not self.playing
            self.play_button.label = "Pause" if self.playing else "Play"

        def run():
            last = time.perf_counter()
            while not self._stopped.wait(1 / 30):
                now = time.perf_counter()
                if self.playing:
                    value = self.slider.value + (now - last) * speed.value
                    self.slider.value = float(t[0]) if value > t[-1] else value
                last = now

        self._player = threading.Thread(target=run, name="robodyn-viewer-player", daemon=True)
        self._player.start()

    def stop(self) -> None:
        """Stop the player and the server (the port is free again)."""
        self._stopped.set()
        if self._player is not None:
            self._player.join()
        self.server.stop()


def _node(name: str) -> str:
    """A scene-tree name segment from a link name."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "_"


def _rgb(rgba) -> tuple[int, int, int]:
    return tuple(int(round(255 * x)) for x in rgba[:3])


def _add_part(server, parent: str, part, vtf) -> None:
    """A part under the frame ``parent``: one mesh per colour (viser colours a mesh as a whole)."""
    colors = np.asarray(part.mesh.colors)
    keys, group = np.unique(np.round(colors, 3), axis=0, return_inverse=True)
    group = group.reshape(-1)
    wxyz, position = vtf.SO3.from_matrix(part.pose[:3, :3]).wxyz, part.pose[:3, 3]
    for g, rgba in enumerate(keys):
        faces = part.mesh.faces[group == g]
        used, local = np.unique(faces, return_inverse=True)
        server.scene.add_mesh_simple(f"{parent}/{_node(part.name)}_{g}", part.mesh.vertices[used],
                                     local.reshape(faces.shape), color=_rgb(rgba),
                                     opacity=float(rgba[3]) if rgba[3] < 1 else None, side="double",
                                     wxyz=wxyz, position=position)


def show(model, q=None, *, trajectory=None, visuals=None, contacts=None, port: int = 8080, host: str = "127.0.0.1",
         frames: bool = False, com: bool = False, camera=None, block: bool = True) -> Viewer:
    """Serve a 3-D view of the robot in the browser (viser) at ``http://localhost:<port>``.

    ``q`` (nq,): the configuration shown (None: every joint at zero); ``trajectory``: a
    :class:`robodyn.Trajectory` or the path of a log in robodyn's format (CSV or Parquet),
    played with a time slider and a play/pause button (its contact points and forces drawn
    when it has them: red segments, the robot's weight half its size, none longer than it;
    ``contacts``: see :func:`robodyn.viewer.scene.playback`). ``visuals``: the URDF (path
    or XML text) the model was loaded from, or records of :func:`robodyn.viewer.visuals`;
    None (or no visual geometry): the capsule skeleton. ``frames``: show the world and body frames
    (x red, y green, z blue); ``com``: each body's centre of mass (a grey sphere, its volume
    proportional to the mass) and the robot's (black). ``camera``: the initial view
    (:class:`~robodyn.viewer.Camera`), fitted to the robot by default. ``port`` 0 picks a
    free port; a busy port is replaced by the next free one (``Viewer.url`` says which).
    ``host``: the interface to listen on (``"0.0.0.0"``: every one, to view from another
    machine). ``block``: serve until Ctrl-C, then stop; else return at once with the server
    running (stop it with :meth:`Viewer.stop`).

    Needs the optional extra: ``pip install "robodyn[viewer]"`` (viser, trimesh).
    """
    viser = require("viser")
    vtf = require("viser.transforms")
    parts_ = parts(model, visuals)
    play = playback(model, q, trajectory, contacts)
    lo, hi = bounds(parts_, play)
    cam = Camera.of(camera).fitted(lo, hi)
    size = max(float(np.max(hi - lo)), 1e-3)

    server = viser.ViserServer(host=host, port=port, verbose=False)
    server.scene.set_up_direction("+z")
    server.initial_camera.position = cam.eye()
    server.initial_camera.look_at = np.asarray(cam.target)
    server.initial_camera.fov = math.radians(cam.fov)
    cell = nice_step(size / 8)
    width = 2 * math.ceil(1.5 * size / cell) * cell
    center = np.round(np.asarray(cam.target[:2]) / cell) * cell
    server.scene.add_grid("/ground", width=width, height=width, plane="xy", cell_size=cell, section_size=5 * cell,
                          position=(float(center[0]), float(center[1]), min(0.0, float(lo[2]))))
    axes = dict(axes_length=0.15 * size, axes_radius=0.004 * size)
    server.scene.add_frame("/world_axes", show_axes=frames, **axes)
    names = [_node(name) for name in model.link_names]
    if len(set(names)) < len(names):  # link names that differ only in characters a scene name cannot hold
        names = [f"{i}_{name}" for i, name in enumerate(names)]
    bodies = [server.scene.add_frame(f"/robot/{name}", show_axes=frames, **axes) for name in names]
    world = server.scene.add_frame("/fixed", show_axes=False)
    for part in parts_:
        _add_part(server, (world if part.body < 0 else bodies[part.body]).name, part, vtf)
    com_marker = None
    if com and model.total_mass > 0:
        heaviest = float(model.theta[:, 0].max())
        for i, body in enumerate(bodies):
            mass = model.theta[i, 0]
            if mass > 0:
                server.scene.add_icosphere(f"{body.name}/com", radius=0.03 * size * (mass / heaviest) ** (1 / 3),
                                           color=(150, 150, 150), position=model.theta[i, 1:4] / mass)
        com_marker = server.scene.add_icosphere("/com", radius=0.035 * size, color=COM_RGB)
    points = forces = None
    scale = (0.0, 0.0)
    if play.contact_forces is not None and play.contact_forces.size:
        scale = (play.force_scale(model, size), size)
        points = server.scene.add_point_cloud("/contacts/points", np.zeros((1, 3)), FORCE_RGB,
                                              point_size=0.02 * size, point_shape="circle")
        forces = server.scene.add_line_segments("/contacts/forces", np.zeros((1, 2, 3)), FORCE_RGB,
                                                thickness=0.006 * size)
    viewer = Viewer(server, play, bodies, world, com_marker, points, forces, scale)
    viewer.show_sample(0)
    if len(play.t) > 1:
        viewer.add_player()
    print(f"robodyn viewer: {model.name} at {viewer.url} (Ctrl-C to stop)" if block
          else f"robodyn viewer: {model.name} at {viewer.url}", flush=True)
    if block:
        try:
            while True:
                time.sleep(0.5)
        except KeyboardInterrupt:
            pass
        finally:
            viewer.stop()
    return viewer
