"""What a robot's sensors are: one :class:`Channel` per channel group (noise, bias, delay, sampling)
and the momentum estimator's settings, as frozen records whose fields are the keys of a scene's
``[sensors]`` section (:mod:`freefloat.app.scenes.sensor_section`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...arguments import real_array, real_number, whole_number
from ...errors import InvalidArgument

#: The channel groups of a robot's state, in the order their noise is drawn: the base pose (the
#: tangent of the root joint's configuration), the base twist (the root joint's velocity), the
#: joint positions (the tangent of the actuated joints' configuration) and the joint rates.
GROUPS = ("base_pose", "base_twist", "joint_position", "joint_rate")


@dataclass(frozen=True)
class Channel:
    """One channel group's sensor, in the group's coordinates (see :data:`GROUPS`): Pinocchio's
    velocity of the root joint ``[v; w]`` in the base-link frame (a planar base ``[vx, vy, wz]``),
    its configuration's tangent (the same components: a pose error ``exp([dp; dtheta])`` applied on
    the right, in the base-link frame), one component per joint degree of freedom for the joints.

    Attributes:
        noise: standard deviation of the zero-mean Gaussian noise drawn at each sample, one value
            for every component or one per component; m, rad, m/s, rad/s.
        bias: a constant offset added to every sample, one value or one per component, same units.
        delay: control periods between a sample and the control period that first reads it (>= 0).
        every: control periods between two samples (>= 1; 10 at a 1 ms control period: 100 Hz);
            a sample is held until the next one arrives (zero-order hold).
    """

    noise: float | tuple[float, ...] = 0.0
    bias: float | tuple[float, ...] = 0.0
    delay: int = 0
    every: int = 1

    def __post_init__(self) -> None:
        noise = real_array("noise", self.noise)
        if noise.ndim > 1 or (noise < 0.0).any():
            raise_bad("noise", self.noise, "a standard deviation >= 0, or one per component")
        if real_array("bias", self.bias).ndim > 1:
            raise_bad("bias", self.bias, "one number, or one per component")
        whole_number("delay", self.delay, low=0)
        whole_number("every", self.every, low=1)

    @property
    def ideal(self) -> bool:
        """Whether the channel reads the truth at every period: no noise, no bias, no delay, every period."""
        return (self.delay, self.every) == (0, 1) and not (real_array("noise", self.noise).any()
                                                          or real_array("bias", self.bias).any())


@dataclass(frozen=True)
class MomentumKalman:
    """The momentum estimator's settings (:mod:`.momentum`): a Kalman filter on the momentum about
    the inertial origin, constant between impulses up to a random walk.

    An impulse the controller knows of (its own capture, a thruster it fires) is a ``restart``
    time: the first reading taken at or after it restarts the filter. One it does not know of is
    caught by the gate when it moves the momentum by several standard deviations of one reading;
    a smaller one is absorbed at the filter's gain (slowly, once many readings are averaged).

    Attributes:
        linear_process_noise: the random walk's intensity on the linear momentum, N s / sqrt(s)
            (the standard deviation of the unmodelled change over 1 s), > 0.
        angular_process_noise: the same on the angular momentum about the origin, N m s / sqrt(s), > 0.
        false_alarm: the probability that noise alone makes a reading restart the filter, in
            (0, 1): the gate on the normalised innovation squared is the chi-square quantile of
            the conserved components' count at it.
        restart: times of known impulses, s (the filter restarts from the first reading taken at
            or after each).
    """

    linear_process_noise: float = 1e-3
    angular_process_noise: float = 1e-3
    false_alarm: float = 1e-6
    restart: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        for name in ("linear_process_noise", "angular_process_noise"):
            real_number(name, getattr(self, name), above=0.0)
        if not real_number("false_alarm", self.false_alarm, above=0.0) < 1.0:
            raise_bad("false_alarm", self.false_alarm, "a probability below 1")
        if real_array("restart", self.restart).ndim != 1:
            raise_bad("restart", self.restart, "a sequence of times in s")


@dataclass(frozen=True)
class SensorSettings:
    """A robot's sensors: one :class:`Channel` per group of :data:`GROUPS`, the momentum estimator
    (None: a law that reads the momentum computes it from the measured state, as it does from the
    true one), and the seed of the noise.

    Attributes:
        base_pose, base_twist, joint_position, joint_rate: the channel groups (ideal by default).
        momentum: the estimator's settings, or None.
        seed: seed of the noise's ``numpy.random.Generator``.
    """

    base_pose: Channel = field(default_factory=Channel)
    base_twist: Channel = field(default_factory=Channel)
    joint_position: Channel = field(default_factory=Channel)
    joint_rate: Channel = field(default_factory=Channel)
    momentum: MomentumKalman | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        for name in GROUPS:
            if not isinstance(getattr(self, name), Channel):
                raise_bad(name, getattr(self, name), "a Channel")
        if self.momentum is not None and not isinstance(self.momentum, MomentumKalman):
            raise_bad("momentum", self.momentum, "a MomentumKalman or None")
        whole_number("seed", self.seed, low=0)

    def channels(self) -> dict[str, Channel]:
        """The channel of each group, in :data:`GROUPS` order."""
        return {name: getattr(self, name) for name in GROUPS}

    @property
    def ideal(self) -> bool:
        """Whether every channel is ideal and no estimator runs: the law then sees the true state."""
        return self.momentum is None and all(c.ideal for c in self.channels().values())


def raise_bad(name: str, value: object, expected: str) -> None:
    """Refuse a setting.

    Raises:
        InvalidArgument: naming the setting, what it must be and what it was.
    """
    raise InvalidArgument(f"sensor setting '{name}' must be {expected}, got {value!r}")
