"""Self-contained meshcat animation pages of a run, written without a meshcat server.

A page is meshcat's bundled viewer (``meshcat/viewer/dist/main.min.js``) followed by meshcat
command packets (msgpack, base64), the content of ``Visualizer.static_html()``, but the packets
are lowered here from ``meshcat.commands`` objects and no server is started. The page decodes
them synchronously, in order, so it needs neither network nor server.

Scene layout: one meshcat node per Pinocchio joint, ``/meshcat/freefloat/<joint name>``, whose
animated pose is the joint frame in the inertial frame (``data.oMi``). Geometry hangs below it,
``/meshcat/freefloat/<joint name>/<geometry name>``, with its constant placement in that joint
frame (and mesh scale) as the object's intrinsic matrix. Extra bodies are animated nodes
``/meshcat/freefloat/extra/<name>``. Animation key times are in frames of ``fps``, so the clip
plays in simulated time.
"""

from __future__ import annotations

import base64
import warnings
from pathlib import Path

import meshcat
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import umsgpack
from meshcat.animation import Animation, AnimationClip, AnimationTrack
from meshcat.commands import SetAnimation, SetObject
from meshcat.path import Path as MeshcatPath
from pinocchio.visualize.meshcat_visualizer import DaeMeshGeometry, loadPrimitive

from ...robot.robot import Robot

#: The viewer bundled with the installed meshcat package.
VIEWER_JS = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
#: Meshcat node under which the whole run is drawn.
ROOT = MeshcatPath(("meshcat", "freefloat"))

#: An extra animated body: (name, meshcat geometry or object, poses in the inertial frame
#: (N, 4, 4) at the same samples as ``q``).
ExtraBody = tuple[str, mg.Geometry | mg.Object, np.ndarray]

_COLORS = {"base": 0x9A9A9A, "link": 0x4F7FC0, "joint": 0xF0A030, "end_effector": 0xD02020}

_PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>body {{margin: 0;}} #meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden;}}</style>
</head>
<body>
<div id="meshcat-pane"></div>
<script>
{viewer_js}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
function freefloat_command(b64) {{
  viewer.handle_command_bytearray(Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)));
}}
{commands}
</script>
</body>
</html>
"""


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
) -> Path:
    """Write a self-contained meshcat page animating a run.

    Args:
        robot: the robot; its visual geometry is drawn when it has any, otherwise a stick
            figure built from the model (base box, joint spheres, links, end-effectors).
        t: sample times, s (N,).
        q: Pinocchio configurations at those times (N, nq).
        path: output ``.html`` file.
        fps: animation frames per second of simulated time (samples are picked by
            :func:`frame_indices`).
        extra: further bodies to animate, each (name, meshcat geometry or object, poses
            (N, 4, 4) in the inertial frame).

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

    packets = [
        _object_packet(ROOT.append(f"{model.names[j]}/{name}"), obj, placement)
        for j, name, obj, placement in _robot_objects(robot)
    ]
    data = model.createData()
    poses = np.empty((len(shown), model.njoints, 4, 4))
    for k, i in enumerate(shown):
        pin.forwardKinematics(model, data, q[i])
        poses[k] = [m.homogeneous for m in data.oMi]
    animation = Animation(default_framerate=fps)
    for j in range(1, model.njoints):
        animation.clips[ROOT.append(model.names[j])] = _clip(keys, poses[:, j], fps)
    for name, obj, body_poses in extra or []:
        body_poses = np.asarray(body_poses, dtype=float)
        if body_poses.shape != (len(t), 4, 4):
            raise ValueError(
                f"extra body '{name}': poses must be ({len(t)}, 4, 4), got {body_poses.shape}"
            )
        node = ROOT.append(f"extra/{name}")
        packets.append(SetObject(obj, path=node).lower())
        animation.clips[node] = _clip(keys, body_poses[shown], fps)
    packets.append(SetAnimation(animation, play=True, repetitions=1).lower())

    commands = "\n".join(
        f'freefloat_command("{base64.b64encode(umsgpack.packb(p)).decode("ascii")}");'
        for p in packets
    )
    html = _PAGE.format(
        title=f"freefloat: {robot.urdf_path.name}",
        viewer_js=VIEWER_JS.read_text(),
        commands=commands,
    )
    path = Path(path)
    path.write_text(html, encoding="utf-8")
    return path


def _clip(keys: np.ndarray, poses: np.ndarray, fps: float) -> AnimationClip:
    """Position and quaternion ([x, y, z, w]) tracks of one node; ``keys`` in frames."""
    positions = [p[:3, 3].tolist() for p in poses]
    quaternions = [pin.Quaternion(p[:3, :3]).coeffs().tolist() for p in poses]
    return AnimationClip(
        tracks={
            "position": AnimationTrack("position", "vector3", keys.tolist(), positions),
            "quaternion": AnimationTrack("quaternion", "quaternion", keys.tolist(), quaternions),
        },
        fps=fps,
    )


def _object_packet(
    node: MeshcatPath, obj: mg.Object | DaeMeshGeometry, placement: np.ndarray
) -> dict:
    """A lowered ``set_object`` command at ``node`` with intrinsic matrix ``placement`` (4, 4)."""
    if isinstance(obj, DaeMeshGeometry):
        obj.path = node
        packet = obj.lower()
    else:
        packet = SetObject(obj, path=node).lower()
    packet["object"]["object"]["matrix"] = placement.T.flatten().tolist()  # three.js: column-major
    return packet


def _robot_objects(robot: Robot) -> list[tuple[int, str, mg.Object | DaeMeshGeometry, np.ndarray]]:
    """(joint id, name, meshcat object, placement in the joint frame incl. scale (4, 4))."""
    visual = robot.visual_model
    objects = [] if visual is None else [_visual_object(g) for g in visual.geometryObjects]
    objects = [o for o in objects if o is not None]
    return objects or _stick_figure(robot)


def _visual_object(
    geometry: pin.GeometryObject,
) -> tuple[int, str, mg.Object | DaeMeshGeometry, np.ndarray] | None:
    """Meshcat object of one Pinocchio geometry (mesh file or primitive), or None if unsupported."""
    suffix = Path(geometry.meshPath).suffix.lower()
    intrinsic = np.eye(4)
    if suffix == ".dae":  # keeps the Collada materials, textures embedded as data URIs
        obj = DaeMeshGeometry(geometry.meshPath)
    else:
        if suffix == ".stl":
            shape = mg.StlMeshGeometry.from_file(geometry.meshPath)
        elif suffix == ".obj":
            shape = mg.ObjMeshGeometry.from_file(geometry.meshPath)
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                shape = loadPrimitive(geometry)
        if shape is None:
            warnings.warn(
                f"geometry '{geometry.name}' cannot be drawn by meshcat; skipped", stacklevel=3
            )
            return None
        intrinsic = shape.intrinsic_transform()
        obj = mg.Mesh(shape, _material(_rgb_int(geometry.meshColor), float(geometry.meshColor[3])))
    scale = np.diag([*geometry.meshScale, 1.0])
    return (
        geometry.parentJoint,
        geometry.name,
        obj,
        geometry.placement.homogeneous @ scale @ intrinsic,
    )


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
