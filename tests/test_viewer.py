"""robodyn.viewer: visual geometry read from URDFs (against Pinocchio's visual model),
primitives, decimation, the capsule skeleton, offscreen renders (PNG, GIF) and ``robodyn view``.

The browser viewer itself is tested in test_viewer_browser.py (headless Chromium)."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import robodyn as rd
from conftest import example_robot_data_dir
from robodyn.cli import main
from robodyn.errors import ModelError, RobodynWarning
from robodyn.io.log import write_log
from robodyn.viewer import Camera, VisualShape, shape_mesh, skeleton, visual_poses, visuals
from robodyn.viewer.geometry import Mesh, decimate, load_mesh_file
from robodyn.viewer.offscreen import Painter, frame_samples
from robodyn.viewer.scene import parts, playback

ERD = example_robot_data_dir()
SHARE = ERD.parent.parent  # holds example-robot-data/: Pinocchio's package directory
ROBOTS = {"panda": (ERD / "panda_description/urdf/panda.urdf", False),
          "solo12": (ERD / "solo_description/robots/solo12.urdf", True),
          "ur5": (ERD / "ur_description/urdf/ur5_robot.urdf", False)}


def quiet_load(source, floating_base=False):
    """``load_urdf`` without its warning about what has no dynamics (materials, gazebo, ...);
    mimic joints as independent joints, as Pinocchio's visual models read them."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        return rd.load_urdf(source, floating_base=floating_base, mimic="independent")


def load(name):
    path, floating = ROBOTS[name]
    return path, quiet_load(path, floating)


def pixels(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=int)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_visuals_of_example_robot_data_resolve_and_sit_on_the_right_bodies(name):
    path, model = load(name)
    shapes = visuals(path, model)
    assert len(shapes) == path.read_text().count("<visual")
    for s in shapes:
        assert s.kind == "mesh" and s.mesh.is_file() and s.mesh.is_relative_to(ERD), s
        assert s.body == model.frame_index(s.link)[0]  # the body the link was merged into
        if s.link in model.link_names:
            assert model.link_names[s.body] == s.link
    assert {s.link for s in shapes} <= set(model.link_names) | set(model.frame_names)
    assert {model.link_names[s.body] for s in shapes if s.body >= 0} == set(model.link_names)  # every body drawn


@pytest.mark.parametrize("name", ["panda", "solo12"])
def test_mesh_vertices_after_kinematics_agree_with_pinocchio(name):
    """The world position of every visual mesh's vertices at a random q: robodyn's forward
    kinematics and visual records against Pinocchio's visual GeometryModel placements."""
    import pinocchio as pin
    path, model = load(name)
    root = pin.JointModelFreeFlyer() if ROBOTS[name][1] else None
    args = (str(path), [str(SHARE)]) + ((root,) if root is not None else ())
    pmodel, _, vmodel = pin.buildModelsFromUrdf(*args)
    q = rd.random.random_configuration(model, np.random.default_rng(7))
    pdata, vdata = pmodel.createData(), pin.GeometryData(vmodel)
    pin.updateGeometryPlacements(pmodel, pdata, vmodel, vdata, q)
    shapes = visuals(path, model)
    poses = visual_poses(model, shapes, q)
    ours = {s.name: (s, T) for s, T in zip(shapes, poses)}
    assert set(ours) == {g.name for g in vmodel.geometryObjects}
    meshes = {}
    for k, g in enumerate(vmodel.geometryObjects):
        s, T = ours[g.name]
        assert s.mesh.resolve() == type(s.mesh)(g.meshPath).resolve()
        np.testing.assert_array_equal(s.scale, g.meshScale)
        if s.rgba is not None:
            np.testing.assert_allclose(s.rgba, g.meshColor, atol=1e-6)
        if s.mesh not in meshes:
            meshes[s.mesh] = load_mesh_file(s.mesh).vertices[:400]
        x = meshes[s.mesh] * s.scale
        oMg = vdata.oMg[k].homogeneous
        np.testing.assert_allclose(x @ T[:3, :3].T + T[:3, 3], x @ oMg[:3, :3].T + oMg[:3, 3], rtol=0, atol=1e-9)


URDF = """<robot name="shapes">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <visual><origin xyz="0 0 0.05"/><geometry><box size="0.4 0.3 0.1"/></geometry>
      <material name="red"/></visual>
  </link>
  <link name="arm">
    <inertial><mass value="1"/><origin xyz="0 0 0.25"/><inertia ixx="0.01" iyy="0.01" izz="0.001"/></inertial>
    <visual><origin xyz="0 0 0.25" rpy="0 0 0.3"/><geometry><cylinder radius="0.03" length="0.5"/></geometry>
      <material name="inline"><color rgba="0 0.5 1 0.5"/></material></visual>
  </link>
  <link name="tool">
    <visual><geometry><sphere radius="0.04"/></geometry></visual>
    <visual><origin xyz="0.01 0 0"/><geometry><mesh filename="tool.stl" scale="2 2 -1"/></geometry></visual>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0 0 0.5" rpy="0.2 0 0"/></joint>
</robot>
"""

STL = """solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 0.01 0 0
vertex 0 0.01 0
endloop
endfacet
endsolid t
"""


def test_primitives_materials_and_fixed_joints(tmp_path):
    urdf = tmp_path / "shapes.urdf"
    urdf.write_text(URDF)
    (tmp_path / "tool.stl").write_text(STL)
    model = quiet_load(urdf)
    shapes = {s.name: s for s in visuals(urdf, model)}
    assert sorted(shapes) == ["arm_0", "base_0", "tool_0", "tool_1"]
    base, arm, sphere, mesh = shapes["base_0"], shapes["arm_0"], shapes["tool_0"], shapes["tool_1"]
    assert (base.kind, base.size, base.body) == ("box", (0.4, 0.3, 0.1), -1)  # the root is welded to the world
    np.testing.assert_array_equal(base.rgba, [1, 0, 0, 1])  # by name, from the robot-level material
    np.testing.assert_array_equal(arm.rgba, [0, 0.5, 1, 0.5])
    assert (arm.kind, arm.size, arm.body) == ("cylinder", (0.03, 0.5), 0)
    assert sphere.rgba is None and sphere.body == 0 and mesh.body == 0  # the tool merged into the arm
    weld = rd.builder.rpy_to_matrix([0.2, 0, 0])
    np.testing.assert_allclose(sphere.pose[:3, :3], weld)
    np.testing.assert_allclose(sphere.pose[:3, 3], [0, 0, 0.5])
    np.testing.assert_allclose(mesh.pose[:3, 3], [0, 0, 0.5] + weld @ [0.01, 0, 0])
    assert mesh.mesh == tmp_path / "tool.stl" and list(mesh.scale) == [2, 2, -1]
    m = shape_mesh(mesh)  # scaled, and a mirror keeps the faces outward
    np.testing.assert_allclose(m.vertices.max(0), [0.02, 0.02, 0])
    assert list(m.faces[0]) == [2, 1, 0]
    # the world pose of each geometry frame at q: body pose times the record's pose
    q = np.array([0.7])
    T = visual_poses(model, list(shapes.values()), q)
    body = rd.forward_kinematics(model, q)[0]
    np.testing.assert_allclose(T[1], body @ arm.pose)
    np.testing.assert_allclose(T[0], base.pose)  # fixed to the world


def test_bad_visuals_warn_naming_the_link_and_are_skipped(tmp_path):
    bad = URDF.replace('<sphere radius="0.04"/>', '<capsule radius="0.04" length="1"/>').replace(
        '<box size="0.4 0.3 0.1"/>', '<box size="0.4 nan 0.1"/>')
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(bad)  # tool.stl is missing too
    model = quiet_load(urdf.read_text().replace("nan", "0.3"))
    with pytest.warns(RobodynWarning) as record:
        shapes = visuals(urdf, model)
    messages = [str(w.message) for w in record]
    assert any("unknown geometry <capsule>" in m and "'tool'" in m for m in messages), messages
    assert any("not finite" in m and "'base'" in m for m in messages), messages
    assert any("tool.stl" in m and "'tool'" in m and "not found" in m for m in messages), messages
    assert [s.name for s in shapes] == ["arm_0"]
    with pytest.warns(RobodynWarning, match="link 'nowhere' is not in the model"):
        assert visuals(URDF.replace('<link name="tool">', '<link name="nowhere">'), model)
    out = rd.viewer.render(model, [0.3], tmp_path / "bad.png", visuals=shapes, size=(200, 150))
    assert pixels(out).shape == (150, 200, 3)


def test_unreadable_mesh_file_is_skipped_with_a_warning(tmp_path):
    (tmp_path / "tool.stl").write_bytes(b"solid broken\n\x00\x01garbage")
    urdf = tmp_path / "shapes.urdf"
    urdf.write_text(URDF)
    model = quiet_load(urdf)
    with pytest.warns(RobodynWarning, match=r"tool\.stl of link 'tool' cannot be read"):
        drawn = parts(model, urdf)
    assert sorted(p.name for p in drawn) == ["arm_0", "base_0", "tool_0"]


def test_visuals_keep_the_hardened_xml_reader():
    entity = '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY e "x">]><robot name="r"><link name="a"/></robot>'
    with pytest.raises(ModelError, match="forbidden XML construct"):
        rd.io.urdf.read_visuals(entity)
    deep = "<robot name='r'>" + "<a>" * 100 + "</a>" * 100 + "</robot>"
    with pytest.raises(ModelError, match="nested deeper"):
        rd.io.urdf.read_visuals(deep)


@pytest.mark.parametrize("kind, size, volume", [
    ("box", (0.4, 0.3, 0.1), 0.4 * 0.3 * 0.1),
    ("cylinder", (0.1, 0.5), np.pi * 0.1 ** 2 * 0.5),
    ("sphere", (0.2,), 4 / 3 * np.pi * 0.2 ** 3),
    ("capsule", (0.1, 0.3), np.pi * 0.1 ** 2 * 0.3 + 4 / 3 * np.pi * 0.1 ** 3),
    ("ellipsoid", (0.1, 0.2, 0.3), 4 / 3 * np.pi * 0.1 * 0.2 * 0.3),
])
def test_primitives_are_closed_outward_surfaces(kind, size, volume):
    """Volume by the divergence theorem (sum of signed tetrahedra): positive (faces wound
    outward), and the solid's to within the tessellation's error."""
    m = shape_mesh(VisualShape("x", "x", -1, np.eye(4), kind, size, None, np.ones(3), None), resolution=64)
    tri = m.vertices[m.faces]
    signed = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    np.testing.assert_allclose(signed, volume, rtol=0.01 if kind != "box" else 1e-12)
    edges = np.sort(np.concatenate([m.faces[:, [0, 1]], m.faces[:, [1, 2]], m.faces[:, [2, 0]]]), axis=1)
    key = edges[:, 0] * len(m.vertices) + edges[:, 1]
    if kind == "box":  # each edge shared by two triangles: closed (no hole, no crack)
        assert np.all(np.unique(key, return_counts=True)[1] == 2)
    assert m.colors.shape == (len(m.faces), 4)


def test_decimation_keeps_the_budget_the_shape_and_the_colours():
    fine = shape_mesh(VisualShape("s", "s", -1, np.eye(4), "sphere", (1.0,), None, np.ones(3), None), resolution=200)
    colors = np.where((fine.vertices[fine.faces].mean(1)[:, 2] > 0)[:, None], [1.0, 0, 0, 1], [0, 0, 1.0, 1])
    coarse = decimate(Mesh(fine.vertices, fine.faces, colors), 2000)
    assert len(fine.faces) > 30000 and 500 < len(coarse.faces) <= 2000
    np.testing.assert_allclose(np.linalg.norm(coarse.vertices, axis=1)[np.unique(coarse.faces)], 1, atol=0.05)
    height = coarse.vertices[coarse.faces].mean(1)[:, 2]
    assert np.all(coarse.colors[height > 0.1, 0] == 1) and np.all(coarse.colors[height < -0.1, 2] == 1)
    assert decimate(coarse, 10**6) is coarse


def empty_render(model, q, camera, size):
    """The same view with nothing on it (the ground only)."""
    painter = Painter(model, [], playback(model, q), camera, size)
    painter.draw(0)
    return painter.image()


def test_render_png_of_a_urdf_robot(tmp_path):
    path, model = load("panda")
    q = np.array([0.3, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8, 0.02, 0.02])
    camera = Camera(azimuth=30, elevation=20, distance=1.6, target=(0.2, 0.0, 0.45))
    out = rd.viewer.render(model, q, tmp_path / "panda.png", visuals=path, camera=camera, size=(400, 300),
                           max_faces=6000)
    image = pixels(out)
    assert image.shape == (300, 400, 3)
    empty = empty_render(model, q, camera, (400, 300))
    robot = np.abs(image - empty).sum(-1) > 30
    assert 0.03 < robot.mean() < 0.6  # the robot covers part of the picture
    rows, cols = np.nonzero(robot)
    assert 50 < cols.mean() < 350 and 30 < rows.mean() < 270  # around the middle
    assert image[robot].mean() < 250  # shaded, not blank


def test_camera_azimuth_convention(tmp_path):
    """A red ball at +x and a blue one at -x: seen from +y (azimuth 90) red is on the left,
    from -y (azimuth -90) on the right; the eye is where Camera.eye says."""
    model = rd.models.load("pendulum")
    balls = [VisualShape(n, "world", -1, rd.viewer.geometry.homogeneous(np.eye(3), [x, 0, 0.5]), "sphere", (0.2,),
                         None, np.ones(3), np.array(c)) for n, x, c in
             (("red", 1.0, (1, 0, 0, 1)), ("blue", -1.0, (0, 0, 1, 1)))]
    sides = {}
    for azimuth in (90, -90):
        img = pixels(rd.viewer.render(model, None, tmp_path / f"{azimuth}.png", visuals=balls, size=(300, 200),
                                      camera={"azimuth": azimuth, "elevation": 10}))
        red = (img[..., 0] > 120) & (img[..., 1] < 80) & (img[..., 2] < 80)
        blue = (img[..., 2] > 120) & (img[..., 0] < 80) & (img[..., 1] < 80)
        assert red.sum() > 100 and blue.sum() > 100
        sides[azimuth] = np.nonzero(red)[1].mean() < np.nonzero(blue)[1].mean()
    assert sides == {90: True, -90: False}
    cam = Camera(azimuth=90, elevation=0).fitted([-1, -1, 0], [1, 1, 1])
    np.testing.assert_allclose(cam.eye() - cam.target, [0, cam.distance, 0], atol=1e-12)
    with pytest.raises(ValueError, match="unknown fields"):
        Camera.of({"zoom": 2})


def test_a_robot_without_meshes_is_a_capsule_skeleton(tmp_path):
    model = rd.models.load("panda")  # built from DH parameters: no geometry
    shapes = skeleton(model)
    joints = [s for s in shapes if s.kind == "sphere"]
    assert len(joints) == model.nbodies and {s.kind for s in shapes} == {"sphere", "capsule"}
    q = rd.random.random_configuration(model, np.random.default_rng(1))
    T = rd.forward_kinematics(model, q)
    np.testing.assert_allclose(visual_poses(model, joints, q)[:, :3, 3], T[:, :3, 3], atol=1e-12)
    for s, pose in zip(shapes, visual_poses(model, shapes, q)):  # each capsule joins a joint to a child's joint
        if s.kind == "capsule" and s.body >= 0:
            ends = pose[:3, 3] + np.outer([-0.5, 0.5], pose[:3, 2] * s.size[1])
            children = [i for i in range(model.nbodies) if model.parent[i] == s.body]
            assert np.allclose(ends[0], T[s.body, :3, 3])
            assert any(np.allclose(ends[1], T[c, :3, 3]) for c in children) or not children
    camera = Camera(distance=3.0, target=(0, 0, 0.5))
    image = pixels(rd.viewer.render(model, q, tmp_path / "skeleton.png", camera=camera, size=(300, 300)))
    assert (np.abs(image - empty_render(model, q, camera, (300, 300))).sum(-1) > 30).mean() > 0.01
    orange = (image[..., 0] > 180) & (image[..., 1] > 80) & (image[..., 1] < 170) & (image[..., 2] < 90)
    assert orange.sum() > 20  # the joints


def test_render_video_gif_has_one_frame_per_period(tmp_path):
    model = rd.models.load("double_pendulum")
    t = np.linspace(0.0, 1.0, 101)
    q = np.column_stack([np.sin(3 * t), np.cos(2 * t)])
    log = tmp_path / "swing.csv"
    write_log(log, model, t, q)
    out = tmp_path / "swing.gif"
    assert rd.viewer.render_video(model, log, out, fps=8, size=(160, 120)) == 9
    with Image.open(out) as gif:
        assert gif.n_frames == 9 and gif.size == (160, 120)
        first = np.asarray(gif.convert("RGB"), dtype=int)
        gif.seek(8)
        last = np.asarray(gif.convert("RGB"), dtype=int)
    assert (np.abs(first - last).sum(-1) > 30).mean() > 0.005  # the pendulum moved
    np.testing.assert_array_equal(frame_samples(t, 8), np.searchsorted(t, np.arange(9) / 8 + 1e-12, "right") - 1)
    np.testing.assert_array_equal(frame_samples(np.array([0.0, 0.5]), 4), [0, 0, 1])


def test_render_video_mp4_has_the_frames_of_the_gif(tmp_path):
    """The MP4 (the system's ffmpeg or imageio-ffmpeg's, a test dependency) decodes to the
    GIF's frame count, size and rate, each frame the GIF's picture of the same time (up to the
    video's lossy coding)."""
    import imageio_ffmpeg

    model = rd.models.load("double_pendulum")
    t = np.linspace(0.0, 1.0, 101)
    log = tmp_path / "swing.csv"
    write_log(log, model, t, np.column_stack([np.sin(3 * t), np.cos(2 * t)]))
    n = rd.viewer.render_video(model, log, tmp_path / "swing.mp4", fps=8, size=(160, 120))
    assert n == rd.viewer.render_video(model, log, tmp_path / "swing.gif", fps=8, size=(160, 120)) == 9
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "swing.mp4"))
    meta = next(reader)
    assert tuple(meta["size"]) == (160, 120) and meta["fps"] == 8
    frames = [np.frombuffer(f, np.uint8).reshape(120, 160, 3).astype(int) for f in reader]
    assert len(frames) == 9
    pictures = []
    with Image.open(tmp_path / "swing.gif") as gif:
        for j in range(9):
            gif.seek(j)
            pictures.append(np.asarray(gif.convert("RGB"), dtype=int))
    assert (np.abs(pictures[0] - pictures[8]).sum(-1) > 30).mean() > 0.005  # the pendulum moved
    for j, frame in enumerate(frames):  # each frame the GIF's picture of the same time, no other
        distance = [np.abs(frame - p).mean() for p in pictures]
        assert np.argmin(distance) == j and distance[j] < 3, (j, distance)


def test_mp4_without_ffmpeg_is_a_clear_error_before_any_work(tmp_path, monkeypatch):
    from matplotlib.animation import FFMpegWriter

    monkeypatch.setattr(FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # neither ffmpeg: import fails
    model = rd.models.load("pendulum")
    with pytest.raises(ValueError, match="ffmpeg"):
        rd.viewer.render_video(model, "never-read.csv", tmp_path / "x.mp4")
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        rd.viewer.render_video(model, "never-read.csv", tmp_path / "x.avi")
    assert list(tmp_path.iterdir()) == []


FOOT = """<robot name="hopper">
  <link name="body"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
  <link name="foot"/>
  <joint name="ankle" type="fixed"><parent link="body"/><child link="foot"/><origin xyz="0 0 -0.3"/></joint>
</robot>"""


def test_contact_points_by_name_and_from_the_contacts(recwarn):
    model = rd.load_urdf(FOOT, floating_base=True)
    N = 3
    q = np.tile([0, 0, 0.5, 0, 0, 0, 1.0], (N, 1))
    q[:, 0] = [0.0, 0.1, 0.2]
    names = ("foot:sphere@ground", "mystery@ground")
    force = np.zeros((N, 2, 3))
    force[1:, 0, 2] = 19.62
    normal = np.broadcast_to([0, 0, 1.0], (N, 2, 3))
    traj = rd.Trajectory(model=model, t=np.arange(N) * 0.1, q=q, v=np.zeros((N, 6)), a=np.zeros((N, 6)),
                         tau=np.zeros((N, 6)), kinetic=np.zeros(N), potential=np.zeros(N), energy=np.zeros(N),
                         contact_names=names, contact_force=force, contact_normal=normal,
                         contact_distance=np.zeros((N, 2)), contact_friction=np.ones(2))
    with pytest.warns(RobodynWarning, match="mystery@ground"):
        play = playback(model, trajectory=traj)
    assert play.contact_names == ("foot:sphere@ground",)
    foot = np.column_stack([[0, 0.1, 0.2], np.zeros(N), np.full(N, 0.2)])  # 0.3 m below the body
    np.testing.assert_allclose(play.contact_points[:, 0], foot)
    seg = play.force_segments(1, play.force_scale(model, 1.0), 10.0)
    np.testing.assert_allclose(seg, [[[0.1, 0, 0.2], [0.1, 0, 0.7]]])  # the weight: half the size (1 m)
    assert play.force_segments(0, 1.0, 1.0).shape == (0, 2, 3)  # no force, no segment
    contacts = rd.contact.Contacts([rd.contact.Sphere("foot", 0.05, name="foot:sphere"),
                                    rd.contact.Point("body", (0.1, 0, 0), name="mystery")])
    play = playback(model, trajectory=traj, contacts=contacts)
    np.testing.assert_allclose(play.contact_points[2], [[0.2, 0, 0.15], [0.3, 0, 0.5]])


def test_importing_robodyn_imports_no_viewer_package():
    code = ("import sys, robodyn as rd; assert 'viser' not in sys.modules and 'trimesh' not in sys.modules;"
            "rd.viewer.render; assert 'viser' not in sys.modules and 'trimesh' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_without_the_extra_show_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "viser", None)
    with pytest.raises(ImportError, match=r'pip install "robodyn\[viewer\]"'):
        rd.viewer.show(rd.models.load("pendulum"), block=False)


def test_cli_view_renders_and_serves(tmp_path, capsys, monkeypatch):
    path, _ = load("ur5")
    png = tmp_path / "ur5.png"
    with pytest.warns(RobodynWarning, match="gazebo"):  # the loader's word on what has no dynamics
        assert main(["view", str(path), "--png", str(png)]) == 0
    assert pixels(png).shape == (600, 800, 3) and f"wrote {png}" in capsys.readouterr().out
    model = rd.models.load("double_pendulum")
    log = tmp_path / "run.csv"
    write_log(log, model, np.linspace(0, 0.5, 11), np.zeros((11, 2)))
    gif = tmp_path / "run.gif"
    assert main(["view", "double_pendulum", "--trajectory", str(log), "--video", str(gif), "--fps", "10"]) == 0
    assert "(6 frames at 10 fps)" in capsys.readouterr().out and Image.open(gif).n_frames == 6
    seen = {}
    monkeypatch.setattr(rd.viewer, "show", lambda model, **kw: seen.update(kw, model=model))
    assert main(["view", "double_pendulum", "--trajectory", str(log), "--port", "0", "--frames", "--com"]) == 0
    assert seen["port"] == 0 and seen["frames"] and seen["com"] and seen["block"] and seen["visuals"] is None
    assert seen["model"].name == "double_pendulum" and len(seen["trajectory"].t) == 11
    assert main(["view", "double_pendulum", "--port", "70000"]) == 2
    assert "--port 70000" in capsys.readouterr().err


def test_cli_view_of_an_example_robot_by_name(tmp_path, capsys):
    """``robodyn view solo12 --floating-base --trajectory run.csv`` (example-robot-data's URDF
    found by name): a rendered standing pose and a trajectory of it, meshes drawn."""
    from robodyn.models import example_robot_urdf

    assert example_robot_urdf("solo12") == ERD / "solo_description/robots/solo12.urdf"
    assert example_robot_urdf("no_such_robot") is None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        model = rd.load_urdf(example_robot_urdf("solo12"), floating_base=True)
    q = np.tile(np.r_[0, 0, 0.3, 0, 0, 0, 1, np.zeros(12)], (5, 1))
    q[:, 7::3] = np.linspace(0, 0.5, 5)[:, None]  # the hip abduction joints open
    log = tmp_path / "run.csv"
    write_log(log, model, np.linspace(0, 0.4, 5), q)
    png, gif = tmp_path / "solo12.png", tmp_path / "solo12.gif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        assert main(["view", "solo12", "--floating-base", "--png", str(png)]) == 0
        assert main(["view", "solo12", "--floating-base", "--trajectory", str(log), "--video", str(gif),
                     "--fps", "10"]) == 0
    image = pixels(png)
    assert (image.std(axis=2) < 10).mean() > 0.2 and image.min() < 120  # grey meshes drawn on the white scene
    assert Image.open(gif).n_frames == 5
    assert main(["view", "solo13"]) == 2
    assert "example-robot-data" in capsys.readouterr().err


def test_cli_view_of_an_mjcf_file_draws_its_geoms(tmp_path, monkeypatch):
    """``robodyn view ant.xml``: the geoms of the file (gymnasium's ant: capsules and a sphere
    of rgba 0.8 0.6 0.4), not the capsule skeleton, in the render and in the browser."""
    import gymnasium

    from robodyn.viewer import mjcf_visuals

    path = Path(gymnasium.__file__).parent / "envs/mujoco/assets/ant.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        model = rd.load_mjcf(path)
        expected = mjcf_visuals(path, model)
        png = tmp_path / "ant.png"
        assert main(["view", str(path), "--png", str(png)]) == 0
        seen = {}
        monkeypatch.setattr(rd.viewer, "show", lambda model, **kw: seen.update(kw))
        assert main(["view", str(path), "--port", "0"]) == 0
    assert [v.name for v in seen["visuals"]] == [v.name for v in expected] and len(expected) == 13
    assert {v.kind for v in expected} == {"sphere", "capsule"}
    image = pixels(png)
    tan = np.abs(image - np.array([0.8, 0.6, 0.4]) * 255).max(axis=2) < 30  # the file's colour, shaded
    assert tan.mean() > 0.01  # the skeleton (grey-blue, orange joints) has 0.03 % such pixels


def _msh(vertices, faces, normals=0, texcoords=0) -> bytes:
    v, f = np.asarray(vertices, "<f4"), np.asarray(faces, "<i4")
    head = np.array([len(v), normals, texcoords, len(f)], "<i4")
    return head.tobytes() + v.tobytes() + np.zeros(3 * normals + 2 * texcoords, "<f4").tobytes() + f.tobytes()


def test_mujoco_msh_meshes_are_read_and_bad_ones_refused(tmp_path):
    """MuJoCo's binary ``.msh``: the vertices and faces it holds (after its normals and texture
    coordinates); a size that does not match the header, an index out of range or no faces is
    a ValueError naming the fault (a drawn shape: a warning, not drawn)."""
    from robodyn.viewer.geometry import load_msh

    V = [[0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]]
    F = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    good = tmp_path / "tet.msh"
    good.write_bytes(_msh(V, F, normals=4, texcoords=4))
    mesh = load_mesh_file(good)
    np.testing.assert_array_equal(mesh.vertices, V)
    np.testing.assert_array_equal(mesh.faces, F)
    assert mesh.colors.shape == (4, 4)
    for data, message in ((good.read_bytes()[:-4], "do not hold"), (b"\x01\x00", "16-byte header"),
                          (_msh(V, [[0, 1, 4]]), "outside the 4 vertices"), (_msh(V, np.zeros((0, 3))), "no triangles"),
                          (np.array([-1, 0, 0, 0], "<i4").tobytes(), "do not hold")):
        bad = tmp_path / "bad.msh"
        bad.write_bytes(data)
        with pytest.raises(ValueError, match=message):
            load_msh(bad)
    shape = VisualShape("m", "world", -1, np.eye(4), "mesh", (), bad, np.ones(3), None)
    with pytest.warns(RobodynWarning, match="bad.msh .*cannot be read"):
        assert shape_mesh(shape) is None


def test_cli_view_draws_msh_meshes_without_trimesh(tmp_path, capsys, monkeypatch):
    """MuJoCo's ``.msh`` is read here: ``robodyn view`` needs trimesh only for other meshes."""
    monkeypatch.setitem(sys.modules, "trimesh", None)
    (tmp_path / "tet.msh").write_bytes(_msh([[0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]],
                                            [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]))
    (tmp_path / "tet.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 3\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")
    xml = ('<mujoco><asset><mesh file="tet.{}"/></asset><worldbody><body name="b"><joint/>'
           '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/><geom type="mesh" mesh="tet"/></body></worldbody></mujoco>')
    path, png = tmp_path / "tet.xml", tmp_path / "tet.png"
    path.write_text(xml.format("msh"))
    assert main(["view", str(path), "--png", str(png)]) == 0 and pixels(png).shape == (600, 800, 3)
    path.write_text(xml.format("obj"))
    assert main(["view", str(path), "--png", str(png)]) == 2
    assert 'robodyn view needs trimesh: pip install "robodyn[viewer]"' in capsys.readouterr().err


def test_a_urdf_saved_as_xml_is_read_as_a_urdf(tmp_path):
    """The first element decides: a ``.xml`` file holding ``<robot>`` is a URDF."""
    from robodyn.viewer.geometry import is_mjcf

    path = tmp_path / "robot.xml"
    path.write_text('<?xml version="1.0"?><!-- <mujoco> --><robot name="r"><link name="a"><visual><geometry>'
                    '<box size="1 2 3"/></geometry></visual></link></robot>')
    assert not is_mjcf(path) and is_mjcf("<mujoco/>") and not is_mjcf("x.urdf")
    [shape] = visuals(path, quiet_load(path))
    assert shape.kind == "box" and shape.size == (1.0, 2.0, 3.0)
