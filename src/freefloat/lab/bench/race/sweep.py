"""Work against precision: each method's median wall time and its errors against the reference."""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from ....errors import SimulationDiverged
from .scene import BenchScene, Method


@dataclass(frozen=True)
class Point:
    """One measured method on one scene.

    Attributes:
        method: what ran.
        wall_time: median wall time of the repeated runs, s.
        errors: the scene's errors of the last run (:meth:`.scene.BenchScene.errors`); all infinite
            for a run that diverged.
    """

    method: Method
    wall_time: float
    errors: dict[str, float]

    @property
    def state_error(self) -> float:
        """The final-state error, the metric of the accuracy bands."""
        return self.errors["state_error"]

    def record(self, scene: str) -> dict:
        """The point as a flat record (a row of ``bench.csv``, strict JSON); a diverged run's
        errors are None."""
        errors = {key: value if math.isfinite(value) else None for key, value in self.errors.items()}
        return {"scene": scene, "package": self.method.package, "integrator": self.method.integrator,
                "model": self.method.model, "loop": self.method.loop, "setting": self.method.setting,
                "wall_time_s": self.wall_time, **errors}

    @classmethod
    def from_record(cls, row: dict) -> Point:
        """The point of a :meth:`record` (errors None read back as infinite)."""
        method = Method(row["package"], row["integrator"], row["setting"], row["loop"], row["model"])
        errors = {key: math.inf if value is None else value for key, value in row.items() if key not in RECORD_KEYS}
        return cls(method, row["wall_time_s"], errors)


#: The keys of a :meth:`Point.record` that are not errors.
RECORD_KEYS = ("scene", "package", "integrator", "model", "loop", "setting", "wall_time_s")


def _call(run: Any) -> tuple[float, Any]:
    """Wall time (s) and result of one run; the result None when it blew up."""
    start = time.perf_counter()
    try:
        result = run()
    except (SimulationDiverged, ArithmeticError):
        result = None
    return time.perf_counter() - start, result


def _point(scene: BenchScene, method: Method, times: list[float], result: Any, ref: Any) -> Point:
    """The median of ``times`` and the errors of ``result`` (all infinite when it is None or its
    errors are not finite, under the keys of the reference's own errors)."""
    errors = None if result is None else scene.errors(result, ref)
    if errors is None or not all(math.isfinite(e) for e in errors.values()):
        errors = dict.fromkeys(scene.errors(ref, ref), math.inf)
    return Point(method, statistics.median(times), errors)


def measure(scene: BenchScene, method: Method, ref, repeats: int) -> Point:
    """Run ``method`` ``repeats`` times; the median wall time and the errors of the last run.

    A run that diverges (raises, or ends in a state whose errors are not finite) keeps its time
    and gets infinite errors (under the keys of the reference's own errors).
    """
    run = scene.run(method)
    calls = [_call(run) for _ in range(repeats)]
    return _point(scene, method, [t for t, _ in calls], calls[-1][1], ref)


def taking_turns(scene: BenchScene, ref: Any, repeats: int) -> Iterator[Point]:
    """Every method of the scene run once per round, ``repeats`` rounds, so that load from
    elsewhere falls on all of them alike; each point (as :func:`measure`'s) comes as its method's
    last run ends, in the last round."""
    runs = [(method, scene.run(method)) for method in scene.methods()]
    times: list[list[float]] = [[] for _ in runs]
    for round_ in range(repeats):
        for (method, run), own in zip(runs, times):
            elapsed, result = _call(run)
            own.append(elapsed)
            if round_ == repeats - 1:
                yield _point(scene, method, own, result, ref)


def timed_reference(scene: BenchScene) -> tuple[Any, float]:
    """The scene's reference result and its wall time, s."""
    start = time.perf_counter()
    ref = scene.reference()
    return ref, time.perf_counter() - start


def sweep(scene: BenchScene, ref: Any, repeats: int = 3) -> Iterator[Point]:
    """Every method of the scene measured in this process against ``ref``, one point as each
    finishes (so an interrupted sweep keeps the points before it); by :func:`taking_turns` when
    the scene's ``turns`` is true (its points then come in the last round)."""
    if getattr(scene, "turns", False):
        yield from taking_turns(scene, ref, repeats)
        return
    for method in scene.methods():
        yield measure(scene, method, ref, repeats)
