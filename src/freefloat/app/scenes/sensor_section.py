"""A robot scene's ``[sensors]`` section: what its controller reads, as the sensors' own settings
records (:class:`~freefloat.dynamics.sensors.SensorSettings`, one :class:`~freefloat.dynamics.sensors.Channel`
per channel group, the :class:`~freefloat.dynamics.sensors.MomentumKalman` estimator): their
fields are the keys, their constructors the checks.

.. code-block:: toml

    [sensors]
    seed = 1                      # the noise's generator
    [sensors.joint_rate]          # rad/s: one value or one per joint; delay and every in control periods
    noise = 0.01
    delay = 2
    every = 10
    [sensors.momentum]            # the Kalman estimator; absent: a law reads the map of the readings
    restart = [0.015]             # s: known impulses
"""

from __future__ import annotations

from typing import Any

from ...dynamics.sensors import GROUPS, Channel, MomentumKalman, SensorSettings
from ...errors import InvalidArgument, SceneError
from .fields import Rules, number, parse_section, reject_unknown, typed, vector

#: Ranges of the keys whose constructor would otherwise name them without the section.
RULES = Rules({}, {("sensors.momentum", "linear_process_noise"), ("sensors.momentum", "angular_process_noise"),
                   *((f"sensors.{g}", "every") for g in GROUPS)},
              {("sensors", "seed"), *((f"sensors.{g}", "delay") for g in GROUPS)})


def parse_sensors(where: str, raw: Any) -> SensorSettings:
    """``[sensors]``: ``seed``, a table per channel group of :data:`~freefloat.dynamics.sensors.GROUPS`
    (``noise`` and ``bias``: one number or a list, one per component; ``delay`` and ``every``:
    whole control periods) and ``momentum`` (the estimator's keys); a group not given is ideal.

    Raises:
        SceneError: naming ``sensors.<key>`` that is unknown (with the nearest) or wrong.
    """
    raw = typed(where, "sensors", raw, dict)
    reject_unknown(where, "sensors", raw, {"seed", "momentum", *GROUPS})
    values: dict[str, Any] = {group: _channel(where, group, raw[group]) for group in GROUPS if group in raw}
    if "seed" in raw:
        values["seed"] = number(where, "sensors", "seed", raw["seed"], int, RULES)
    if "momentum" in raw:
        momentum = typed(where, "sensors.momentum", raw["momentum"], dict)
        if momentum.get("restart") == []:  # no known impulse, as a run folder's scene.toml writes it
            momentum = {k: v for k, v in momentum.items() if k != "restart"}
        values["momentum"] = parse_section(where, "sensors.momentum", MomentumKalman, momentum, RULES)
    return SensorSettings(**values)


def _channel(where: str, group: str, raw: Any) -> Channel:
    """One group's :class:`Channel` from its table.

    Raises:
        SceneError: naming ``sensors.<group>.<key>``.
    """
    section = f"sensors.{group}"
    raw = typed(where, section, raw, dict)
    reject_unknown(where, section, raw, set(Channel.__dataclass_fields__))
    values: dict[str, Any] = {}
    for key, value in raw.items():
        if key in ("noise", "bias"):
            values[key] = (vector(where, f"{section}.{key}", value, None) if isinstance(value, list)
                           else number(where, section, key, value, float, RULES))
        else:
            values[key] = number(where, section, key, value, int, RULES)
    try:
        return Channel(**values)
    except InvalidArgument as exc:  # a negative noise
        raise SceneError(f"{where}[{section}] {exc}") from exc


__all__ = ["parse_sensors"]
