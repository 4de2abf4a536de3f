"""A controller that reads the robot's state through sensors: the composition ``Sensed(controller,
sensors)`` hands the law, at each control period, the measured state instead of the true one and
records what it handed (the truth is the run's telemetry).

Laws that read the system momentum compute it from the state they are handed:
``DetumblingController`` (eq 134) through ``gjm.compute(robot, q, v).momentum_base``
(``M = H0 x0dot + H0m qdot``, eq 69) and ``LoopDetumblingController`` through ``(M v)_b`` and
the same GJM momentum. With an estimator, the handed state's base rates are those that carry the
estimated momentum with the measured joint rates, so both laws read the estimate unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...arguments import whole_number
from .readings import Measurement, Sensors


@dataclass(frozen=True)
class SensorRecord:
    """What the controller read, one row per recorded control period (N rows).

    Attributes:
        t: period start, s (N,).
        q: measured configuration (N, nq).
        v: measured velocity handed to the law (N, nv).
        momentum: momentum map of the measured state ``[P; L_O]`` (N, 6), inertial frame, kg m/s and
            kg m^2/s (NaN without an estimator).
        estimate: the estimator's ``[P; L_O]`` (N, 6) (NaN without one).
        spread: the estimate's standard deviations (N, 6) (NaN without an estimator).
        reset: whether a reading restarted the estimator (N,).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    momentum: np.ndarray
    estimate: np.ndarray
    spread: np.ndarray
    reset: np.ndarray


@dataclass
class SensorLog:
    """Rows of a :class:`SensorRecord` as they come (see :meth:`record`)."""

    t: list[float] = field(default_factory=list)
    measurements: list[Measurement] = field(default_factory=list)

    def record(self) -> SensorRecord:
        """The rows as arrays."""
        rows = self.measurements

        def stacked(name: str) -> np.ndarray:
            """One field of every row (N, 6), NaN where it is None."""
            return np.array([np.full(6, np.nan) if getattr(m, name) is None else getattr(m, name)
                             for m in rows]).reshape(-1, 6)

        return SensorRecord(np.array(self.t), np.array([m.q for m in rows]), np.array([m.v for m in rows]),
                            stacked("momentum"), stacked("estimate"), stacked("spread"),
                            np.array([m.reset for m in rows], dtype=bool))


class Sensed:
    """``controller`` fed the readings of ``sensors`` (:class:`~.readings.Sensors`).

    The loop calls :meth:`torque` once per control period, in order (as
    :func:`freefloat.dynamics.simulation.run` does); a call at another time is refused. With every
    channel ideal and no estimator the law sees the true state, and :meth:`compiled_law` hands the
    compiled loop the controller's own law (the run is then today's, and nothing is recorded);
    otherwise there is no compiled twin and the law runs in Python.

    Args:
        controller: anything with ``torque(t, q, v)`` and ``reference(t)``.
        sensors: the robot's sensors (one run: they keep the samples in flight).
        record_every: record every this many control periods (0: none).

    Attributes:
        log: what the controller read (:meth:`SensorLog.record` as arrays).
    """

    def __init__(self, controller: Any, sensors: Sensors, record_every: int = 1):
        self.controller, self.sensors = controller, sensors
        self.record_every = whole_number("record_every", record_every, low=0)
        self.log = SensorLog()

    @property
    def robot(self) -> Any:
        """The controller's robot, if it has one (what the compiled loop checks its law against)."""
        return getattr(self.controller, "robot", None)

    def compiled_law(self) -> Any:
        """The controller's compiled law when the sensors are ideal, else None."""
        if not self.sensors.settings.ideal:
            return None
        return getattr(self.controller, "compiled_law", lambda: None)()

    def reference(self, t: float) -> np.ndarray | None:
        """The controller's reference at ``t``."""
        return self.controller.reference(t)

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The controller's efforts for what the sensors read of the true state (q, v) at ``t``.

        Raises:
            InvalidArgument: when ``t`` is not the next control period's start (the law evaluated
                per integrator stage, or twice in a period).
        """
        seen = self.sensors.read(t, q, v)
        if self.record_every and (self.sensors.periods - 1) % self.record_every == 0:
            self.log.t.append(t)
            self.log.measurements.append(seen)
        return self.controller.torque(t, seen.q, seen.v)
