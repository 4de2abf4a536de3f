"""Tests of freefloat.app.viz: the self-contained meshcat page and the run figures."""

from __future__ import annotations

import importlib.metadata
import re
import warnings
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from freefloat.app.viz import frame_indices, write_figures, write_trajectory_html
from freefloat.app.viz.camera import ASPECT, FIELD_OF_VIEW
from freefloat.app.viz.figures import (
    APPROACH_TITLE,
    END_COLOR,
    arm_name,
    base_trajectory_figure,
    com_drift_figure,
    end_effector_paths_figure,
    joint_error_figure,
    skeleton,
    torque_figure,
    write_approach_figure,
)
from freefloat.app.viz.meshcat_html import quaternions
from freefloat.app.viz.meshcat_html import read_settings as _settings
from freefloat.dynamics.metrics import free_com_motion, summarize
from freefloat.dynamics.telemetry import Telemetry
from freefloat.robot.loading import load_robot

from .conftest import SPART
from .pages import animation as _animation
from .pages import assets as _assets
from .pages import objects as _objects
from .pages import packets as _packets

SPART_URDF = SPART / "urdf"

SHARE = Path(
    str(importlib.metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share"))
)
UR5 = SHARE / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
ROOT = "/meshcat/freefloat"


def _load(path: Path, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(path, **kwargs)


@pytest.fixture(scope="module")
def sc3():
    return _load(SPART_URDF / "SC_3DoF.urdf")


@pytest.fixture(scope="module")
def sc3_stick():
    return _load(SPART_URDF / "SC_3DoF.urdf", visuals=False)


@pytest.fixture(scope="module")
def iiwa2():
    return _load(SPART_URDF / "2_iiwa_base.urdf")


@pytest.fixture(scope="module")
def ur5(tmp_path_factory):
    """UR5 with its meshes, its massless ``world`` root link and joint removed."""
    tree = ET.parse(UR5)
    root = tree.getroot()
    for element in list(root):
        if (element.tag == "link" and element.get("name") == "world") or (
            element.tag == "joint" and element.find("parent").get("link") == "world"
        ):
            root.remove(element)
    path = tmp_path_factory.mktemp("ur5") / "ur5_free.urdf"
    tree.write(path)
    return _load(path)


def _configurations(model: pin.Model, n: int, seed: int = 0) -> np.ndarray:
    """n configurations: neutral perturbed, base translated and rotated (unit quaternions)."""
    rng = np.random.default_rng(seed)
    q = np.tile(pin.neutral(model), (n, 1))
    q[:, :3] = rng.normal(size=(n, 3))
    quaternions = rng.normal(size=(n, 4))
    q[:, 3:7] = quaternions / np.linalg.norm(quaternions, axis=1, keepdims=True)
    q[:, 7:] += rng.uniform(-2.0, 2.0, size=(n, model.nq - 7))
    return q


def _node_pose(tracks: dict[str, list], frame: int) -> np.ndarray:
    """Homogeneous pose (4, 4) of an animated node at a key frame."""
    pose = np.eye(4)
    pose[:3, 3] = tracks[".position"][frame][1]
    pose[:3, :3] = pin.Quaternion(np.array(tracks[".quaternion"][frame][1])).matrix()
    return pose


def _intrinsic(lowered: dict) -> np.ndarray:
    """The object's intrinsic matrix (three.js stores it column-major)."""
    return np.array(lowered["object"]["matrix"]).reshape(4, 4).T


class _Tags(HTMLParser):
    """Collects (tag, attributes) of every start tag (script contents are not parsed as HTML)."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: list[tuple[str, list]] = []

    def handle_starttag(self, tag: str, attrs: list) -> None:
        self.seen.append((tag, attrs))


def _run(robot, n=201, duration=2.0, seed=0):
    return np.linspace(0.0, duration, n), _configurations(robot.model, n, seed)


def test_page_makes_no_network_reference(sc3, tmp_path):
    """The page loads no script or resource by URL; its only URL is an XML namespace in the JS."""
    t, q = _run(sc3)
    page = write_trajectory_html(sc3, t, q, tmp_path / "run.html").read_text()
    tags = _Tags()
    tags.feed(page)
    assert {tag for tag, _ in tags.seen} == {
        "html", "head", "meta", "title", "style", "body", "div", "script", "button", "input", "datalist", "span",
    }
    assert not [
        name for _, attrs in tags.seen for name, _ in attrs if name in ("src", "href", "srcset")
    ]
    assert set(re.findall(r"https?://[^\s\"'<>)]*", page)) <= {"http://www.w3.org/1999/xhtml"}
    assert "new MeshCat.Viewer" in page and len(_packets(tmp_path / "run.html")) > 1


def test_animation_frames_follow_fps(sc3, tmp_path):
    """At 10 fps a 2 s run sampled every 10 ms animates every 10th sample, keyed 0..20 frames."""
    t, q = _run(sc3)
    tracks = _animation(_packets(write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0)))
    base = tracks[f"{ROOT}/base"]
    times = np.array([time for time, _ in base[".position"]])
    np.testing.assert_allclose(times, np.arange(21), atol=1e-9)
    np.testing.assert_allclose([v for _, v in base[".position"]], q[::10, :3], atol=1e-12)


def test_frame_indices_pick_nearest_samples():
    """Uneven samples are picked nearest to each 1/fps tick, and sparse samples are all kept."""
    np.testing.assert_array_equal(
        frame_indices(np.array([0.0, 0.01, 0.3, 0.31, 1.0]), 2.0), [0, 3, 4]
    )
    np.testing.assert_array_equal(frame_indices(np.array([0.0, 0.5, 1.0]), 30.0), [0, 1, 2])


def test_joint_poses_match_forward_kinematics(sc3, tmp_path):
    """Each animated joint pose equals Pinocchio's oMi for the shown configuration; the base
    pose equals the free-flyer coordinates of q."""
    t, q = _run(sc3)
    tracks = _animation(_packets(write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0)))
    model, data = sc3.model, sc3.model.createData()
    for frame in (3, 17):
        sample = 10 * frame
        base = _node_pose(tracks[f"{ROOT}/base"], frame)
        np.testing.assert_allclose(base[:3, 3], q[sample, :3], atol=1e-12)
        np.testing.assert_allclose(
            base[:3, :3], pin.Quaternion(q[sample, 3:7]).matrix(), atol=1e-12
        )
        pin.forwardKinematics(model, data, q[sample])
        for j in range(2, model.njoints):
            pose = _node_pose(tracks[f"{ROOT}/{model.names[j]}"], frame)
            np.testing.assert_allclose(pose, data.oMi[j].homogeneous, atol=1e-12)


def test_primitive_geometry_placed_like_pinocchio(sc3, tmp_path):
    """SC_3DoF's boxes, spheres and cylinders sit where updateGeometryPlacements puts them
    (cylinders along the geometry's z axis)."""
    t, q = _run(sc3)
    packets = _packets(write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0))
    tracks, objects = _animation(packets), _objects(packets)
    model, data = sc3.model, sc3.model.createData()
    visual, visual_data = sc3.visual_model, pin.GeometryData(sc3.visual_model)
    pin.forwardKinematics(model, data, q[50])
    pin.updateGeometryPlacements(model, data, visual, visual_data)
    assert len([n for n in objects if n.startswith(ROOT) and n.split("/")[3] not in ("markers", "paths")]) == visual.ngeoms
    for g, g_id in ((g, visual.getGeometryId(g.name)) for g in visual.geometryObjects):
        node = f"{ROOT}/{model.names[g.parentJoint]}"
        world = _node_pose(tracks[node], 5) @ _intrinsic(objects[f"{node}/{g.name}"])
        expected = visual_data.oMg[g_id].homogeneous
        np.testing.assert_allclose(world[:3, 3], expected[:3, 3], atol=1e-12)
        if type(g.geometry).__name__ == "Cylinder":
            assert abs(world[:3, 1] @ expected[:3, 2]) == pytest.approx(1.0, abs=1e-12)
        else:
            np.testing.assert_allclose(world[:3, :3], expected[:3, :3], atol=1e-12)


def test_primitives_are_lowered_as_pinocchio_s_meshcat_visualizer_lowers_them(sc3):
    """Boxes, spheres and cylinders become the meshcat geometry (and intrinsic rotation) that
    Pinocchio's ``loadPrimitive`` makes, without importing ``pinocchio.visualize`` (viser, trimesh)."""
    from pinocchio.visualize.meshcat_visualizer import loadPrimitive

    from freefloat.app.viz.meshcat_html import _primitive

    kinds = set()
    for geometry in sc3.visual_model.geometryObjects:
        ours, theirs = _primitive(geometry), loadPrimitive(geometry)
        kinds.add(type(geometry.geometry).__name__)
        assert {**ours.lower(None), "uuid": 0} == {**theirs.lower(None), "uuid": 0}, geometry.name
        np.testing.assert_array_equal(ours.intrinsic_transform(), theirs.intrinsic_transform())
    assert kinds == {"Box", "Sphere", "Cylinder"}


def test_stick_figure_links_join_joints_and_end_effector(sc3_stick, tmp_path):
    """Without visuals, each link cylinder runs from a joint origin to its child joint or
    end-effector frame origin as placed by forward kinematics; the base box sits at the base CoM."""
    assert sc3_stick.visual_model is None
    t, q = _run(sc3_stick)
    packets = _packets(write_trajectory_html(sc3_stick, t, q, tmp_path / "run.html", fps=10.0))
    tracks, objects = _animation(packets), _objects(packets)
    model, data = sc3_stick.model, sc3_stick.model.createData()
    pin.framesForwardKinematics(model, data, q[70])
    ee = model.getFrameId(sc3_stick.end_effectors[0])
    segments = [
        (model.parents[j], f"link_to_{model.names[j]}", data.oMi[j].translation)
        for j in range(2, model.njoints)
    ]
    segments.append(
        (
            model.frames[ee].parentJoint,
            f"link_to_{sc3_stick.end_effectors[0]}",
            data.oMf[ee].translation,
        )
    )
    for parent, name, end in segments:
        node = f"{ROOT}/{model.names[parent]}"
        lowered = objects[f"{node}/{name}"]
        assert lowered["geometries"][0]["type"] == "CylinderGeometry"
        half = lowered["geometries"][0]["height"] / 2
        world = _node_pose(tracks[node], 7) @ _intrinsic(lowered)
        np.testing.assert_allclose(
            world @ [0.0, -half, 0.0, 1.0], [*data.oMi[parent].translation, 1.0], atol=1e-12
        )
        np.testing.assert_allclose(world @ [0.0, half, 0.0, 1.0], [*end, 1.0], atol=1e-12)
    box = _node_pose(tracks[f"{ROOT}/base"], 7) @ _intrinsic(objects[f"{ROOT}/base/base_box"])
    np.testing.assert_allclose(box[:3, 3], data.oMi[1].act(model.inertias[1].lever), atol=1e-12)


@pytest.mark.slow
def test_mesh_files_are_embedded(ur5, tmp_path):
    """UR5's Collada meshes are embedded verbatim, one object per visual geometry naming its
    file's entry, with no external texture."""
    t, q = _run(ur5, n=11, duration=1.0)
    page = write_trajectory_html(ur5, t, q, tmp_path / "ur5.html")
    files, objects = _assets(page), _objects(page)
    assert len(objects) >= ur5.visual_model.ngeoms
    for g in ur5.visual_model.geometryObjects:
        lowered = objects[f"{ROOT}/{ur5.model.names[g.parentJoint]}/{g.name}"]["object"]
        assert lowered["type"] == "_meshfile_object" and lowered["format"] == "dae"
        assert files[int(lowered["data"].removeprefix("freefloat-asset:"))] == Path(g.meshPath).read_bytes()
        assert lowered["resources"] == {}


@pytest.mark.slow
def test_a_missing_mesh_leaves_the_other_meshes_and_a_stick_for_its_link(ur5, tmp_path):
    """UR5 with wrist2's mesh file missing: the page draws every other link's mesh, and on
    wrist2's joint the stick figure's pieces (its sphere, its link to the next joint); no other
    joint gets any."""
    path = tmp_path / "ur5_no_wrist2.urdf"
    path.write_text(ur5.urdf_path.read_text().replace("visual/wrist2.dae", "visual/wrist2_gone.dae"))
    robot = _load(path)
    t, q = _run(robot, n=11, duration=1.0)
    objects = _objects(write_trajectory_html(robot, t, q, tmp_path / "ur5.html"))
    meshes = {n for n, o in objects.items() if o["object"]["type"] == "_meshfile_object"}
    assert len(meshes) == ur5.visual_model.ngeoms - 1 and not any("wrist2" in n for n in meshes)
    wrist2 = robot.model.frames[robot.model.getFrameId("wrist_2_link")].parentJoint
    sticks = {n for n in objects if n.startswith(ROOT) and n.split("/")[3] not in ("markers", "paths")} - meshes
    assert sticks and {n.split("/")[3] for n in sticks} == {robot.model.names[wrist2]}
    assert f"{ROOT}/{robot.model.names[wrist2]}/joint_sphere" in sticks


@pytest.mark.slow
def test_each_mesh_file_is_embedded_once(tmp_path):
    """The dual-arm satellite uses each UR5 mesh twice but embeds it once; its page stays under 5 MB."""
    robot = _load(Path(__file__).resolve().parents[1] / "urdf" / "dual_arm_satellite.urdf")
    meshes = [g.meshPath for g in robot.visual_model.geometryObjects if g.meshPath.endswith(".dae")]
    assert len(meshes) > len(set(meshes))
    t, q = _run(robot, n=11, duration=1.0)
    page = write_trajectory_html(robot, t, q, tmp_path / "satellite.html")
    assert sorted(_assets(page)) == sorted(Path(m).read_bytes() for m in set(meshes))
    assert page.stat().st_size < 5e6


def test_animation_loops(sc3, tmp_path):
    """The animation starts playing and repeats without end."""
    t, q = _run(sc3)
    (animation,) = [p for p in _packets(write_trajectory_html(sc3, t, q, tmp_path / "run.html"))
                    if p["type"] == "set_animation"]
    assert animation["options"]["play"] is True and animation["options"]["repetitions"] == float("inf")


def test_events_and_clock_reach_the_page(sc3, tmp_path):
    """Named events, the start time and the duration are the page's settings."""
    t, q = _run(sc3)
    page = write_trajectory_html(sc3, t + 3.0, q, tmp_path / "run.html", events=[(4.25, "grasp")])
    assert _settings(page)["events"] == [[4.25, "grasp"]]
    assert _settings(page)["t0"] == 3.0 and _settings(page)["duration"] == pytest.approx(2.0)


def test_camera_sees_every_joint_at_every_frame(sc3, tmp_path):
    """Every joint origin of every shown frame lies inside the camera's view cone, in front of it."""
    t, q = _run(sc3)
    page = write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0)
    camera = _settings(page)["camera"]
    position, target = np.array(camera["position"]), np.array(camera["target"])
    axis = (target - position) / np.linalg.norm(target - position)
    data = sc3.model.createData()
    for k in range(0, len(t), 10):
        pin.forwardKinematics(sc3.model, data, q[k])
        for m in data.oMi[1:]:
            ray = m.translation - position
            assert np.arccos(ray @ axis / np.linalg.norm(ray)) < np.radians(75.0) / 2


def _grid_ends(page: Path) -> np.ndarray:
    """The ends of a page's grid lines (2 K, 3), inertial frame, m: its ``/Grid`` object, or
    meshcat's own grid (20 m wide, 40 cells, at z = 0) when the page leaves that in place."""
    grid = _objects(page).get("/Grid")
    if grid is None:
        ticks = np.linspace(-10.0, 10.0, 41)
        return np.array([[(x, -10.0, 0.0), (x, 10.0, 0.0)] for x in ticks]
                        + [[(-10.0, y, 0.0), (10.0, y, 0.0)] for y in ticks]).reshape(-1, 3)
    (geometry,) = grid["geometries"]
    return np.frombuffer(geometry["data"]["attributes"]["position"]["array"].data, np.float32).reshape(-1, 3)


def test_the_grid_lies_under_a_3d_motion_and_in_front_of_the_camera(sc3, tmp_path):
    """A robot tumbling in 3-D: the grid is one plane under every joint origin of every shown frame,
    under the camera's target, and every line's ends lie in front of the camera (lines crossing
    the camera's plane were dropped by the browser, leaving a few far ones above the robot)."""
    t, q = _run(sc3)
    page = write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0)
    camera = _settings(page)["camera"]
    position, target = np.array(camera["position"]), np.array(camera["target"])
    axis = (target - position) / np.linalg.norm(target - position)
    ends = _grid_ends(page)
    data = sc3.model.createData()
    shown = q[frame_indices(t, 10.0)]
    lowest = min(m.translation[2] for qk in shown for m in (pin.forwardKinematics(sc3.model, data, qk), data.oMi)[1][1:])
    assert np.ptp(ends[:, 2]) == 0.0 and ends[0, 2] <= lowest
    assert (ends[:, :2].min(axis=0) <= target[:2]).all() and (target[:2] <= ends[:, :2].max(axis=0)).all()
    assert ((ends - position) @ axis).min() > 0.04 * np.linalg.norm(target - position)


def test_camera_sees_every_corner_of_an_extra_box(sc3, tmp_path):
    """A box drawn beside the robot (a capture's target) is framed whole: its corners, not only its
    centre, are inside the picture (vertical field of view, and the narrowest aspect framed)."""
    t, q = _run(sc3)
    size = np.array([3.0, 2.0, 2.5])  # several times the robot
    poses = np.tile(np.eye(4), (len(t), 1, 1))
    poses[:, :3, 3] = [4.0, 0.0, 0.0]
    page = write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0,
                                 extra=[("target", mg.Mesh(mg.Box(size.tolist())), poses)])
    camera = _settings(page)["camera"]
    position, target = np.array(camera["position"]), np.array(camera["target"])
    axis = (target - position) / np.linalg.norm(target - position)
    right = np.cross(axis, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, axis)
    corners = poses[0, :3, 3] + size / 2 * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    rays = corners - position
    depth = rays @ axis
    assert np.all(np.abs(rays @ up) <= depth * np.tan(FIELD_OF_VIEW / 2))
    assert np.all(np.abs(rays @ right) <= depth * ASPECT * np.tan(FIELD_OF_VIEW / 2))


def test_markers_follow_robot_com_and_end_effectors(sc3, tmp_path):
    """By default the base CoM, the system CoM and each end-effector get an animated sphere at
    their positions and a drawn path."""
    t, q = _run(sc3)
    packets = _packets(write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0))
    tracks, objects = _animation(packets), _objects(packets)
    data = sc3.model.createData()
    names = ["base_com", "system_com"] + [f"end_effector_{e}" for e in sc3.end_effectors]
    for name in names:
        assert objects[f"{ROOT}/paths/{name}"]["object"]["type"] == "Line"
    com = pin.centerOfMass(sc3.model, data, q[40])
    np.testing.assert_allclose(_node_pose(tracks[f"{ROOT}/markers/system_com"], 4)[:3, 3], com, atol=1e-12)


def test_extra_body_follows_its_poses(sc3, tmp_path):
    """An extra body is drawn and animated with its own poses at the shown samples."""
    t, q = _run(sc3)
    rng = np.random.default_rng(1)
    poses = np.array(
        [pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous for _ in t]
    )
    extra = [("target", mg.Box([0.1, 0.2, 0.3]), poses)]
    packets = _packets(
        write_trajectory_html(sc3, t, q, tmp_path / "run.html", fps=10.0, extra=extra)
    )
    assert _objects(packets)[f"{ROOT}/extra/target"]["geometries"][0]["type"] == "BoxGeometry"
    tracks = _animation(packets)[f"{ROOT}/extra/target"]
    for frame in (0, 9, 20):
        np.testing.assert_allclose(_node_pose(tracks, frame), poses[10 * frame], atol=1e-12)


def test_configurations_of_wrong_size_are_rejected(sc3, tmp_path):
    """q whose width is not the model's nq raises ValueError naming the expected shape."""
    t, q = _run(sc3)
    with pytest.raises(ValueError, match=f"q \\(N, {sc3.model.nq}\\)"):
        write_trajectory_html(sc3, t, q[:, :-1], tmp_path / "run.html")


def _telemetry(robot, n: int = 40, references: bool = True) -> Telemetry:
    """Synthetic telemetry with smooth base attitude (yaw crossing pi) and random signals."""
    rng = np.random.default_rng(2)
    model = robot.model
    tel = Telemetry.allocate(n, model.nq, model.nv, robot.n_joints, len(robot.end_effectors))
    tel.t[:] = np.linspace(0.0, 4.0, n)
    tel.q[:] = _configurations(model, n)
    tel.joint_positions[:] = tel.q[:, 7:]
    if references:
        tel.joint_reference[:] = tel.joint_positions + rng.normal(
            scale=0.1, size=tel.joint_positions.shape
        )
    tel.tau[:] = rng.normal(size=tel.tau.shape)
    tel.base_position[:] = rng.normal(size=(n, 3))
    rpy = np.column_stack([0.5 * np.sin(tel.t), 0.3 * np.cos(tel.t), np.linspace(0.0, 5.0, n)])
    tel.base_quaternion[:] = [pin.Quaternion(pin.rpy.rpyToMatrix(a)).coeffs() for a in rpy]
    tel.ee_position[:] = rng.normal(size=tel.ee_position.shape)
    tel.com[:] = rng.normal(size=(n, 3))
    tel.momentum[:] = rng.normal(size=(n, 6))
    return tel


def _lines(ax) -> dict[str, np.ndarray]:
    """{label: (N, 2) xy data} of an axes' lines."""
    return {line.get_label(): np.column_stack(line.get_data()) for line in ax.get_lines()}


def test_joint_error_curves_are_reference_minus_position_in_radians(iiwa2):
    """Each arm's panel plots, per joint, (reference - position) in rad against t, and names the arm."""
    tel = _telemetry(iiwa2)
    figure = joint_error_figure(iiwa2, tel)
    assert len(figure.axes) == len(iiwa2.arms) == 2
    for k, (ax, arm) in enumerate(zip(figure.axes, iiwa2.arms)):
        lines = _lines(ax)
        assert list(lines) == list(arm.joints) and ax.get_title().startswith(arm_name(arm, k))
        assert ax.get_ylabel() == "error (rad)"
        for name in arm.joints:
            column = iiwa2.joint_names.index(name)
            expected = tel.joint_reference[:, column] - tel.joint_positions[:, column]
            np.testing.assert_allclose(lines[name], np.column_stack([tel.t, expected]), rtol=1e-12)


def test_curves_of_a_panel_are_distinguishable(iiwa2):
    """No two curves of a panel share both colour and dash pattern."""
    figure = joint_error_figure(iiwa2, _telemetry(iiwa2))
    for ax in figure.axes:
        styles = [(line.get_color(), line.get_linestyle()) for line in ax.get_lines()]
        assert len(set(styles)) == len(styles)


def test_arm_names_come_from_joint_names():
    """An arm is named by its joints' common prefix, or numbered when they share none."""
    from freefloat.robot.robot import Arm

    joints = np.arange(3)
    assert arm_name(Arm("arm1_ee", ("arm1_joint1", "arm1_joint2"), joints), 0) == "arm1"
    assert arm_name(Arm("left_tool0", ("left_shoulder_pan_joint", "left_elbow_joint"), joints), 0) == "left"
    assert arm_name(Arm("ee", ("Joint_1", "Joint_2"), joints), 2) == "arm 3"


def test_torque_curves_are_held_steps_of_tau(iiwa2):
    """Each arm's panel plots its joints' torques as steps held from each sample."""
    tel = _telemetry(iiwa2)
    figure = torque_figure(iiwa2, tel)
    for ax, _arm in zip(figure.axes, iiwa2.arms):
        for line in ax.get_lines():
            column = iiwa2.joint_names.index(line.get_label())
            assert line.get_drawstyle() == "steps-post"
            np.testing.assert_array_equal(line.get_ydata(), tel.tau[:, column])


def test_base_figure_plots_position_unwrapped_attitude_and_3d_path(iiwa2):
    """The base figure plots r0 components, the generating roll/pitch/yaw in degrees (yaw
    unwrapped past 180 deg) and, for a motion out of the xy-plane, the path in 3-D."""
    tel = _telemetry(iiwa2)
    position_ax, attitude_ax, path_ax = base_trajectory_figure(tel).axes
    for i, axis in enumerate("xyz"):
        np.testing.assert_array_equal(_lines(position_ax)[axis][:, 1], tel.base_position[:, i])
    rpy = np.column_stack(
        [0.5 * np.sin(tel.t), 0.3 * np.cos(tel.t), np.linspace(0.0, 5.0, len(tel.t))]
    )
    for i, angle in enumerate(("roll", "pitch", "yaw")):
        np.testing.assert_allclose(
            _lines(attitude_ax)[angle][:, 1], np.degrees(rpy[:, i]), atol=1e-9
        )
    assert path_ax.name == "3d" and "3-D" in path_ax.get_title()
    (path,) = [line for line in path_ax.get_lines() if line.get_label() == "base CoM"]
    np.testing.assert_array_equal(np.column_stack(path.get_data_3d()), tel.base_position)


def test_planar_motion_is_drawn_in_the_xy_plane_and_says_so(iiwa2):
    """When the base stays at one height its path is an xy panel titled as such."""
    tel = _telemetry(iiwa2)
    tel.base_position[:, 2] = 0.3
    path_ax = base_trajectory_figure(tel).axes[2]
    assert path_ax.name == "rectilinear" and "xy-plane" in path_ax.get_title()
    np.testing.assert_array_equal(_lines(path_ax)["base CoM"], tel.base_position[:, :2])


def test_end_effector_paths_mark_start_and_end_and_draw_the_robot(iiwa2):
    """Each end-effector's path is drawn, marked at its first and last samples in its colour,
    and the robot is drawn at the first and last configurations (forward kinematics)."""
    tel = _telemetry(iiwa2)
    ax = end_effector_paths_figure(iiwa2, tel).axes[0]
    lines = ax.get_lines()
    for k, (arm, name) in enumerate(zip(iiwa2.arms, iiwa2.end_effectors)):
        (path,) = [line for line in lines if line.get_label() == f"{arm_name(arm, k)} ({name})"]
        np.testing.assert_array_equal(np.column_stack(path.get_data_3d()), tel.ee_position[:, k])
        marks = {line.get_marker(): np.column_stack(line.get_data_3d()) for line in lines
                 if line.get_color() == path.get_color() and line.get_marker() in ("o", "s")}
        np.testing.assert_array_equal(marks["o"], tel.ee_position[:1, k])
        np.testing.assert_array_equal(marks["s"], tel.ee_position[-1:, k])
    drawn = [np.column_stack(line.get_data_3d()) for line in lines if line.get_color() == END_COLOR]
    np.testing.assert_allclose(np.concatenate(drawn), np.concatenate(skeleton(iiwa2, tel.q[-1])), atol=1e-12)


def test_skeleton_joins_joint_origins_to_their_parents(iiwa2):
    """The drawn robot's segments run between Pinocchio's joint origins (and to the end-effectors)."""
    q = _configurations(iiwa2.model, 1)[0]
    data = iiwa2.model.createData()
    pin.framesForwardKinematics(iiwa2.model, data, q)
    segments = skeleton(iiwa2, q)
    assert len(segments) == iiwa2.model.njoints - 2 + len(iiwa2.end_effectors)
    np.testing.assert_allclose(segments[0], [data.oMi[1].translation, data.oMi[2].translation], atol=1e-12)


def test_drift_curves_are_the_summary_drifts(iiwa2):
    """The CoM curve is the distance from the free CoM motion (its maximum is the summary's
    com_drift_max); the momentum curves are the norms of the differences from sample 0 (the
    zero at sample 0 left out of the log axis)."""
    tel = _telemetry(iiwa2)
    com_ax, momentum_ax = com_drift_figure(iiwa2, tel).axes
    com_curve = _lines(com_ax)["|com - free motion|"][:, 1]
    np.testing.assert_allclose(com_curve[1:], np.linalg.norm(tel.com - free_com_motion(tel, iiwa2), axis=1)[1:])
    assert np.nanmax(com_curve) == summarize(tel, iiwa2)["com_drift_max"]
    linear, angular = (line.get_ydata() for line in momentum_ax.get_lines())
    np.testing.assert_allclose(
        linear[1:], np.linalg.norm(tel.momentum[1:, :3] - tel.momentum[0, :3], axis=1)
    )
    np.testing.assert_allclose(
        angular[1:], np.linalg.norm(tel.momentum[1:, 3:] - tel.momentum[0, 3:], axis=1)
    )
    assert np.isnan(linear[0]) and np.isnan(angular[0])


def test_log_axes_are_clipped_to_the_data():
    """A denormal at t = 0 is left out of a log axis instead of stretching it to 1e-312."""
    from freefloat.app.viz.plotting import figure, log_curve

    _, (ax,) = figure(1, 1, (4.0, 3.0), "test")
    log_curve(ax, np.arange(4.0), np.array([1e-312, 1e-11, 3e-11, 2e-11]), "drift")
    low, high = ax.get_ylim()
    assert 1e-12 < low < 1e-11 and 3e-11 < high < 1e-10


@pytest.mark.slow
def test_write_figures_writes_png_and_pdf(iiwa2, tmp_path):
    """With references, all six figures are written, as PNG (the default) and, when chosen, as
    PNG and PDF files."""
    from freefloat.app.viz.plotting import choose

    stems = ["joint_errors", "torques", "base_trajectory", "end_effector_paths", "end_effector_displacement",
             "com_drift"]
    assert [p.name for p in write_figures(iiwa2, _telemetry(iiwa2), tmp_path / "png")] == [f"{s}.png" for s in stems]
    with choose(None, ("png", "pdf")):
        written = write_figures(iiwa2, _telemetry(iiwa2), tmp_path / "figs")
    assert [p.name for p in written] == [f"{stem}.{fmt}" for stem in stems for fmt in ("png", "pdf")]
    assert all(p.read_bytes().startswith(b"\x89PNG\r\n\x1a\n") for p in written if p.suffix == ".png")
    assert all(p.read_bytes().startswith(b"%PDF") for p in written if p.suffix == ".pdf")


@pytest.mark.slow
def test_error_figure_skipped_without_references(iiwa2, tmp_path):
    """A run without joint references (NaN) gets no joint error figure and the five others."""
    written = write_figures(iiwa2, _telemetry(iiwa2, references=False), tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written)
    assert "joint_errors.png" not in [p.name for p in written] and len(written) == 5


def test_an_approach_with_a_plan_gets_its_tracking_figure(iiwa2, tmp_path):
    """A planned capture's approach (a phase with joint references) gets approach_joint_errors,
    titled as the approach; one without references gets none."""
    written = write_approach_figure(iiwa2, _telemetry(iiwa2), tmp_path / "planned")
    assert [p.name for p in written] == ["approach_joint_errors.png"] and written[0].stat().st_size > 0
    assert write_approach_figure(iiwa2, _telemetry(iiwa2, references=False), tmp_path / "none") == []
    assert joint_error_figure(iiwa2, _telemetry(iiwa2), title=APPROACH_TITLE).get_suptitle() == APPROACH_TITLE


@pytest.mark.slow
def test_a_torque_free_run_writes_no_torque_figure(iiwa2, tmp_path):
    """Zero joint torques throughout: no torque figure is written, and empty_figures says why."""
    from freefloat.app.viz.figures import empty_figures

    tel = _telemetry(iiwa2)
    tel.tau[:] = 0.0
    written = [p.name for p in write_figures(iiwa2, tel, tmp_path)]
    assert "torques.png" not in written and "base_trajectory.png" in written
    assert empty_figures(iiwa2, tel) == {"torques": "every joint torque is zero (a torque-free run)"}


def test_angular_rate_curves_are_the_angular_speeds(iiwa2):
    """The log panel draws each end-effector's and the base's |w| (rad/s), the base panel w0's
    components, and the threshold line sits at the given rate."""
    from freefloat.app.viz.figures import angular_rates_figure
    from freefloat.dynamics.metrics import angular_speeds

    tel = _telemetry(iiwa2)
    tel.v[:] = np.random.default_rng(3).normal(size=tel.v.shape)
    tel.base_twist[:, 3:] = np.random.default_rng(4).normal(size=(len(tel.t), 3))
    base_ax, log_ax = angular_rates_figure(iiwa2, tel, threshold=1e-3).axes
    base, ends = angular_speeds(iiwa2, tel)
    curves = _lines(log_ax)
    np.testing.assert_allclose(curves["base"][:, 1], base)
    for k, name in enumerate(iiwa2.end_effectors):
        (label,) = [key for key in curves if key.endswith(f"({name})")]
        np.testing.assert_allclose(curves[label][:, 1], ends[:, k])
    np.testing.assert_allclose(curves["threshold 0.001 rad/s"][:, 1], 1e-3)
    np.testing.assert_allclose(_lines(base_ax)["w0 z"][:, 1], tel.base_twist[:, 5])


def test_the_threshold_label_gives_three_significant_digits_and_its_unit(iiwa2):
    """A threshold computed by the run (1.02706e-05 rad/s) is labelled to 3 digits, with rad/s."""
    from freefloat.app.viz.figures import angular_rates_figure

    tel = _telemetry(iiwa2)
    tel.base_twist[:, 3:] = np.random.default_rng(4).normal(size=(len(tel.t), 3))
    _, log_ax = angular_rates_figure(iiwa2, tel, threshold=1.0270612e-05).axes
    assert "threshold 1.03e-05 rad/s" in _lines(log_ax)


def test_balance_curves_are_the_summary_balances(iiwa2):
    """With a wrench, the balance figure's residual curves peak at the summary's balances, and
    its momentum panel draws the change next to the impulse applied."""
    from freefloat.app.viz.figures import balance_figure
    from freefloat.dynamics.balance import balance
    from freefloat.dynamics.wrenches import ExternalWrench

    tel = _telemetry(iiwa2)
    tel.t[:] = np.arange(len(tel.t)) * 1e-3
    link = [f.name for f in iiwa2.model.frames if f.type == pin.FrameType.BODY][3]
    wrenches = (ExternalWrench(link, force=(1.0, 2.0, 0.0), torque=(0.0, 0.0, 3.0), start=0.002, end=0.02),)
    s = summarize(tel, iiwa2, wrenches, 1e-3)
    momentum_ax, _, residual_ax, energy_ax = balance_figure(tel, balance(iiwa2, tel, wrenches, 1e-3)).axes
    residuals = {**_lines(residual_ax), **_lines(energy_ax)}
    for label, key in (("|P - P(0) - impulse| (kg m/s)", "linear_momentum_balance_max"),
                       ("|L - L(0) - impulse| (kg m^2/s)", "angular_momentum_balance_max"),
                       ("|E - E(0) - W joints - W wrenches|", "energy_balance_max")):
        assert np.nanmax(residuals[label][:, 1]) == pytest.approx(s[key])
    impulse = _lines(momentum_ax)["|impulse| on P (kg m/s)"][:, 1]
    assert impulse[-1] == pytest.approx(np.linalg.norm(s["external_impulse"][:3]))


@pytest.mark.slow
def test_figures_rendered_in_two_processes_are_all_written(tmp_path, monkeypatch):
    """save_all writes every figure, half of them from the helper process; when the helper cannot
    take them (here a save function it cannot import), this process writes its share itself."""
    import os

    from matplotlib.figure import Figure

    from freefloat.app.viz import plotting

    def figures():
        out = {}
        for i in range(5):
            fig = Figure()
            fig.add_subplot().plot([0, 1], [0, i])
            out[f"f{i}"] = fig
        return out

    expected = {f"f{i}.{fmt}" for i in range(5) for fmt in plotting.FORMATS}
    (tmp_path / "a").mkdir()
    written = plotting.save_all(figures(), tmp_path / "a")
    assert {p.name for p in written} == expected == {p.name for p in (tmp_path / "a").iterdir()}
    parent, real = os.getpid(), plotting.save

    def child_fails(fig, out_dir, stem, formats):
        if os.getpid() != parent:
            raise RuntimeError("planted failure in the helper")
        return real(fig, out_dir, stem, formats)

    monkeypatch.setattr(plotting, "save", child_fails)
    (tmp_path / "b").mkdir()
    plotting.save_all(figures(), tmp_path / "b")
    assert {p.name for p in (tmp_path / "b").iterdir()} == expected


def _artists(fig) -> list:
    """Every plotted datum of a figure: its title and figure legends' texts, per axes its title,
    labels, limits, legend texts and per line its label, style and data."""
    out = [fig._suptitle.get_text(), [[text.get_text() for text in legend.get_texts()] for legend in fig.legends]]
    for ax in fig.axes:
        legend = ax.get_legend()
        out.append((ax.get_title(), ax.get_xlabel(), ax.get_ylabel(), ax.get_xlim(), ax.get_ylim(),
                    [text.get_text() for text in legend.get_texts()] if legend else None))
        out += [(line.get_label(), line.get_drawstyle(), line.get_linestyle(), line.get_color(),
                 np.asarray(line.get_xdata(), float).tolist(), np.asarray(line.get_ydata(), float).tolist())
                for line in ax.get_lines()]
    return out


@pytest.mark.parametrize("robot", ["iiwa2", "four_arm"])
def test_a_redrawn_per_arm_figure_equals_a_fresh_one(robot, request):
    """torques drawn on the figure joint_errors drew first (one Figure redrawn) has the same
    titles, labels, limits, legends, line styles and data as torques drawn on a fresh figure
    (with a legend per panel, and with one for all panels)."""
    from freefloat.app.viz.figures import ArmPanels

    robot = request.getfixturevalue(robot)
    tel = _telemetry(robot, n=3000)  # thinned curves: the redrawn lines change their sample count
    tel.tau[:] = np.cumsum(tel.tau, axis=0)  # torques at another scale than the errors
    panels = ArmPanels(robot, tel.t)
    errors = joint_error_figure(robot, tel, panels)
    first = _artists(errors)
    redrawn = torque_figure(robot, tel, panels)
    assert redrawn is errors
    assert _artists(redrawn) == _artists(torque_figure(robot, tel))
    assert _artists(joint_error_figure(robot, tel)) == first
    assert _artists(redrawn) != first


@pytest.fixture(scope="module")
def four_arm():
    """The default job's robot: four arms whose joints are named alike (arm1_joint1, ...)."""
    from freefloat.paths import URDF_DIR

    return _load(URDF_DIR / "four_arm_planar.urdf")


def test_one_legend_names_the_joints_of_every_arm_panel(four_arm):
    """When every arm names its joints alike, one figure legend serves all panels: its k-th
    entry is the end of each arm's k-th joint name and has that joint's line style in every
    panel, whose lines keep the full joint names and plot every sample of the error."""
    tel = _telemetry(four_arm, n=200)
    fig = joint_error_figure(four_arm, tel)
    (legend,) = fig.legends
    assert all(ax.get_legend() is None for ax in fig.axes)
    entries = [text.get_text() for text in legend.get_texts()]
    handles = legend.legend_handles
    error = tel.joint_reference - tel.joint_positions
    for ax, arm in zip(fig.axes, four_arm.arms):
        assert [line.get_label() for line in ax.get_lines()] == list(arm.joints)
        for line, joint, entry, handle, column in zip(ax.get_lines(), arm.joints, entries, handles,
                                                      arm.v_indices - four_arm.n_base):
            assert joint.endswith(entry) and len(entry) < len(joint)
            assert (line.get_color(), line.get_linestyle(), line.get_linewidth()) == (
                handle.get_color(), handle.get_linestyle(), handle.get_linewidth())
            np.testing.assert_array_equal(line.get_ydata(), error[:, column])
    assert len(entries) == len(set(entries)) == len(four_arm.arms[0].joints)


def test_arms_named_apart_keep_a_legend_each(iiwa2):
    """Arms whose joints' names differ beyond the arm's name (lbr_iiwa_joint_1, lbr_iiwa_joint_1_2)
    get a legend per panel with the full names, and no figure legend."""
    from freefloat.app.viz.figures import joint_suffixes

    assert joint_suffixes(iiwa2) is None
    fig = torque_figure(iiwa2, _telemetry(iiwa2))
    assert not fig.legends
    for ax, arm in zip(fig.axes, iiwa2.arms):
        assert [text.get_text() for text in ax.get_legend().get_texts()] == list(arm.joints)


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, (8, 4), elements=st.floats(-1.0, 1.0)).filter(lambda a: np.linalg.norm(a, axis=1).min() > 1e-3))
def test_page_quaternions_are_pinocchios_up_to_sign(raw):
    """The page's vectorised rotation -> quaternion equals ``pin.Quaternion(R).coeffs()`` up to
    sign, on random rotations and on the half-turns about each axis (where the trace is -1)."""
    rotations = [pin.Quaternion(q / np.linalg.norm(q)).matrix() for q in raw]
    rotations += [np.eye(3), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    found = quaternions(np.array(rotations))
    expected = np.array([pin.Quaternion(r).coeffs() for r in rotations])
    np.testing.assert_allclose(np.abs(np.sum(found * expected, axis=1)), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(found, axis=1), 1.0, atol=1e-12)
