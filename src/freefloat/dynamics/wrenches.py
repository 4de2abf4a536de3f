"""External wrenches on links, given in the inertial frame and applied at the link's CoM."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import FreefloatError, did_you_mean
from ..robot.conventions import cross3
from ..robot.robot import Robot


@dataclass(frozen=True)
class ExternalWrench:
    """A wrench on one link during [start, end), rising linearly over ``rise`` s, then constant
    (sampled at the start of each control period: zero-order hold).

    Attributes:
        link: URDF link name.
        force: force, inertial frame, N (3,).
        torque: torque, inertial frame, N m (3,), the force acting at the link's CoM.
        start: time it starts, s.
        end: time it stops, s.
        rise: duration of the linear ramp from 0 to the full wrench, s (0: a step).
    """

    link: str
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)
    start: float = 0.0
    end: float = float("inf")
    rise: float = 0.0

    def scale(self, t: float) -> float:
        """Profile at time t: 0 outside [start, end), a linear rise over ``rise`` s, then 1."""
        if not self.start <= t < self.end:
            return 0.0
        return 1.0 if self.rise <= 0.0 else min(1.0, (t - self.start) / self.rise)


class WrenchField:
    """Joint-local ``pin.Force`` list for the wrenches active at a given time.

    The inertial components are rotated into each joint frame at the current configuration, so an
    integrator calls :meth:`forces` at every stage.

    Raises:
        FreefloatError: naming a link that does not exist.
    """

    def __init__(self, robot: Robot, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench]):
        self.model = robot.model
        self.data = robot.model.createData()
        self._items = []
        links = [f.name for f in robot.model.frames if f.type == pin.FrameType.BODY]
        for w in wrenches:
            if w.link not in links:
                raise FreefloatError(f"external wrench: link '{w.link}' does not exist{did_you_mean(w.link, links, 'links')}")
            frame = robot.model.frames[robot.model.getFrameId(w.link, pin.FrameType.BODY)]
            com_in_joint = frame.placement.act(robot.link_coms[w.link])
            self._items.append((w, frame.parentJoint, com_in_joint, np.asarray(w.force, float), np.asarray(w.torque, float)))
        self._active: list = []

    def activate(self, t: float) -> bool:
        """Select the wrenches active at time t, with their profile value; return whether any is."""
        scaled = ((item, item[0].scale(t)) for item in self._items)
        self._active = [(item, scale) for item, scale in scaled if scale > 0.0]
        return bool(self._active)

    def active(self) -> tuple[list[int], np.ndarray, np.ndarray, np.ndarray]:
        """The active set as arrays: parent joints (k,), CoMs in their joint frames (k, 3), m, and
        the inertial forces (k, 3), N, and torques (k, 3), N m, scaled by their profiles."""
        items = [(joint, com, scale * force, scale * torque) for (_, joint, com, force, torque), scale in self._active]
        if not items:
            return [], np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3))
        joints, coms, forces, torques = zip(*items)
        return list(joints), np.array(coms), np.array(forces), np.array(torques)

    def profiles(self) -> tuple[list[int], np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every wrench as data, for the compiled loop: parent joints (k,), CoMs in their joint
        frames (k, 3), m, inertial forces (k, 3), N, and torques (k, 3), N m, at profile value 1,
        and the profiles' start, end and rise (k,), s."""
        if not self._items:
            return [], *(np.zeros((0, 3)),) * 3, *(np.zeros(0),) * 3
        wrenches, joints, coms, forces, torques = zip(*self._items)
        return (list(joints), np.array(coms), np.array(forces), np.array(torques),
                *(np.array([getattr(w, key) for w in wrenches], dtype=float) for key in ("start", "end", "rise")))

    def forces(self, q: np.ndarray) -> list[pin.Force]:
        """Wrenches of the active set, one ``pin.Force`` [f; n] per joint (njoints): joint-frame
        axes, moment about the joint-frame origin."""
        pin.forwardKinematics(self.model, self.data, q)
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for joint, com, force, torque in zip(*self.active()):
            R = self.data.oMi[joint].rotation
            f_local = R.T @ force
            out[joint] += pin.Force(f_local, R.T @ torque + cross3(com, f_local))
        return out
