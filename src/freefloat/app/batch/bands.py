"""The command line's vocabulary of a batch (``--vary KEY=WIDTH``, ``--runs``): the keys a batch
varies, a band, and its parsing. Light on purpose: the command line reads it to build its help
before anything heavy is imported (the draws are in :mod:`.variations`)."""

from __future__ import annotations

import math
from typing import NamedTuple

from ...errors import FreefloatError, did_you_mean

#: Vary keys, what each varies and in which unit. Robot scenes take the first five (``mass``
#: only without a ``[target]``), mechanism scenes the last two.
VARIES: dict[str, str] = {
    "base_rate": "base angular velocity, each component (planar base: z), in angle_unit/s",
    "base_velocity": "base CoM velocity, each component (planar base: x, y), m/s",
    "joint_angle": "every joint's start position, in angle_unit (m for prismatic joints)",
    "joint_rate": "every joint's start rate, in angle_unit/s (m/s for prismatic joints)",
    "mass": "the plant's link masses and inertias, each body by its own factor 1 +- WIDTH (WIDTH < 1, "
            "or a percentage such as 10%); the controller keeps the nominal model",
    "platform": "mechanism: the platform coordinates at t = 0 (m or rad)",
    "platform_rate": "mechanism: the platform rates at t = 0 (m/s or rad/s)",
}
ROBOT_KEYS = ("base_rate", "base_velocity", "joint_angle", "joint_rate", "mass")
MECHANISM_KEYS = ("platform", "platform_rate")


class Band(NamedTuple):
    """One ``--vary KEY=WIDTH``: the key (of :data:`VARIES`) and the half-width of its band."""

    key: str
    width: float


def parse_band(text: str) -> Band:
    """A band from ``KEY=WIDTH`` (``mass`` also takes ``P%``).

    Raises:
        FreefloatError: naming ``--vary`` and the text for a missing ``=``, an unknown key (listing
            the keys) or a width that is not a finite number >= 0 (< 1 for ``mass``).
    """
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep:
        raise FreefloatError(f"--vary '{text}': expected KEY=WIDTH such as base_rate=2 or mass=10%")
    if key not in VARIES:
        raise FreefloatError(f"--vary '{text}': unknown key '{key}'{did_you_mean(key, VARIES, 'keys')}")
    value = value.strip()
    percent = key == "mass" and value.endswith("%")
    try:
        width = float(value[:-1] if percent else value) / (100.0 if percent else 1.0)
    except ValueError:
        raise FreefloatError(f"--vary '{text}': width '{value}' is not a number") from None
    if not math.isfinite(width) or width < 0:
        raise FreefloatError(f"--vary '{text}': width must be a finite number >= 0")
    if key == "mass" and width >= 1:
        raise FreefloatError(f"--vary '{text}': mass factors 1 +- width must stay positive; use a width < 1 (or < 100%)")
    return Band(key, width)


#: Most runs one batch takes: every run is planned up front (about a kilobyte each), and
#: 10**12 runs grew memory at 15 MB/s until it ran out.
MAX_RUNS = 100_000
