"""External wrenches: profiles on links (given in the inertial frame, applied at the link's CoM,
which the compiled loop applies natively), and any field of the environment that applies
wrenches depending on time and state (:class:`WrenchField`: orbit, thrusters, contact, a user's),
which the Python loop evaluates at every integrator stage, at the stage's own time."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument, did_you_mean
from ..robot.conventions import cross3
from ..robot.robot import Robot


class WrenchField(Protocol):
    """Wrenches the environment applies to a robot, at time ``t`` (s) and state ``q`` (nq,), ``v``
    (nv,) (Pinocchio's), evaluated by the loop at every integrator stage with the stage's own
    time and state (``t0 + c_i h`` of a Runge-Kutta stage, an adaptive step's trial times: not
    held over the control period, as the profiles are); several fields add up.

    A field may also give its own impulse and work over a run, ``impulse(t, q, v)`` and
    ``work(t, q, v)``: from the recorded rows (N,), (N, nq), (N, nv), ``[N s; N m s about the
    origin]`` (N, 6) and J (N,) from the first row to each, which the balances use instead of the
    trapezoidal rule over :meth:`wrench` and the power of :meth:`forces` (:mod:`.balance`; the
    thrusters' switch at every period, where the rule errs by half a period's impulse)."""

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> list[pin.Force] | None:
        """One ``pin.Force`` [f; n] per joint (``model.njoints``): joint-frame axes, moment about
        the joint origin (Pinocchio's ``fext`` of ``aba``); None: nothing at this instant."""
        ...

    def wrench(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The total it applies, ``[force (N); torque about the inertial origin (N m)]``, inertial
        frame (6,): what the momentum balance integrates."""
        ...


def field_forces(fields: Sequence[WrenchField], t: float, q: np.ndarray, v: np.ndarray,
                 base: list[pin.Force] | None = None) -> list[pin.Force] | None:
    """The sum of ``base`` (joint forces already applied, or None) and every field's forces at
    ``(t, q, v)``; None when nothing applies."""
    total = base
    for field in fields:
        forces = field.forces(t, q, v)
        if forces is None:
            continue
        total = list(forces) if total is None else [a + b for a, b in zip(total, forces)]
    return total


def field_power(model: pin.Model, data: pin.Data, forces: list[pin.Force]) -> float:
    """Power (W) of joint ``forces`` (as :meth:`WrenchField.forces` gives them) at the velocities
    ``data.v`` (joint frames, after ``pin.forwardKinematics`` with velocities)."""
    return float(sum(f.linear @ data.v[j].linear + f.angular @ data.v[j].angular
                     for j, f in enumerate(forces) if j > 0))


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


class WrenchProfiles:
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
                raise InvalidArgument(f"external wrench: link '{w.link}' does not exist{did_you_mean(w.link, links, 'links')}")
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
