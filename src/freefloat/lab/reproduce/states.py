"""Random states with a prescribed momentum, for model comparisons."""

from __future__ import annotations

import numpy as np

from ...dynamics import gjm
from ...dynamics.verify import random_configuration
from ...robot.conventions import base_state, state_from_base
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot


def state_with_momentum(robot: Robot, rng: np.random.Generator, P: np.ndarray | None = None,
                        L: np.ndarray | None = None, joint_range: float = 1.5) -> tuple[np.ndarray, np.ndarray]:
    """A random state (free-flyer base) whose momentum about the base CoM is ``[P; L]``.

    Base pose random in a unit box, joints uniform in ``[-joint_range, joint_range]``, joint rates
    N(0, 1); the base twist is then solved from ``H0 x0dot + H0m qdot = [P; L]`` (default zero).
    """
    q = random_configuration(robot, rng, JointCoordinates(robot), box=1.0, joint_range=joint_range)
    qdot = rng.normal(size=robot.n_joints)
    s = gjm.compute(robot, q, np.concatenate((np.zeros(6), qdot)))
    M = np.concatenate((np.zeros(3) if P is None else P, np.zeros(3) if L is None else L))
    x0dot = np.linalg.solve(s.H0, M - s.H0m @ qdot)
    r0, R0, _ = base_state(robot, q, np.zeros(robot.model.nv))
    return state_from_base(robot, r0, R0, x0dot, q[7:], qdot)
