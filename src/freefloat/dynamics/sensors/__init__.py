"""Sensors between the robot and its controller: noise, bias, delay and sampling on what a law reads,
seeded and recorded, and the system momentum estimated from the readings.

``settings`` (what the sensors are: a :class:`~.settings.Channel` per channel group and the
estimator's settings, the keys of a scene's ``[sensors]`` section), ``readings`` (the readings of
each control period: samples in flight, held, noisy on the configuration's Lie group),
``momentum`` (the Kalman filter of the momentum, constant between impulses) and ``sensed`` (the
composition ``Sensed(controller, sensors)`` that hands a law the measured state and records it).

May import: :mod:`freefloat.robot`, :mod:`freefloat.errors`, :mod:`freefloat.arguments`.
"""

from .momentum import MomentumEstimator
from .readings import Measurement, Sensors
from .sensed import Sensed, SensorRecord
from .settings import GROUPS, Channel, MomentumKalman, SensorSettings

__all__ = ["GROUPS", "Channel", "Measurement", "MomentumEstimator", "MomentumKalman", "Sensed",
           "SensorRecord", "SensorSettings", "Sensors"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
