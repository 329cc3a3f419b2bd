"""See the robot: a 3-D viewer in the browser and offscreen renders.

    import robodyn as rd
    path = "panda.urdf"
    model = rd.load_urdf(path)
    rd.viewer.show(model, q, visuals=path)                     # http://localhost:8080
    rd.viewer.show(model, trajectory=traj, visuals=path)       # time slider, play/pause
    rd.viewer.render(model, q, "panda.png", visuals=path)      # matplotlib, no display
    rd.viewer.render_video(model, traj, "run.gif", fps=25, visuals=path)

The model keeps no geometry: ``visuals=`` names the URDF it was loaded from (its
``<visual>`` elements: meshes STL/OBJ/DAE by trimesh, ``package://`` and relative paths
resolved, boxes, cylinders, spheres, ``<material>`` colours) or the MJCF file (its geoms,
:func:`mjcf_visuals`), or gives the records of :func:`visuals`. Without visuals a robot is
drawn as its capsule skeleton (:func:`skeleton`).

:func:`show` (browser, viser) needs the optional extra, ``pip install "robodyn[viewer]"``
(viser, trimesh, pycollada for DAE meshes); :func:`render` and :func:`render_video` need
only matplotlib, and trimesh for meshes. The command line: ``robodyn view MODEL``.
"""

from .camera import Camera
from .geometry import Mesh, VisualShape, mjcf_visuals, resolve_mesh, shape_mesh, skeleton, visual_poses, visuals
from .offscreen import render, render_video
from .scene import Part, Playback, parts, playback
from .server import Viewer, show

__all__ = ["show", "render", "render_video", "visuals", "mjcf_visuals", "visual_poses", "skeleton", "VisualShape",
           "Camera", "Viewer", "Mesh", "Part", "Playback", "parts", "playback", "resolve_mesh", "shape_mesh"]
