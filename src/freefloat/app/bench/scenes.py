"""Bench scenes: a robot tumbling torque-free from a seeded random state with non-zero momentum."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument, did_you_mean
from ...robot.loading import load_robot
from ...robot.robot import Robot
from .mjcf import balanced_model


@dataclass(frozen=True)
class TumblingScene:
    """A torque-free run of one robot.

    Attributes:
        name: scene name.
        robot: the robot both sides simulate, with a balanced copy of its model when the URDF's
            inertias break the triangle inequality (see :func:`.mjcf.balanced_model`).
        q0: initial configuration (nq,), Pinocchio's convention.
        v0: initial velocity (nv,), Pinocchio's convention (base twist local).
        duration: simulated time, s.
    """

    name: str
    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    duration: float

    @property
    def model(self) -> pin.Model:
        """The Pinocchio free-flyer model both sides simulate."""
        return self.robot.model


#: Built-in bench scenes: name -> (robot, note).
SCENES = {
    "four_arm": ("four_arm_planar", "four-arm robot with a free base; inertias balanced (MuJoCo refuses the URDF's)"),
    "dual_arm": ("dual_arm_satellite", "UR5 dual-arm satellite"),
}


def random_state(model: pin.Model, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Seeded state: joints uniform in +-0.5 rad; base rates and joint rates normal with 0.5 rad/s
    standard deviation, base linear velocity with 0.05 m/s (so the momentum is non-zero)."""
    rng = np.random.default_rng(seed)
    q = pin.neutral(model)
    q[7:] = rng.uniform(-0.5, 0.5, model.nq - 7)
    v = np.concatenate([rng.normal(0.0, 0.05, 3), rng.normal(0.0, 0.5, 3), rng.normal(0.0, 0.5, model.nv - 6)])
    return q, v


def tumbling_scene(name: str, duration: float = 1.0, seed: int = 0) -> TumblingScene:
    """The bench scene ``name`` (see :data:`SCENES`).

    Raises:
        InvalidArgument: unknown name (lists the valid ones) or a duration that is not > 0.
    """
    if name not in SCENES:
        raise InvalidArgument(f"unknown bench scene '{name}'{did_you_mean(name, SCENES)}")
    if not duration > 0.0:
        raise InvalidArgument(f"duration must be > 0 s, got {duration}")
    robot = load_robot(SCENES[name][0], base="free", visuals=False)
    robot = replace(robot, model=balanced_model(robot.model))
    q0, v0 = random_state(robot.model, seed)
    return TumblingScene(name, robot, q0, v0, duration)
