"""What ``freefloat bench`` asks of the suites it runs, checked once for all of them."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import InvalidArgument

#: What a ``--quick`` bench's terminal lines, JSON and charts say of their numbers.
SMOKE = "smoke test (--quick): too few points, runs and repeats to be a measurement"


@dataclass(frozen=True)
class Options:
    """The command's settings, handed to every suite.

    Attributes:
        quick: each suite's smoke form (few points, short runs, one repeat).
        repeats: times each measurement is repeated (the suite says whether the best or the
            median counts); None: each suite's own default.
        scenes: the ``mujoco`` suite's scenes (empty: all of them); no other suite takes scenes.
        duration: simulated time per run of the ``mujoco`` suite, s (None: each scene's own).
        seed: initial-state seed of the ``mujoco`` suite's tumbling scenes.

    Raises:
        InvalidArgument: repeats that is not an integer >= 1, or a duration that is not > 0 s.
    """

    quick: bool = False
    repeats: int | None = None
    scenes: tuple[str, ...] = ()
    duration: float | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        if self.repeats is not None and not (isinstance(self.repeats, int) and self.repeats >= 1):
            raise InvalidArgument(f"repeats must be an integer >= 1, got {self.repeats!r}")
        if self.duration is not None and not self.duration > 0.0:
            raise InvalidArgument(f"duration must be > 0 s, got {self.duration}")
