"""The robots of the size sweeps (``gjm``, ``models``): the four-arm planar robot, the UR5
dual-arm satellite and 2 to 48 spatial 4-link arms around one base (nv 14 to 198), all on a
free-flyer base."""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator
from pathlib import Path

from ....paths import URDF_DIR
from ....robot.builders import ArmSpec, LinkSpec, RobotSpec, write_urdf
from ....robot.loading import load_robot
from ....robot.robot import Robot

#: The URDF robots of every size sweep.
NAMED = ("four_arm_planar", "dual_arm_satellite")
#: Arm counts of a size sweep (4 joints per arm: 8 to 192 joints), full and quick.
ARM_COUNTS = (2, 4, 8, 16, 32, 48)
QUICK_ARM_COUNTS = (2, 4)


def robot_names(arm_counts: tuple[int, ...]) -> list[str]:
    """The names :func:`robots` gives: :data:`NAMED`, then ``arms<n>`` per arm count."""
    return [*NAMED, *(f"arms{arms}" for arms in arm_counts)]


def multi_arm_robot(arms: int, folder: Path) -> Robot:
    """A free-floating robot with ``arms`` spatial 4-link arms evenly around a 10 kg base (links
    0.5 m, 2 kg, DH twists 90, 0, 90, 0 deg), written as URDF to ``folder`` and loaded."""
    links = tuple(LinkSpec(0.5, 2.0, (0.01, 0.05, 0.05), alpha=alpha) for alpha in (math.pi / 2, 0.0, math.pi / 2, 0.0))
    yaws = [2 * math.pi * i / arms for i in range(arms)]
    spec = RobotSpec(f"arms{arms}", 10.0, (0.6, 0.6, 0.6), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), tuple(
        ArmSpec(f"arm{i}", (0.5 * math.cos(y), 0.5 * math.sin(y), 0.0), (0.0, 0.0, y), links) for i, y in enumerate(yaws)))
    path = write_urdf(spec, folder / f"arms{arms}.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(path, visuals=False)


def robots(arm_counts: tuple[int, ...], folder: Path) -> Iterator[tuple[str, Robot]]:
    """``(name, robot)`` of each robot of :func:`robot_names`, loaded as it is reached (the
    generated URDFs written to ``folder``)."""
    for name in NAMED:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = load_robot(URDF_DIR / f"{name}.urdf", visuals=False)
        yield name, robot
    for arms in arm_counts:
        yield f"arms{arms}", multi_arm_robot(arms, folder)
