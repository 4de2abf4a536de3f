"""The meshcat page of a closed-chain mechanism run (a mechanism scene), without the plotting stack.

The page draws the linkage as the thesis's figures do: a thin bar for each link, between the
centres of the joints it joins (and from a chain's last joint to its closure point), a dark
sphere at each joint centre, the base (the URDF's root link: the 5R's bar between its pivots,
the 2RSU+PPaP's plate), the platform point with its path and the reference path (dashed). The
bars follow the spanning tree's forward kinematics at the chains' joints of each sample, so the
loop closes because the simulated joints satisfy the closure; each closure's two points are
followed too (sphere and path): where they part, the loop has come apart.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin

from ...parallel.closed_chain import ClosedChain
from ...robot.joints import slides
from ...robot.loading import load_robot
from .camera import PLANE_VIEW
from .markers import PALETTE, Bar, Marker
from .meshcat_html import write_trajectory_html

#: Colours (0xRRGGBB) of the page: bars, joint centres, the platform point, the reference path.
BAR_COLOR, JOINT_COLOR, PLATFORM_COLOR, REFERENCE_COLOR = 0x2F5FA8, 0x303030, 0x20A040, 0x808080
#: Offsets below this are no link, m (the coincident joints of a spherical or universal joint).
_APART = 1e-9


def write_mechanism_html(chain: ClosedChain, t: np.ndarray, q: np.ndarray, path: str | Path, fps: float,
                         reference: np.ndarray | None = None, base: np.ndarray | None = None,
                         extra: list | None = None) -> Path:
    """Self-contained meshcat page of a mechanism run: the linkage (:func:`linkage_bars`,
    :func:`joint_markers`), the platform point and its path, the closure points
    (:func:`closure_markers`) and the reference path; a planar mechanism (two platform
    coordinates) seen from above (:data:`.camera.PLANE_VIEW`), a spatial one obliquely.

    Args:
        chain: the mechanism loaded from its closure file; its URDF gives the base drawn, and
            it maps Orsino's coordinates to the spanning tree's joints.
        t: sample times, s (N,).
        q: Orsino's coordinates ``[q#; q°]`` (N, n_q); q# are the platform point's x, y (, z).
        path: output ``.html`` file.
        fps: animation frames per second of simulated time.
        reference: the platform reference q#_d (N, p), drawn as a dashed path; None: none.
        base: a moving base's placement at each sample (N, 4, 4), inertial frame: ``q`` and
            ``reference`` are then in the base frame, and the base, linkage, markers and paths
            are drawn where the base carries them; None: a fixed base.
        extra: further bodies, as :func:`~.meshcat_html.write_trajectory_html` takes them
            (e.g. a map's point cloud, ``(name, object, poses (N, 4, 4))``).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(chain.urdf, base="free")
    tree, model = chain.model, robot.model
    tree_q = np.array([chain.pinocchio_q(qk) for qk in q]).reshape(len(t), tree.nq)
    configurations = np.tile(robot.neutral(), (len(t), 1))
    for j in range(1, tree.njoints):  # same URDF, so the same joint names; the robot adds its base
        start, size = model.idx_qs[model.getJointId(tree.names[j])], tree.nqs[j]
        configurations[:, start:start + size] = tree_q[:, tree.idx_qs[j]:tree.idx_qs[j] + size]
    if base is not None:  # the robot's free flyer is the root link's placement
        configurations[:, :7] = [pin.SE3ToXYZQUAT(pin.SE3(pose)) for pose in base]
    p = chain.mechanism.p
    carried = (lambda points: points) if base is None else (lambda points: _carried(base, points))
    platform = Marker("platform", PLATFORM_COLOR, carried(_padded(np.asarray(q, float)[:, :p])))
    lines = []
    if reference is not None and np.isfinite(reference).all():
        lines.append(("platform_reference", REFERENCE_COLOR, carried(_padded(np.asarray(reference, float)))))
    markers = [m._replace(positions=carried(m.positions)) for m in joint_markers(chain, tree_q) + closure_markers(chain, tree_q)]
    bars = [b._replace(start=carried(b.start), end=carried(b.end)) for b in linkage_bars(chain, tree_q)]
    return write_trajectory_html(robot, t, configurations, path, fps=fps, markers=markers + [platform],
                                 bars=bars, lines=lines, view=PLANE_VIEW if p < 3 else None, extra=extra)


def _carried(base: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points given in the base frame at each sample (N, 3) in the inertial frame, the base at
    ``base`` (N, 4, 4)."""
    return np.einsum("nij,nj->ni", base[:, :3, :3], points) + base[:, :3, 3]


def _padded(points: np.ndarray) -> np.ndarray:
    """Platform coordinates x, y (, z) (N, p) as points (N, 3), z = 0 for a planar mechanism."""
    return np.pad(points, ((0, 0), (0, 3 - points.shape[1])))


def _joint_centres(chain: ClosedChain, tree_q: np.ndarray) -> np.ndarray:
    """Every tree joint's centre (its frame's origin) at each configuration, inertial frame, m
    (N, njoints, 3); joint 0 is the world origin."""
    model, data = chain.model, chain.model.createData()
    out = np.zeros((len(tree_q), model.njoints, 3))
    for k, qk in enumerate(tree_q):
        pin.forwardKinematics(model, data, qk)
        out[k] = [m.translation for m in data.oMi]
    return out


def linkage_bars(chain: ClosedChain, tree_q: np.ndarray) -> list[Bar]:
    """The mechanism's links as bars at the spanning tree's configurations ``tree_q`` (N, nq),
    inertial frame, m: from each joint's parent joint centre to its centre (a link; telescopic
    behind a prismatic joint), from a prismatic joint on the base to where it slides from (the
    rail), and from each closure frame's joint centre to the closure point. Joints at one point
    (a spherical joint's three axes) make no bar; a revolute joint on the base starts none (the
    base is drawn from the URDF)."""
    model = chain.model
    centres = _joint_centres(chain, tree_q)
    bars = []
    for j in range(1, model.njoints):
        parent = model.parents[j]
        if parent > 0:
            start = centres[:, parent]
        elif slides(model.joints[j]):
            start = np.tile(model.jointPlacements[j].translation, (len(tree_q), 1))
        else:
            continue
        if np.linalg.norm(centres[:, j] - start, axis=1).max() > _APART:
            bars.append(Bar(f"{model.names[parent]}_to_{model.names[j]}", BAR_COLOR, start, centres[:, j]))
    for marker, joint in zip(closure_markers(chain, tree_q), _closure_joints(chain)):
        if np.linalg.norm(marker.positions - centres[:, joint], axis=1).max() > _APART:
            bars.append(Bar(f"{model.names[joint]}_to_{marker.name}", BAR_COLOR, centres[:, joint], marker.positions))
    return bars


def joint_markers(chain: ClosedChain, tree_q: np.ndarray) -> list[Marker]:
    """A dark sphere, without trail, at each distinct joint centre (one for the coincident axes
    of a spherical or universal joint), inertial frame, m (N, 3)."""
    model = chain.model
    centres = _joint_centres(chain, tree_q)
    return [Marker(f"joint_{model.names[j]}", JOINT_COLOR, centres[:, j], trail=False)
            for j in range(1, model.njoints)
            if model.parents[j] == 0 or slides(model.joints[j])
            or np.linalg.norm(model.jointPlacements[j].translation) > _APART]


def _closure_joints(chain: ClosedChain) -> list[int]:
    """The tree joint of each closure point, in :func:`closure_markers`' order."""
    return [getattr(c, f"joint{side}_id") for c in chain.constraints for side in (1, 2)]


def closure_markers(chain: ClosedChain, tree_q: np.ndarray) -> list[Marker]:
    """Both points of every closure (the constraint frames' origins, inertial frame, m (N, 3)) at
    the spanning tree's configurations ``tree_q`` (N, nq)."""
    model, data = chain.model, chain.model.createData()
    sides = [(i, side, getattr(c, f"joint{side}_id"), getattr(c, f"joint{side}_placement"))
             for i, c in enumerate(chain.constraints) for side in (1, 2)]
    points = np.empty((len(sides), len(tree_q), 3))
    for k, qk in enumerate(tree_q):
        pin.forwardKinematics(model, data, qk)
        for s, (_, _, joint, placement) in enumerate(sides):
            points[s, k] = data.oMi[joint].act(placement.translation)
    return [Marker(f"closure{i}_{model.names[joint]}", PALETTE[s % len(PALETTE)], points[s])
            for s, (i, _, joint, _) in enumerate(sides)]
