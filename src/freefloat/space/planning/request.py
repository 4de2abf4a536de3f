"""What a pre-capture plan is asked for (dissertation sec 3.8, the pre-capture phase): the robot and
its start, the end-effector, the target's grasp-point flight, the grasp instant and the limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument, did_you_mean
from ...robot.robot import Robot
from .grasp_motion import GraspMotion


@dataclass(frozen=True)
class Limits:
    """Per-joint limits of a plan, actuated joint order.

    Attributes:
        joint_rate: largest |qdot| per joint, rad/s or m/s (n,).
        torque: largest |tau| per joint, N m or N (n,).
    """

    joint_rate: np.ndarray
    torque: np.ndarray

    @classmethod
    def of(cls, robot: Robot, joint_rate: float | None = None, torque: float | None = None) -> Limits:
        """``joint_rate`` and ``torque`` for every joint, or where None the URDF's ``<limit
        velocity effort>`` (Pinocchio's ``velocityLimit``, ``effortLimit``).

        Raises:
            InvalidArgument: for a limit that is not > 0 (given, or read from the URDF).
        """
        nb = robot.n_base
        rate = robot.model.velocityLimit[nb:] if joint_rate is None else np.full(robot.n_joints, float(joint_rate))
        effort = robot.model.effortLimit[nb:] if torque is None else np.full(robot.n_joints, float(torque))
        for name, values in (("joint rate", rate), ("torque", effort)):
            bad = np.flatnonzero(~(np.asarray(values) > 0.0))
            if bad.size:
                raise InvalidArgument(f"{name} limit of joint '{robot.joint_names[bad[0]]}' is {values[bad[0]]}; it "
                                      "must be > 0 (set it in the URDF's <limit> or give one)")
        return cls(np.array(rate, float), np.array(effort, float))


#: Most intervals of a planning grid: a plan keeps each step's state and Jacobians (about a
#: kilobyte a joint a step), and a minute of approach at 1 ms is 60,000.
MAX_STEPS = 100_000


@dataclass(frozen=True)
class ApproachRequest:
    """A pre-capture approach: bring each of ``end_effectors`` onto its grasp point at
    ``duration`` s with the grasp point's velocity (one hand, or two grasping one target at once).

    Attributes:
        robot: the free-floating robot.
        q0, v0: its state when the approach starts (t = 0), Pinocchio's (nq,), (nv,).
        end_effectors: the grippers' frames (of ``robot.end_effectors``), one per grasp point.
        grasps: each grasp point's flight, time from the approach's start.
        duration: the grasp instant T, s (the deadline).
        limits: joint-rate and torque limits.
        joints: the mission joints, indices into the actuated joints (None: all).
        steps: intervals of the planning grid over [0, T] (4 to :data:`MAX_STEPS`).
        gain: closed-loop gain of the resolved-rate laws on the task position error, 1/s.
        tolerance: largest grasp-point position mismatch at T the plan may leave (each hand), m.
        velocity_tolerance: largest grasp-point velocity mismatch at T (each hand), m/s.
        match: ``"position"`` (the grasp point's position and velocity) or ``"pose"`` (also the
            grasp frame's orientation and angular velocity: each hand's frame onto its handle).
        angle_tolerance: largest orientation mismatch at T with ``"pose"``, rad.
        angular_velocity_tolerance: largest angular velocity mismatch at T with ``"pose"``, rad/s.
    """

    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    end_effectors: tuple[str, ...]
    grasps: tuple[GraspMotion, ...]
    duration: float
    limits: Limits
    joints: np.ndarray | None = None
    steps: int = 200
    gain: float = 20.0
    tolerance: float = 1e-4
    velocity_tolerance: float = 1e-3
    match: str = "position"
    angle_tolerance: float = 1e-3
    angular_velocity_tolerance: float = 1e-2

    def __post_init__(self):
        if self.match not in MATCHES:
            raise InvalidArgument(f"approach: 'match' must be one of {', '.join(MATCHES)}, got {self.match!r}")
        for name in self.end_effectors:
            if name not in self.robot.end_effectors:
                raise InvalidArgument(f"approach: '{name}' is not an end-effector"
                                      f"{did_you_mean(name, self.robot.end_effectors, 'end-effectors')}")
        if len(self.grasps) != len(self.end_effectors) or len(set(self.end_effectors)) != len(self.end_effectors):
            raise InvalidArgument(f"approach: one grasp point per end-effector, each hand once; got hands "
                                  f"{list(self.end_effectors)} and {len(self.grasps)} grasp points")
        if not self.duration > 0.0:
            raise InvalidArgument(f"approach: the grasp instant must be > 0 s after the start, got {self.duration}")
        if isinstance(self.steps, bool) or not isinstance(self.steps, (int, np.integer)) \
                or not 4 <= self.steps <= MAX_STEPS:
            raise InvalidArgument(f"approach: 'steps' must be an integer from 4 to {MAX_STEPS:,} (the plan keeps every "
                                  f"step's state and Jacobians), got {self.steps!r}")
        if self.joints is not None:
            joints = np.asarray(self.joints)
            names = self.robot.joint_names
            if joints.ndim != 1 or joints.dtype.kind not in "iu" or not np.all((0 <= joints) & (joints < len(names))):
                raise InvalidArgument(f"approach: the mission joints must be indices into the {len(names)} actuated "
                                      f"joints, got {self.joints!r}")
            twice = sorted({names[j] for j in joints if np.count_nonzero(joints == j) > 1})
            if twice:
                raise InvalidArgument(f"approach: mission joint(s) {', '.join(repr(n) for n in twice)} given twice; "
                                      "name each joint once")

    @property
    def times(self) -> np.ndarray:
        """The planning grid over [0, T] (steps + 1,), s."""
        return np.linspace(0.0, self.duration, self.steps + 1)

    @property
    def frames(self) -> tuple[int, ...]:
        """Pinocchio frame ids of the end-effectors."""
        return tuple(self.robot.model.getFrameId(name) for name in self.end_effectors)

    def task_components(self) -> np.ndarray:
        """The position components the plan matches: x, y on a planar base, x, y, z on a free one."""
        return np.arange(2 if self.robot.base == "planar" else 3)

    def angular_components(self) -> np.ndarray:
        """The orientation components the plan matches: none for ``"position"``; z on a planar
        base, x, y, z on a free one for ``"pose"``."""
        if self.match == "position":
            return np.arange(0)
        return np.array([2]) if self.robot.base == "planar" else np.arange(3)

    @property
    def matched(self) -> np.ndarray:
        """Which entries of :meth:`grasp_errors`' (4, 3) block per hand the plan must zero (4, 3)."""
        mask = np.zeros((4, 3), bool)
        mask[:2, self.task_components()] = True
        mask[2:, self.angular_components()] = True
        return mask

    @property
    def tolerances(self) -> np.ndarray:
        """The tolerance of each row of :meth:`grasp_errors`' block (4,): m, m/s, rad, rad/s."""
        return np.array([self.tolerance, self.velocity_tolerance, self.angle_tolerance,
                         self.angular_velocity_tolerance])

    def arm_reach(self, k: int) -> tuple[float, float]:
        """``(distance, reach)`` of hand ``k`` at the start: from its arm's first joint to its grasp
        point at T, and the arm's reach (:func:`arm_reach`), m, for the out-of-reach message."""
        shoulder, reach = arm_reach(self.robot, self.q0, self.end_effectors[k])
        return float(np.linalg.norm(self.grasps[k].at(self.duration)[0] - shoulder)), reach

    def grasp_errors(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Each hand's mismatch with its grasp frame at T, at the state (q, v): rows ``[p_E - p_g,
        v_E - v_g, log(R_E R_g^T), w_E - w]`` per hand (k, 4, 3), m, m/s, rad, rad/s, inertial;
        the entries the plan does not match (:attr:`matched`) are zero."""
        model, data = self.robot.model, self.robot.model.createData()
        pin.forwardKinematics(model, data, q, v)
        out = []
        for frame, grasp in zip(self.frames, self.grasps):
            p_g, v_g, _ = grasp.at(self.duration)
            placement = pin.updateFramePlacement(model, data, frame)
            twist = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            out.append((placement.translation - p_g, twist.linear - v_g,
                        pin.log3(placement.rotation @ grasp.orientation(self.duration).T),
                        twist.angular - grasp.angular_velocity))
        return np.where(self.matched, np.array(out), 0.0)


#: What a plan matches at the grasp: see :class:`ApproachRequest`.
MATCHES = ("position", "pose")


def arm_reach(robot: Robot, q: np.ndarray, end_effector: str) -> tuple[np.ndarray, float]:
    """``(shoulder, reach)``: the position of the end-effector arm's first joint at configuration
    q (inertial, m (3,)) and the sum of the arm's joint-to-joint and joint-to-end-effector lengths
    (m)."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    arm = robot.arms[robot.end_effectors.index(end_effector)]
    points = [data.oMi[model.getJointId(name)].translation for name in arm.joints]
    points.append(data.oMf[model.getFrameId(end_effector)].translation)
    return points[0].copy(), float(sum(np.linalg.norm(b - a) for a, b in zip(points, points[1:])))
