"""What a robot run's sensors did (a scene with ``[sensors]``): the seed of their noise and, with
the momentum estimator, how far its estimate and the readings' momentum map were from the true
momentum (the run's telemetry, row for row)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...dynamics.sensors import Sensed
from ...dynamics.sensors.momentum import CONSERVED
from ...dynamics.telemetry import Telemetry

#: Summary keys of a sensed run, in the order the command line prints them.
HEADLINE = ("sensor_seed", "momentum_estimate_error_linear", "momentum_estimate_error_angular",
            "momentum_reading_error_linear", "momentum_reading_error_angular")
#: The unit of each key :func:`sensor_summary` gives.
UNITS = {"sensor_seed": "", "momentum_estimate_error_linear": "N s", "momentum_estimate_error_angular": "N m s",
         "momentum_reading_error_linear": "N s", "momentum_reading_error_angular": "N m s",
         "momentum_estimate_spread_angular_final": "N m s", "momentum_estimate_restarts": "",
         "momentum_estimate_from": "s"}


def sensor_summary(controller: Any, telemetry: Telemetry, control_period: float) -> dict[str, Any]:
    """The sensed run's figures: ``sensor_seed``; with the estimator, over the control periods
    from its last restart (``momentum_estimate_from``, s) to the end, the RMS of the error norm
    of the estimate and of the readings' map ``A_O(q) v`` against the true momentum about the
    inertial origin, on the components only external wrenches change (all six on a free base;
    Px, Py, Lz on a planar one): linear (N s) and angular (N m s); the estimate's own standard
    deviation on the angular components at the end (norm, N m s) and how often it restarted.
    Empty for a run whose controller reads the true state."""
    if not isinstance(controller, Sensed):
        return {}
    summary: dict[str, Any] = {"sensor_seed": controller.sensors.settings.seed}
    seen = controller.log.record()
    if controller.sensors.settings.momentum is None or not len(seen.t) or not len(telemetry.t):
        return summary
    k_seen, k_true = np.rint(seen.t / control_period), np.rint(telemetry.t / control_period)
    common, i_seen, i_true = np.intersect1d(k_seen, k_true, return_indices=True)
    restarts = np.flatnonzero(seen.reset[i_seen])
    start = restarts[-1] if len(restarts) else 0
    i_seen, i_true = i_seen[start:], i_true[start:]
    rows = CONSERVED[controller.sensors.robot.base]
    linear, angular = rows[rows < 3], rows[rows >= 3]
    truth = telemetry.momentum[i_true]

    def rms(values: np.ndarray, components: np.ndarray) -> float:
        """RMS over the periods of the error norm on ``components``."""
        error = values[i_seen][:, components] - truth[:, components]
        return float(np.sqrt(np.mean(np.sum(error ** 2, axis=1))))

    summary.update(
        momentum_estimate_error_linear=rms(seen.estimate, linear), momentum_estimate_error_angular=rms(seen.estimate, angular),
        momentum_reading_error_linear=rms(seen.momentum, linear), momentum_reading_error_angular=rms(seen.momentum, angular),
        momentum_estimate_spread_angular_final=float(np.linalg.norm(seen.spread[i_seen[-1], angular])),
        momentum_estimate_restarts=int(seen.reset.sum()), momentum_estimate_from=float(common[start] * control_period))
    return summary


__all__ = ["HEADLINE", "UNITS", "sensor_summary"]
