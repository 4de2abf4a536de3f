"""What a run with contact adds to its summary, measured from its telemetry rows: when the shapes
first and last touched, how deep and how hard, and how it ended (no contact, a rebound, or still
touching: held)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...robot.robot import Robot
from .field import ContactField

__all__ = ["SUMMARY_UNITS", "contact_summary"]

#: The unit of each key :func:`contact_summary` adds ("" for a text).
SUMMARY_UNITS = {"contact_outcome": "", "contact_start": "s", "contact_end": "s", "contact_max_penetration": "m",
                 "contact_peak_force": "N", "contact_final_normal_speed": "m/s"}


def contact_summary(field: ContactField, robot: Robot, telemetry: Any) -> dict[str, Any]:
    """The contact seen at the recorded rows of ``telemetry`` (a
    :class:`~freefloat.dynamics.telemetry.Telemetry` of ``robot``, the model the field acts in):
    ``contact_outcome`` ("none": never touching; "rebound": touching, then apart at the last row
    and separating; "held": touching, or apart but closing, at the last row), the first and last
    row's time in contact (s, None without contact), the deepest penetration (m) and the largest
    contact force (N) seen at a row, and the normal speed at which the second shape leaves the
    first at the last row (m/s, > 0 separating). A contact shorter than the row spacing can fall
    between rows (record every period to see it).

    Units: :data:`SUMMARY_UNITS`.
    """
    depths, forces, times = [], [], []
    for t, q, v in zip(telemetry.t, telemetry.q, telemetry.v):
        touch = field.contact(q, v)
        if touch is not None:
            times.append(float(t))
            depths.append(touch[0].depth)
            forces.append(float(np.linalg.norm(touch[1])))
    near, velocity = field.nearest(telemetry.q[-1], telemetry.v[-1])
    leaving = float(near.normal @ velocity)
    if not times:
        outcome = "none"
    else:
        outcome = "rebound" if near.depth <= 0.0 and leaving > 0.0 else "held"
    return {"contact_outcome": outcome, "contact_start": times[0] if times else None,
            "contact_end": times[-1] if times else None, "contact_max_penetration": max(depths, default=0.0),
            "contact_peak_force": max(forces, default=0.0), "contact_final_normal_speed": leaving}
