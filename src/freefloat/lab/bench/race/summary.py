"""The cheapest method per accuracy band, for each package, and the ratio between them."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from .sweep import Point

#: Final-state errors at which the packages are compared.
BANDS = (1e-3, 1e-5, 1e-7, 1e-9, 1e-11)


@dataclass(frozen=True)
class Cheapest:
    """The cheapest way one package reaches a band.

    Attributes:
        label: ``package integrator``.
        wall_time: wall time at which the error reaches the band, s, interpolated in log-log
            between the two measured points of that method that bracket it (the measured time
            when its cheapest point is already under the band).
        upper_bound: True when the method's coarsest measured setting is already under the band, so
            a coarser setting (outside the sweep) could reach it for less.
    """

    label: str
    wall_time: float
    upper_bound: bool


def time_to_reach(points: list[Point], band: float) -> float:
    """Least wall time (s) at which one method's curve has a state error <= ``band`` (inf if never).

    ``points`` are one method's measurements; consecutive points from the coarsest setting (largest
    step or tolerance) to the finest that bracket the band are interpolated linearly in
    (log time, log error).
    """
    curve = [(p.wall_time, p.state_error) for p in sorted(points, key=lambda p: -p.method.setting)]
    best = math.inf
    for i, (t, e) in enumerate(curve):
        if e <= band:
            best = min(best, t)
        if i and curve[i - 1][1] > band >= e > 0.0 and math.isfinite(curve[i - 1][1]):
            (t1, e1), (t2, e2) = curve[i - 1], (t, e)
            slope = (math.log(t2) - math.log(t1)) / (math.log(e2) - math.log(e1))
            best = min(best, math.exp(math.log(t1) + slope * (math.log(band) - math.log(e1))))
    return best


def curves(points: list[Point]) -> dict[str, list[Point]]:
    """The points by method (``Method.label``), in the order the methods first come."""
    out: dict[str, list[Point]] = {}
    for p in points:
        out.setdefault(p.method.label, []).append(p)
    return out


def times_to_reach(points: list[Point], band: float) -> dict[str, float]:
    """Per method that reaches ``band``: the least wall time at which it does, s
    (:func:`time_to_reach`), fastest first."""
    times = {label: time_to_reach(curve, band) for label, curve in curves(points).items()}
    return dict(sorted(((label, t) for label, t in times.items() if math.isfinite(t)), key=lambda item: item[1]))


def cheapest(points: list[Point], package: str, band: float) -> Cheapest | None:
    """The method of ``package`` that reaches ``band`` in the least wall time, or None."""
    own = [p for p in points if p.method.package == package]
    times = times_to_reach(own, band)
    if not times:
        return None
    label = next(iter(times))
    first = max(curves(own)[label], key=lambda p: p.method.setting)
    return Cheapest(label, times[label], first.state_error <= band)


def band_rows(points: list[Point], bands: tuple[float, ...] = BANDS) -> list[dict]:
    """Per band: freefloat's and MuJoCo's cheapest method, their times (s) and
    ``mujoco_speedup`` = freefloat time / MuJoCo time (> 1: MuJoCo faster; None if either misses)."""
    rows = []
    for band in bands:
        ff, mj = cheapest(points, "freefloat", band), cheapest(points, "mujoco", band)
        rows.append({
            "band": band,
            "freefloat": None if ff is None else asdict(ff),
            "mujoco": None if mj is None else asdict(mj),
            "mujoco_speedup": None if ff is None or mj is None else ff.wall_time / mj.wall_time,
        })
    return rows


def summary_lines(scene: str, rows: list[dict]) -> list[str]:
    """One readable line per band ("at most": met by the method's coarsest measured setting)."""
    lines = []
    for row in rows:
        ff, mj, ratio = row["freefloat"], row["mujoco"], row["mujoco_speedup"]
        def say(side, package):
            if side is None:
                return f"{package} not reached"
            bound = "at most " if side["upper_bound"] else ""
            return f"{side['label']} {bound}{side['wall_time'] * 1e3:.3g} ms"
        verdict = "" if ratio is None else (f": MuJoCo {ratio:.2f}x faster" if ratio >= 1.0
                                            else f": freefloat {1.0 / ratio:.2f}x faster")
        lines.append(f"{scene} error <= {row['band']:.0e}: {say(ff, 'freefloat')}, {say(mj, 'mujoco')}{verdict}")
    return lines
