"""Self-contained meshcat animation pages of a run, written without a meshcat server.

A page is meshcat's bundled viewer (``meshcat/viewer/dist/main.min.js``) followed by meshcat
command packets (msgpack, base64), objects lowered by ``meshcat.commands`` and the animation as
three.js clips whose key times and values are typed arrays (:func:`_animated`), and the
embedded mesh files (:mod:`.assets`: each once, gzipped, only from allowed folders). The page
(:mod:`.page_template`) replays them in order, so it needs neither network nor server, frames
the camera on the motion (:mod:`.camera`), draws a grid just under it (:mod:`.floor`, in place of
meshcat's own at ``/Grid``), loops the animation and shows play/pause, a time slider and the
run's events.

Scene layout: one meshcat node per Pinocchio joint, ``/meshcat/freefloat/<joint name>``, whose
animated pose is the joint frame in the inertial frame (``data.oMi``). Geometry hangs below it,
``/meshcat/freefloat/<joint name>/<geometry name>``, with its constant placement in that joint
frame (and mesh scale) as the object's intrinsic matrix. Extra bodies are animated nodes
``/meshcat/freefloat/extra/<name>``; followed points (:mod:`.markers`) are animated spheres
``/meshcat/freefloat/markers/<name>`` with their whole path drawn at
``/meshcat/freefloat/paths/<name>``; bars (a closed chain's links) are unit cylinders
``/meshcat/freefloat/bars/<name>`` along their node's y axis, animated in position (the bar's
middle), quaternion (y onto the bar) and scale (y: its length). Static lines (a reference path)
are ``/meshcat/freefloat/lines/<name>``. Animation key times are in frames of ``fps``, so the clip
plays in simulated time.
"""

from __future__ import annotations

import base64
import json
import re
import uuid
import warnings
from pathlib import Path

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import umsgpack
from meshcat.commands import SetObject
from meshcat.path import Path as MeshcatPath

from ...robot.robot import Robot
from .assets import AssetTable, allowed_folders
from .camera import frame_motion
from .floor import floor, grid_object
from .markers import Bar, Marker, robot_markers
from .page_template import PAGE

#: The viewer bundled with the installed meshcat package.
VIEWER_JS = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
#: Meshcat node under which the whole run is drawn.
ROOT = MeshcatPath(("meshcat", "freefloat"))
#: Meshcat's grid node, which a page redraws under the motion (:mod:`.floor`).
GRID = MeshcatPath(("Grid",))

#: An extra animated body: (name, meshcat geometry or object, poses in the inertial frame
#: (N, 4, 4) at the same samples as ``q``).
ExtraBody = tuple[str, mg.Geometry | mg.Object, np.ndarray]
#: A moment of the run named on the page: (time, s, same clock as ``t``; label).
Event = tuple[float, str]

_COLORS = {"base": 0x9A9A9A, "link": 0x4F7FC0, "joint": 0xF0A030, "end_effector": 0xD02020}
#: Radius of a marker sphere, of a marker without trail (a joint centre) and of a bar, as fractions
#: of the framed radius.
_MARKER_SIZE, _JOINT_SIZE, _BAR_SIZE = 0.015, 0.011, 0.006
#: Opacity of a linkage's base, so that the pivots on it show.
_BASE_OPACITY = 0.5
#: A static line: (name, 0xRRGGBB, points (K, 3), inertial frame, m).
Line = tuple[str, int, np.ndarray]


def frame_indices(t: np.ndarray, fps: float) -> np.ndarray:
    """Samples shown in the animation: the nearest sample to each tick of a 1/fps grid.

    Args:
        t: sample times, s, non-decreasing (N,).
        fps: frames per second of simulated time.

    Returns:
        Increasing sample indices (M,), starting at 0 and ending at N - 1; every sample when
        the samples are sparser than the grid.
    """
    if fps <= 0.0:
        raise ValueError(f"fps must be positive, got {fps}")
    if len(t) == 1:
        return np.zeros(1, dtype=int)
    n_ticks = int(np.floor((t[-1] - t[0]) * fps + 1e-9)) + 1
    grid = t[0] + np.arange(n_ticks) / fps
    right = np.clip(np.searchsorted(t, grid), 1, len(t) - 1)
    left = right - 1
    nearest = np.where(np.abs(t[left] - grid) <= np.abs(t[right] - grid), left, right)
    return np.unique(np.append(nearest, len(t) - 1))


def write_trajectory_html(
    robot: Robot,
    t: np.ndarray,
    q: np.ndarray,
    path: str | Path,
    fps: float = 30.0,
    extra: list[ExtraBody] | None = None,
    markers: list[Marker] | None = None,
    events: list[Event] | None = None,
    bars: list[Bar] | None = None,
    lines: list[Line] | None = None,
    view: np.ndarray | None = None,
) -> Path:
    """Write a self-contained meshcat page animating a run.

    Args:
        robot: the robot; its visual geometry is drawn when it has any, otherwise a stick
            figure built from the model (base box, joint spheres, links, end-effectors); a
            link whose mesh is missing gets its pieces of the stick figure.
        t: sample times, s (N,).
        q: Pinocchio configurations at those times (N, nq).
        path: output ``.html`` file.
        fps: animation frames per second of simulated time (samples are picked by
            :func:`frame_indices`).
        extra: further bodies to animate, each (name, meshcat geometry or object, poses
            (N, 4, 4) in the inertial frame).
        markers: points to follow, positions (N, 3) at the samples; default the robot's base
            CoM, system CoM and end-effectors (:func:`.markers.robot_markers`).
        events: moments named under the time slider, e.g. ``[(2.0, "grasp")]``.
        bars: links to draw as bars between moving points, ends (N, 3) at the samples; with
            bars, the robot's own geometry is drawn for its base (root link) only: the bars
            are its links.
        lines: static polylines, e.g. a reference path, each (name, colour, points (K, 3)).
        view: direction from the motion to the camera (3,); default
            :data:`.camera.VIEW_DIRECTION` (oblique, from the front right).

    Returns:
        The written path.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    model = robot.model
    if t.ndim != 1 or len(t) == 0 or q.shape != (len(t), model.nq):
        raise ValueError(f"need t (N,) and q (N, {model.nq}); got {t.shape} and {q.shape}")
    shown = frame_indices(t, fps)
    keys = (t[shown] - t[0]) * fps
    bodies = [(name, obj, _checked_poses(name, poses, len(t))[shown]) for name, obj, poses in extra or []]
    if markers is None:
        markers = robot_markers(robot, q[shown])
    else:
        markers = [m._replace(positions=_checked_points(m.name, m.positions, len(t))[shown]) for m in markers]
    bars = [b._replace(start=_checked_points(b.name, b.start, len(t), "bar", "start")[shown],
                       end=_checked_points(b.name, b.end, len(t), "bar", "end")[shown]) for b in bars or []]

    table = AssetTable(allowed_folders(robot.urdf_path), robot.urdf_path)
    packets = [
        _object_packet(ROOT.append(f"{model.names[j]}/{name}"), obj, placement)
        for j, name, obj, placement in _robot_objects(robot, table, base_only=bool(bars))
    ]
    data = model.createData()
    poses = np.empty((len(shown), model.njoints, 4, 4))
    for k, i in enumerate(shown):
        pin.forwardKinematics(model, data, q[i])
        poses[k] = [m.homogeneous for m in data.oMi]
    visited = np.concatenate(
        [poses[:, 1:, :3, 3].reshape(-1, 3), _geometry_points(robot, poses)]
        + [_body_points(obj, body_poses) for _, obj, body_poses in bodies] + [m.positions for m in markers]
        + [p for b in bars for p in (b.start, b.end)] + [np.asarray(points, float) for _, _, points in lines or []])
    framing = frame_motion(visited, **({} if view is None else {"direction": view}))
    packets.append(SetObject(grid_object(floor(visited, framing)), path=GRID).lower())

    clips: list[dict] = []
    for j in range(1, model.njoints):
        clips.append(_clip(ROOT.append(model.names[j]), keys, poses[:, j], fps))
    for name, obj, body_poses in bodies:
        node = ROOT.append(f"extra/{name}")
        packets.append(SetObject(obj, path=node).lower())
        clips.append(_clip(node, keys, body_poses, fps))
    for marker in markers:
        packets += _marker_packets(marker, (_MARKER_SIZE if marker.trail else _JOINT_SIZE) * framing.radius)
        marker_poses = np.tile(np.eye(4), (len(shown), 1, 1))
        marker_poses[:, :3, 3] = marker.positions
        clips.append(_clip(ROOT.append(f"markers/{marker.name}"), keys, marker_poses, fps))
    for bar in bars:
        node = ROOT.append(f"bars/{bar.name}")
        packets.append(SetObject(mg.Mesh(mg.Cylinder(1.0, _BAR_SIZE * framing.radius), _material(bar.color)),
                                 path=node).lower())
        clips.append(_bar_clip(node, keys, bar, fps))
    for name, color, points in lines or []:
        packets.append(SetObject(_dashed(np.asarray(points, float), color), path=ROOT.append(f"lines/{name}")).lower())
    packets.append({"type": "set_animation", "path": "", "animations": clips,
                    "options": {"play": True, "repetitions": float("inf")}})  # loop until paused

    settings = {
        "duration": float(t[-1] - t[0]),
        "t0": float(t[0]),
        "events": [[float(time), label] for time, label in events or []],
        "camera": {"position": framing.position.tolist(), "target": framing.target.tolist(),
                   "radius": framing.radius},
    }
    html = PAGE.format(
        title=f"freefloat: {robot.urdf_path.name}",
        viewer_js=VIEWER_JS.read_text(),
        settings=json.dumps(settings),
        commands="\n".join(
            [f'freefloat_asset("{kind}", "{b64}");' for kind, b64 in table.entries]
            + [f'freefloat_command("{base64.b64encode(umsgpack.packb(p)).decode("ascii")}");' for p in packets]
        ),
    )
    path = Path(path)
    path.write_text(html, encoding="utf-8")
    return path


def read_settings(page: str | Path) -> dict:
    """The settings a page was written with: ``duration`` and ``t0`` (s), ``events``
    ([time s, label]) and ``camera`` (``position``, ``target`` in m, inertial frame; ``radius``)."""
    found = re.search(r"const FREEFLOAT = (\{.*?\});\n", Path(page).read_text())
    if found is None:
        raise ValueError(f"{page} is not a freefloat page")
    return json.loads(found.group(1))


def _geometry_points(robot: Robot, poses: np.ndarray) -> np.ndarray:
    """Corners of every visual geometry's bounding box at every shown frame, inertial frame, m
    (K, 3); ``poses`` are the joint poses (M, njoints, 4, 4)."""
    if robot.visual_model is None:
        return np.empty((0, 3))
    points = []
    for g in robot.visual_model.geometryObjects:
        g.geometry.computeLocalAABB()
        in_joint = _box_corners(g.geometry.aabb_local.min_, g.geometry.aabb_local.max_) @ g.placement.homogeneous.T
        points.append(_posed(poses[:, g.parentJoint], in_joint))
    return np.concatenate(points) if points else np.empty((0, 3))


def _body_points(obj: mg.Geometry | mg.Object, poses: np.ndarray) -> np.ndarray:
    """Points an extra body covers at every shown frame, inertial frame, m (K, 3): the corners of a
    box (a meshcat ``Box``, or a mesh of one), else its origin; ``poses`` (M, 4, 4)."""
    box = getattr(obj, "geometry", obj)
    if not isinstance(box, mg.Box):
        return poses[:, :3, 3]
    half = np.asarray(box.lengths, dtype=float) / 2
    return _posed(poses, _box_corners(-half, half))


def _box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The 8 corners of the box from ``low`` to ``high`` (3,), axis-aligned in the frame those are
    given in, homogeneous in that frame (8, 4), m."""
    return np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])


def _posed(poses: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Homogeneous ``points`` (K, 4) of a body placed at each of ``poses`` (M, 4, 4), inertial frame
    (M K, 3)."""
    return np.einsum("mij,kj->mki", poses, points)[..., :3].reshape(-1, 3)


def _checked_poses(name: str, poses: np.ndarray, n: int) -> np.ndarray:
    """An extra body's poses as (n, 4, 4) floats, or ValueError naming the body."""
    poses = np.asarray(poses, dtype=float)
    if poses.shape != (n, 4, 4):
        raise ValueError(f"extra body '{name}': poses must be ({n}, 4, 4), got {poses.shape}")
    return poses


def _checked_points(name: str, points: np.ndarray, n: int, what: str = "marker",
                    field: str = "positions") -> np.ndarray:
    """A marker's positions or a bar's ends as (n, 3) floats, or ValueError naming it."""
    points = np.asarray(points, dtype=float)
    if points.shape != (n, 3):
        raise ValueError(f"{what} '{name}': {field} must be ({n}, 3), got {points.shape}")
    return points


def _marker_packets(marker: Marker, radius: float) -> list[dict]:
    """The marker's sphere (animated node) and, with ``trail``, its whole path as a line
    (static node)."""
    sphere = mg.Mesh(mg.Sphere(radius), _material(marker.color))
    packets = [SetObject(sphere, path=ROOT.append(f"markers/{marker.name}")).lower()]
    if marker.trail:
        line = mg.Line(mg.PointsGeometry(marker.positions.T.astype(np.float32)),
                       mg.LineBasicMaterial(color=marker.color, linewidth=2))
        packets.append(SetObject(line, path=ROOT.append(f"paths/{marker.name}")).lower())
    return packets


def _dashed(points: np.ndarray, color: int, dashes: int = 120) -> mg.LineSegments:
    """A polyline (K, 3) drawn dashed (meshcat has no dashed material): cut into ``2 dashes``
    pieces of equal sample count, every other one drawn as a straight segment."""
    picked = points[np.unique(np.linspace(0, len(points) - 1, 2 * dashes + 1).round().astype(int))]
    ends = picked[: len(picked) - len(picked) % 2]  # an even count: (start, end) pairs
    return mg.LineSegments(mg.PointsGeometry(ends.T.astype(np.float32)), mg.LineBasicMaterial(color=color))


def _bar_clip(node: MeshcatPath, keys: np.ndarray, bar: Bar, fps: float) -> dict:
    """A bar's unit cylinder's animation at ``node``: position (the middle), quaternion (the
    node's y axis onto the bar) and scale (y: the length) tracks; ``keys`` in frames (M,)."""
    axis = bar.end - bar.start
    length = np.linalg.norm(axis, axis=1)
    y = np.array([0.0, 1.0, 0.0])
    quaternions = np.array([pin.Quaternion.FromTwoVectors(y, a / n if n > 0.0 else y).coeffs()
                            for a, n in zip(axis, length)])
    scale = np.ones((len(length), 3))
    scale[:, 1] = length
    return _animated(node, keys, fps, [("position", "vector3", 0.5 * (bar.start + bar.end)),
                                       ("quaternion", "quaternion", quaternions), ("scale", "vector3", scale)])


def _clip(node: MeshcatPath, keys: np.ndarray, poses: np.ndarray, fps: float) -> dict:
    """A node's animation: position and quaternion ([x, y, z, w]) tracks of ``poses`` (M, 4, 4);
    ``keys`` in frames (M,)."""
    return _animated(node, keys, fps, [("position", "vector3", poses[:, :3, 3]),
                                       ("quaternion", "quaternion", quaternions(poses[:, :3, :3]))])


def quaternions(rotations: np.ndarray) -> np.ndarray:
    """Unit quaternions ``[x, y, z, w]`` (M, 4) of rotation matrices (M, 3, 3), each up to sign
    (as ``pin.Quaternion(R).coeffs()``), vectorised: each row from its largest of 4w^2 = 1 + tr R
    and 4x^2 = 1 + 2 R_00 - tr R (and y, z alike), the others from the sums and differences of
    the off-diagonal terms (Shepperd's method)."""
    r = np.asarray(rotations, dtype=float)
    trace = np.trace(r, axis1=1, axis2=2)
    candidates = np.stack([r[:, 0, 0], r[:, 1, 1], r[:, 2, 2], trace], axis=1)
    largest = candidates.argmax(axis=1)
    s = np.sqrt(np.maximum(1.0 + 2.0 * candidates[np.arange(len(r)), largest] - trace, 0.0))  # 2 |that term|
    half = 0.5 / s
    wx, wy, wz = r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]
    xy, xz, yz = r[:, 0, 1] + r[:, 1, 0], r[:, 0, 2] + r[:, 2, 0], r[:, 1, 2] + r[:, 2, 1]
    rows = {0: (0.5 * s, xy * half, xz * half, wx * half), 1: (xy * half, 0.5 * s, yz * half, wy * half),
            2: (xz * half, yz * half, 0.5 * s, wz * half), 3: (wx * half, wy * half, wz * half, 0.5 * s)}
    out = np.empty((len(r), 4))
    for case, columns in rows.items():
        chosen = largest == case
        out[chosen] = np.stack(columns, axis=1)[chosen]
    return out


#: msgpack extension code of a Float64Array in meshcat's viewer (its own packer writes float32, 0x17).
FLOAT64_ARRAY = 0x18


def _animated(node: MeshcatPath, keys: np.ndarray, fps: float, tracks: list[tuple[str, str, np.ndarray]]) -> dict:
    """One node's lowered animation: a three.js clip of ``fps`` whose tracks, each (property,
    three.js type, values (M, k)), carry their key times (``keys``, frames) and values as
    Float64Arrays, which three.js's ``KeyframeTrack.parse`` takes as they are. meshcat's own
    ``AnimationTrack`` writes a map per key instead: packing those in pure Python was most of a
    page's cost, and grew with the run's length."""
    def typed(values: np.ndarray) -> umsgpack.Ext:
        return umsgpack.Ext(FLOAT64_ARRAY, np.ascontiguousarray(values, dtype="<f8").tobytes())

    return {"path": node.lower(), "clip": {"fps": fps, "name": "default", "tracks": [
        {"name": f".{name}", "type": kind, "times": typed(keys), "values": typed(values)}
        for name, kind, values in tracks]}}


def _object_packet(node: MeshcatPath, obj: mg.Object | dict, placement: np.ndarray) -> dict:
    """A lowered ``set_object`` command at ``node`` with intrinsic matrix ``placement`` (4, 4);
    ``obj`` is a meshcat object or an already lowered Collada object."""
    if isinstance(obj, dict):
        packet = {"type": "set_object", "path": node.lower(),
                  "object": {"metadata": {"version": 4.5, "type": "Object"}, "geometries": [], "materials": [],
                             "object": obj}}
    else:
        packet = SetObject(obj, path=node).lower()
    packet["object"]["object"]["matrix"] = placement.T.flatten().tolist()  # three.js: column-major
    return packet


def _robot_objects(robot: Robot, table: AssetTable,
                   base_only: bool = False) -> list[tuple[int, str, mg.Object | dict, np.ndarray]]:
    """(joint id, name, meshcat object, placement in the joint frame incl. scale (4, 4)): the
    robot's visual geometry, and the stick figure's pieces on each joint that lost a geometry (a
    mesh file the loader did not find, :attr:`~freefloat.robot.robot.Robot.missing_meshes`, or
    one the page may not embed); the whole stick figure when no geometry is drawn. With
    ``base_only`` the root link's geometry alone (nothing when it has none), half transparent
    so that the bars' pivots on it show."""
    visual, model = robot.visual_model, robot.model
    geometries = [] if visual is None else [g for g in visual.geometryObjects
                                            if not base_only or g.parentJoint <= 1]
    opacity = _BASE_OPACITY if base_only else 1.0
    objects, bare = [], set()
    for geometry in geometries:
        drawn = _visual_object(geometry, table, opacity)
        if drawn is None:
            bare.add(geometry.parentJoint)
        else:
            objects.append(drawn)
    if base_only:
        return objects
    if not objects:
        return _stick_figure(robot)
    bare |= {model.frames[model.getFrameId(link, pin.FrameType.BODY)].parentJoint for link, _ in robot.missing_meshes
             if model.existFrame(link, pin.FrameType.BODY)}  # a link's body frame (a joint may share its name)
    return objects + [piece for piece in _stick_figure(robot) if piece[0] in bare]


def _visual_object(
    geometry: pin.GeometryObject, table: AssetTable, opacity: float = 1.0
) -> tuple[int, str, mg.Object | dict, np.ndarray] | None:
    """Meshcat object of one Pinocchio geometry (mesh file or primitive), or None if it cannot
    or may not be drawn (a mesh outside the allowed folders, see :mod:`.assets`); a mesh or
    primitive (not Collada) at most ``opacity`` opaque."""
    mesh = Path(geometry.meshPath) if geometry.meshPath else None
    suffix = mesh.suffix.lower() if mesh else ""
    intrinsic = np.eye(4)
    if suffix and not table.allowed_mesh(mesh, geometry.name):  # any mesh file, not a primitive
        return None
    if suffix == ".dae":  # keeps the Collada materials; allowed textures embedded as data URIs
        data, resources = table.collada(mesh)
        obj: mg.Object | dict = {"uuid": str(uuid.uuid4()), "type": "_meshfile_object", "format": "dae",
                                 "data": data, "resources": resources}
    else:
        if suffix == ".stl":
            shape = mg.MeshGeometry(table.placeholder(mesh, "binary"), "stl")
        elif suffix == ".obj":
            shape = mg.MeshGeometry(table.placeholder(mesh, "text"), "obj")
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                shape = _primitive(geometry)
        if shape is None:
            warnings.warn(
                f"geometry '{geometry.name}' cannot be drawn by meshcat; skipped", stacklevel=3
            )
            return None
        intrinsic = shape.intrinsic_transform()
        obj = mg.Mesh(shape, _material(_rgb_int(geometry.meshColor), min(float(geometry.meshColor[3]), opacity)))
    scale = np.diag([*geometry.meshScale, 1.0])
    return (
        geometry.parentJoint,
        geometry.name,
        obj,
        geometry.placement.homogeneous @ scale @ intrinsic,
    )


#: Meshcat's cylinders lie along y, coal's along z: the rotation (4x4) from the first to the second.
Y_TO_Z = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


class _CoalCylinder(mg.Cylinder):
    """A coal cylinder (along its z axis) as meshcat draws it."""

    def intrinsic_transform(self) -> np.ndarray:
        return Y_TO_Z


def _primitive(geometry: pin.GeometryObject) -> mg.Geometry | None:
    """Meshcat geometry of a coal box, sphere or cylinder (what URDF primitives load as), as
    Pinocchio's ``meshcat_visualizer.loadPrimitive`` makes it; other shapes (capsules, cones,
    convex hulls) through that function, imported only then (``pinocchio.visualize`` loads viser,
    trimesh and scipy: about 0.3 s of the default job's CPU)."""
    import coal

    shape = geometry.geometry
    if isinstance(shape, coal.Box):
        return mg.Box(tuple((2.0 * shape.halfSide).tolist()))
    if isinstance(shape, coal.Sphere):
        return mg.Sphere(shape.radius)
    if isinstance(shape, coal.Cylinder):
        return _CoalCylinder(2.0 * shape.halfLength, shape.radius)
    from pinocchio.visualize.meshcat_visualizer import loadPrimitive

    return loadPrimitive(geometry)


def _stick_figure(robot: Robot) -> list[tuple[int, str, mg.Object, np.ndarray]]:
    """Stick figure from the kinematics: base box at the base CoM, a sphere at each joint, a
    cylinder from each joint to each child joint and end-effector frame, a sphere at each
    end-effector. Sizes scale with the longest segment, m."""
    model = robot.model
    segments = [
        (model.parents[j], f"link_to_{model.names[j]}", model.jointPlacements[j].translation)
        for j in range(2, model.njoints)
    ]
    for name, frame_id in zip(robot.end_effectors, robot.end_effector_frame_ids):
        frame = model.frames[frame_id]
        segments.append((frame.parentJoint, f"link_to_{name}", frame.placement.translation))
    length = max([float(np.linalg.norm(d)) for _, _, d in segments] + [0.0]) or 1.0

    base_box = np.eye(4)
    base_box[:3, 3] = model.inertias[1].lever
    objects = [
        (1, "base_box", mg.Mesh(mg.Box([0.4 * length] * 3), _material(_COLORS["base"])), base_box)
    ]
    objects += [
        (
            j,
            "joint_sphere",
            mg.Mesh(mg.Sphere(0.06 * length), _material(_COLORS["joint"])),
            np.eye(4),
        )
        for j in range(2, model.njoints)
    ]
    for joint, name, d in segments:
        height = float(np.linalg.norm(d))
        if height == 0.0:
            continue
        placement = np.eye(4)  # meshcat cylinders run along y, centred on the origin
        placement[:3, :3] = pin.Quaternion.FromTwoVectors(
            np.array([0.0, 1.0, 0.0]), d / height
        ).matrix()
        placement[:3, 3] = d / 2
        cylinder = mg.Mesh(mg.Cylinder(height, 0.025 * length), _material(_COLORS["link"]))
        objects.append((joint, name, cylinder, placement))
    for name, frame_id in zip(robot.end_effectors, robot.end_effector_frame_ids):
        frame = model.frames[frame_id]
        sphere = mg.Mesh(mg.Sphere(0.05 * length), _material(_COLORS["end_effector"]))
        objects.append(
            (frame.parentJoint, f"end_effector_{name}", sphere, frame.placement.homogeneous)
        )
    return objects


def _material(color: int, opacity: float = 1.0) -> mg.MeshPhongMaterial:
    """Phong material of colour 0xRRGGBB."""
    return mg.MeshPhongMaterial(color=color, opacity=opacity)


def _rgb_int(rgba: np.ndarray) -> int:
    """0xRRGGBB from RGBA in [0, 1]."""
    r, g, b = (round(255 * float(np.clip(c, 0.0, 1.0))) for c in rgba[:3])
    return (r << 16) | (g << 8) | b
