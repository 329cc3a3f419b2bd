"""``robodyn view``: the robot in the browser (:func:`robodyn.viewer.show`), or rendered to a
PNG or a GIF/MP4 without a browser (:func:`robodyn.viewer.render`, ``render_video``).

    robodyn view MODEL [--trajectory run.csv] [--port N] [--frames] [--com]
    robodyn view MODEL --png robot.png           # one picture, no server
    robodyn view MODEL --trajectory run.csv --video run.gif

A URDF model is drawn with its ``<visual>`` geometry, an MJCF model with its geoms, a built-in
robot as its capsule skeleton.
"""

from __future__ import annotations

from .. import models
from .common import add_model_arguments, check_output_file, loaded, save, written


def _extra(what: str):
    """The viewer's optional packages, or a one-line error saying how to install them."""
    try:
        return __import__(what)
    except ImportError:
        raise ValueError(f'robodyn view needs {what}: pip install "robodyn[viewer]"') from None


def cmd_view(args) -> int:
    import numpy as np

    from ..viewer import render, render_video, show
    from ..viewer.scene import load_trajectory

    if not args.model:
        raise ValueError("robodyn view: give a MODEL (a built-in name, a URDF or an MJCF path)")
    if not 0 <= args.port <= 65535:
        raise ValueError(f"--port {args.port}: expected a port number in [0, 65535] (0: any free port)")
    if args.video and not args.trajectory:
        raise ValueError("--video needs --trajectory FILE, the motion to show")
    check_output_file(args.png, "--png")
    check_output_file(args.video, "--video")
    if args.video and not str(args.video).lower().endswith((".gif", ".mp4")):
        raise ValueError(f"--video {args.video}: expected a .gif or .mp4 file name")
    model = loaded(args)
    visuals = None
    if args.model not in models.names():  # a URDF's visuals or an MJCF file's geoms
        from ..viewer import visuals as read_visuals

        named = not (args.model.lower().endswith((".urdf", ".xml", ".mjcf")) or "/" in args.model)
        source = models.example_robot_urdf(args.model) if named else args.model
        visuals = read_visuals(source, model, package_dirs=args.package_dir)
        if any(v.kind == "mesh" and v.mesh.suffix.lower() != ".msh" for v in visuals):  # .msh: read without it
            _extra("trimesh")
    trajectory = None
    if args.trajectory:
        trajectory = load_trajectory(model, args.trajectory)
        try:  # a configuration the kinematics refuses (non-finite, overflowing) names the file
            from ..algorithms.kinematics import forward_kinematics

            forward_kinematics(model, np.asarray(trajectory.q))
        except ValueError as e:
            raise ValueError(f"--trajectory {args.trajectory}: {e}") from None
    if args.png:
        q = None if trajectory is None else np.asarray(trajectory.q)[0]
        save(lambda path: render(model, q, path, visuals=visuals), args.png, "--png")
        print(f"wrote {written(args.png)}")
    if args.video:
        frames = save(lambda path: render_video(model, trajectory, path, fps=args.fps, visuals=visuals),
                      args.video, "--video")
        print(f"wrote {written(args.video)} ({frames} frames at {args.fps:g} fps)")
    if args.png or args.video:
        return 0
    _extra("viser")
    show(model, trajectory=trajectory, visuals=visuals, port=args.port, host=args.host, frames=args.frames,
         com=args.com, block=True)
    return 0


def add_commands(sub) -> None:
    """Register ``view`` on the ``robodyn`` subcommand parser."""
    p = sub.add_parser("view", help="3-D view in the browser (viser), or a PNG/GIF/MP4 render")
    add_model_arguments(p)
    p.add_argument("--trajectory", metavar="FILE", help="a trajectory or log (CSV or Parquet) to play")
    p.add_argument("--port", type=int, default=8080, help="the viewer's port (default 8080; 0: any free port)")
    p.add_argument("--host", default="127.0.0.1", help="the interface to serve on (0.0.0.0: every one)")
    p.add_argument("--frames", action="store_true", help="show the world and body frames")
    p.add_argument("--com", action="store_true", help="show the centres of mass")
    p.add_argument("--package-dir", action="append", default=[], metavar="DIR",
                   help="a folder holding the package:// packages of the URDF's meshes (repeatable)")
    p.add_argument("--png", metavar="FILE", help="write a PNG render (of the first sample) instead of serving")
    p.add_argument("--video", metavar="FILE", help="write the trajectory as a .gif (or .mp4, with ffmpeg)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second of --video (default 25)")
    p.set_defaults(func=cmd_view)
