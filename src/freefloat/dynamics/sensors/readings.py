"""What a controller reads of a robot's state through its sensors: each channel group sampled every
``every`` control periods, with noise and bias, delivered ``delay`` periods later and held until
the next sample arrives; the momentum estimated from the readings when asked.

At control period ``k`` a group with sampling ``m`` and delay ``d`` shows the reading taken at
period ``s(k) = m floor((k - d) / m)`` (the latest sample that has arrived), and before the first
one arrives (``k < d``) the reading taken at period 0. A position reading is the true
configuration moved along the group's tangent, ``q (+) e`` (``pin.integrate``: on the Lie group of
the root joint, so the base pose stays a pose and a continuous joint stays on its circle); a rate
reading is ``v + e``; ``e = bias + noise * N(0, 1)``, drawn from one seeded ``numpy`` generator in
:data:`~.settings.GROUPS` order at each sample. An ideal group reads the true values unchanged.
"""

from __future__ import annotations

from collections import deque
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...arguments import real_number
from ...errors import BadShape, InvalidArgument
from ...robot.robot import Robot
from .momentum import MomentumEstimator
from .settings import GROUPS, Channel, SensorSettings

#: Component names of the base groups, by base kind: the tangent of the root joint (pose) and its
#: velocity (twist), in the base-link frame.
BASE_COMPONENTS = {"free": (("x", "y", "z", "rx", "ry", "rz"), ("vx", "vy", "vz", "wx", "wy", "wz")),
                   "planar": (("x", "y", "yaw"), ("vx", "vy", "wz"))}


class Measurement(NamedTuple):
    """What the controller reads at one control period.

    Attributes:
        q: measured configuration (nq,).
        v: measured velocity (nv,); with an estimator, its base rows are those that carry the
            estimated momentum with the measured joint rates (:meth:`MomentumEstimator.velocity`).
        momentum: the momentum map of the measured state ``[P; L_O]`` (6,) before the estimator
            (what a law computes from the readings without it), or None without an estimator.
        estimate: the estimator's ``[P; L_O]`` (6,), or None without one.
        spread: the estimate's standard deviations (6,), the square roots of its covariance's
            diagonal, or None without an estimator.
        reset: whether a reading restarted the estimator at this period.
    """

    q: np.ndarray
    v: np.ndarray
    momentum: np.ndarray | None
    estimate: np.ndarray | None
    spread: np.ndarray | None
    reset: bool


class _Group:
    """One channel group's pipeline: samples taken, in flight for ``delay`` periods, the one held."""

    def __init__(self, name: str, channel: Channel, model: pin.Model, values: slice, tangent: slice,
                 position: bool, components: tuple[str, ...]):
        self.name, self.channel, self.model = name, channel, model
        self.values, self.tangent, self.position = values, tangent, position
        self.noise = per_component(name, "noise", channel.noise, components)
        self.bias = per_component(name, "bias", channel.bias, components)
        self.exact = not (self.noise.any() or self.bias.any())
        self.in_flight: deque[tuple[int, np.ndarray]] = deque()
        self.held: np.ndarray | None = None
        self.held_at = -1

    def sample(self, k: int, q: np.ndarray, v: np.ndarray, rng: np.random.Generator) -> None:
        """Take this period's sample when one is due."""
        if k % self.channel.every:
            return
        if self.exact:
            reading = (q if self.position else v)[self.values].copy()
        else:
            error = self.bias + self.noise * rng.standard_normal(len(self.noise)) if self.noise.any() else self.bias
            if self.position:
                step = np.zeros(self.model.nv)
                step[self.tangent] = error
                reading = pin.integrate(self.model, q, step)[self.values]
            else:
                reading = v[self.values] + error
        self.in_flight.append((k, reading))

    def release(self, k: int) -> bool:
        """Hold the latest sample that has arrived by period k; True when it is a new one."""
        before = self.held_at
        while self.in_flight and self.in_flight[0][0] + self.channel.delay <= k:
            self.held_at, self.held = self.in_flight.popleft()
        if self.held is None:  # nothing has arrived yet: the first sample, taken at period 0
            self.held_at, self.held = self.in_flight[0]
        return self.held_at != before


def per_component(group: str, key: str, value: float | tuple[float, ...], components: tuple[str, ...]) -> np.ndarray:
    """A channel's ``noise`` or ``bias`` as one value per component (len(components),).

    Raises:
        BadShape: naming the group and its components when the count is neither 1 nor theirs.
    """
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return np.full(len(components), float(array))
    if array.shape != (len(components),):
        raise BadShape(f"sensors.{group}.{key} has {array.size} values; the group has {len(components)} components "
                       f"({', '.join(components)}): give one value or one per component")
    return array


class Sensors:
    """A robot's sensors at run time: the readings of each group (module docstring) and the
    momentum estimator, one control period at a time, in order.

    Args:
        robot: the robot whose state is read.
        settings: the channels, the estimator and the seed.
        control_period: s (the estimator's time between readings).
        rng: the noise's generator; by default ``numpy.random.default_rng(settings.seed)``.
    """

    def __init__(self, robot: Robot, settings: SensorSettings, control_period: float,
                 rng: np.random.Generator | None = None):
        model, nb = robot.model, robot.n_base
        nbq = model.nqs[1]
        self.robot, self.settings = robot, settings
        self.control_period = real_number("control_period", control_period, above=0.0)
        self.rng = np.random.default_rng(settings.seed) if rng is None else rng
        pose, twist = BASE_COMPONENTS[robot.base]
        joints = tuple(robot.joint_names)
        layout = {"base_pose": (slice(0, nbq), slice(0, nb), True, pose),
                  "base_twist": (slice(0, nb), slice(0, nb), False, twist),
                  "joint_position": (slice(nbq, model.nq), slice(nb, model.nv), True, joints),
                  "joint_rate": (slice(nb, model.nv), slice(nb, model.nv), False, joints)}
        channels = settings.channels()
        self.groups = [_Group(name, channels[name], model, *layout[name]) for name in GROUPS]
        self.estimator = None if settings.momentum is None else MomentumEstimator(
            robot, settings.momentum, self._noise(False), self._noise(True))
        self._pending = {"base_twist", "joint_rate"}  # rate groups not yet read since the estimator's last update
        self._updated_at = 0  # period of the samples the estimator last took
        self._v = np.zeros(0)  # the velocity handed to the law, recomputed on new readings
        self.periods = 0
        self.start_time: float | None = None

    def _noise(self, position: bool) -> np.ndarray:
        """Standard deviation of each tangent (position) or velocity coordinate's noise (nv,)."""
        return np.concatenate([g.noise for g in self.groups if g.position == position])

    def _period(self, t: float) -> int:
        """The index of the control period that starts at ``t`` (the next one in turn).

        Raises:
            InvalidArgument: when ``t`` is not the next period's start.
        """
        k, T = self.periods, self.control_period
        if self.start_time is None:
            self.start_time = t
        expected = self.start_time + k * T
        if abs(t - expected) > 1e-9 * max(1.0, abs(expected)):
            raise InvalidArgument(f"sensors are read once per control period of {T:g} s, in order: expected "
                                  f"t = {expected:.9g} s (period {k}), got t = {t:.9g} s (a law evaluated at "
                                  "every integrator stage cannot be sensed)")
        self.periods = k + 1
        return k

    def read(self, t: float, q: np.ndarray, v: np.ndarray) -> Measurement:
        """What the controller reads at the control period starting at ``t`` (each period in turn)
        of the true state at that time, q (nq,) and v (nv,).

        The estimator takes a reading once both rate groups have delivered a new sample since its
        previous one (so that no sample counts twice), at the time they were taken, and restarts
        from it when a known impulse (``restart``) fell after the previous one's.

        Raises:
            InvalidArgument: when ``t`` is not the next control period's start.
        """
        k = self._period(t)
        for group in self.groups:
            group.sample(k, q, v, self.rng)
        fresh = {group.name for group in self.groups if group.release(k)}
        base_pose, base_twist, joint_position, joint_rate = (g.held for g in self.groups)
        q_read = np.concatenate((base_pose, joint_position))
        v_read = np.concatenate((base_twist, joint_rate))
        estimator = self.estimator
        if estimator is None:
            return Measurement(q_read, v_read, None, None, None, False)
        reset = False
        if fresh:  # new readings: their momentum map, a filter update once both rates are new, the velocity
            estimator.read(q_read, v_read)
            self._pending -= fresh
            if not self._pending:
                taken, before = max(g.held_at for g in self.groups if not g.position), self._updated_at
                times = self.start_time + self.control_period * np.array([before, taken])
                known = any(times[0] < r <= times[1] + 1e-9 * self.control_period for r in estimator.settings.restart)
                reset = estimator.update(self.control_period * (taken - before), known)
                self._updated_at, self._pending = taken, {"base_twist", "joint_rate"}
            self._v = estimator.velocity()
        return Measurement(q_read, self._v, estimator.z.copy(), estimator.estimate.copy(),
                           estimator.spread(), reset)
