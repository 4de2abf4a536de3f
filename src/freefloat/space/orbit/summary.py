"""What a run in orbit adds to its summary, measured from its telemetry: where the base ends in
the LVLH frame and, for a one-body satellite, its pitch libration period."""

from __future__ import annotations

from typing import Any

from ...errors import InvalidArgument
from ...robot.robot import Robot
from .field import OrbitField
from .libration import crossing_period
from .lvlh import base_in_lvlh

__all__ = ["SUMMARY_UNITS", "orbit_summary"]

#: The unit of each key :func:`orbit_summary` adds ("" for a pure number).
SUMMARY_UNITS = {"base_lvlh_position_final": "m", "base_lvlh_quaternion_final": "", "libration_period": "s"}


def orbit_summary(field: OrbitField, robot: Robot, telemetry: Any) -> dict[str, Any]:
    """The base CoM's LVLH position (m, (3,)) and attitude ([x, y, z, w], base to LVLH) at the last
    row of ``telemetry`` (a :class:`~freefloat.dynamics.telemetry.Telemetry` of ``robot``) and, for
    a one-body robot, ``libration_period``: the mean period (s) between the first and last upward
    zero crossings of the base x axis's pitch from LVLH x about the orbit normal
    (:func:`.libration.crossing_period`; None for fewer than two crossings).

    Units: :data:`SUMMARY_UNITS`.
    """
    track = base_in_lvlh(field.orbit, telemetry)
    summary: dict[str, Any] = {"base_lvlh_position_final": track.position[-1].tolist(),
                               "base_lvlh_quaternion_final": track.quaternion()[-1].tolist()}
    if robot.model.nv == 6:
        try:
            summary["libration_period"] = crossing_period(track.t, track.pitch())
        except InvalidArgument:
            summary["libration_period"] = None
    return summary
