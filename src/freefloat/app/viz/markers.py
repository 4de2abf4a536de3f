"""Points a page follows besides the bodies (a sphere moving along a drawn path), and bars
between moving points (a closed chain's links).

For a robot: the base CoM, the system CoM and each end-effector; for a mechanism: the two
points of each closure, the platform point, its joint centres and the bars joining them.
Positions are in the inertial frame, m.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...robot.robot import Robot

#: Colours (0xRRGGBB): base CoM, system CoM, then end-effectors or closure points in turn.
BASE_COM_COLOR = 0x404040
SYSTEM_COM_COLOR = 0x20A040
PALETTE = (0xD02020, 0x8030C0, 0xE07000, 0x0090B0, 0xC02080, 0x607000)


class Marker(NamedTuple):
    """A followed point.

    Attributes:
        name: node name in the page (``/meshcat/freefloat/markers/<name>``).
        color: 0xRRGGBB of its sphere and path.
        positions: the point at each sample, inertial frame, m (N, 3).
        trail: whether its whole path is drawn too (a joint centre's is not).
    """

    name: str
    color: int
    positions: np.ndarray
    trail: bool = True


class Bar(NamedTuple):
    """A rigid or telescopic link drawn as a thin cylinder between two moving points.

    Attributes:
        name: node name in the page (``/meshcat/freefloat/bars/<name>``).
        color: 0xRRGGBB.
        start: one end at each sample, inertial frame, m (N, 3).
        end: the other end at each sample, inertial frame, m (N, 3).
    """

    name: str
    color: int
    start: np.ndarray
    end: np.ndarray


def robot_markers(robot: Robot, q: np.ndarray) -> list[Marker]:
    """Base CoM, system CoM and end-effector origins of the robot at configurations ``q`` (N, nq)."""
    model = robot.model
    data = model.createData()
    n = len(q)
    base, system = np.empty((n, 3)), np.empty((n, 3))
    ends = np.empty((len(robot.end_effectors), n, 3))
    for k, qk in enumerate(q):
        system[k] = pin.centerOfMass(model, data, qk)  # also runs forward kinematics
        base[k] = data.oMi[1].act(model.inertias[1].lever)
        for e, frame_id in enumerate(robot.end_effector_frame_ids):
            ends[e, k] = pin.updateFramePlacement(model, data, frame_id).translation
    markers = [Marker("base_com", BASE_COM_COLOR, base), Marker("system_com", SYSTEM_COM_COLOR, system)]
    return markers + [
        Marker(f"end_effector_{name}", PALETTE[e % len(PALETTE)], ends[e])
        for e, name in enumerate(robot.end_effectors)
    ]
