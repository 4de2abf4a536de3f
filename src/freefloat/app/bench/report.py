"""``freefloat bench``: sweep the scenes and write ``bench.json``, ``bench.csv``,
``<scene>.png`` (log-log work-precision chart) and ``summary.txt`` into one folder."""

from __future__ import annotations

import csv
import json
import math
import platform
from importlib.metadata import version
from pathlib import Path

from ...errors import InvalidArgument
from .controlled import controlled_scene
from .methods import REFERENCE_ATOL, REFERENCE_RTOL, controlled_methods, methods
from .scenes import SCENES, tumbling_scene
from .summary import band_rows, summary_lines
from .sweep import Point, sweep

#: Steps (s) and dopri5 tolerances of a full sweep and of ``--quick``.
STEPS = (2e-1, 1e-1, 5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)
RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
QUICK_STEPS = (2e-2, 1e-2, 5e-3)
QUICK_RTOLS = (1e-6, 1e-9)
#: The controlled scene's integration steps (s, dividing its 1 ms period) and dopri5 tolerances.
CONTROLLED_STEPS = (1e-3, 5e-4, 2e-4, 1e-4)
CONTROLLED_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10)
QUICK_CONTROLLED_STEPS = (1e-3, 5e-4)
QUICK_CONTROLLED_RTOLS = (1e-6,)
#: Every bench scene with its note: the tumbling ones and the controlled one.
ALL_SCENES = {**{name: note for name, (_, note) in SCENES.items()},
              "controlled": "four-arm robot (balanced, free base), computed torque held over 1 ms, the default "
                            "task's quintic"}
CSV_FIELDS = ("scene", "package", "integrator", "loop", "setting", "wall_time_s", "state_error", "momentum_error",
              "energy_error")

#: Line style per (package, loop) in the charts.
STYLES = {("freefloat", "compiled"): "-o", ("freefloat", "python"): ":o", ("pinocchio", "python"): "-.^",
          ("mujoco", "python"): "--s", ("mujoco", "native"): "-.s"}


def _row(scene: str, p: Point) -> dict:
    """One point as a flat record; a diverged run's errors are None."""
    def finite(x: float) -> float | None:
        return x if math.isfinite(x) else None
    return {"scene": scene, "package": p.method.package, "integrator": p.method.integrator, "loop": p.method.loop,
            "setting": p.method.setting, "wall_time_s": p.wall_time, "state_error": finite(p.state_error),
            "momentum_error": finite(p.momentum_error), "energy_error": finite(p.energy_error)}


def chart(scene: str, points: list[Point], path: Path) -> None:
    """Log-log work-precision chart: wall time against final-state error (left) and against
    momentum error (right), one curve per method (points joined from the coarsest step or
    tolerance to the finest)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharey=True)
    curves: dict[str, list[Point]] = {}
    for p in points:
        curves.setdefault(p.method.label, []).append(p)
    for ax, field, what in ((axes[0], "state_error", "final-state error"),
                            (axes[1], "momentum_error", "momentum error, kg m/s and kg m^2/s")):
        for label, curve in curves.items():
            curve = sorted(curve, key=lambda p: -p.method.setting)
            style = STYLES[(curve[0].method.package, curve[0].method.loop)]
            ax.loglog([getattr(p, field) for p in curve], [p.wall_time * 1e3 for p in curve], style, label=label, ms=4)
        ax.set_xlabel(f"{what} against dopri5 at rtol 1e-13")
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("wall time per run, ms (median)")
    axes[0].legend(fontsize=7, ncol=2)
    names = {"freefloat": "freefloat", "pinocchio": "a bare Pinocchio loop", "mujoco": "MuJoCo"}
    present = [names[p] for p in names if any(q.method.package == p for q in points)]
    fig.suptitle(f"{scene}: work against precision ({', '.join(present[:-1])} and {present[-1]} in one process)"
                 if len(present) > 1 else f"{scene}: work against precision")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def bench(out: Path, scenes: list[str] | None = None, quick: bool = False, duration: float | None = None,
          repeats: int | None = None, seed: int = 0, progress=print) -> dict:
    """Run the sweep for each scene in this process and write the folder ``out``.

    Args:
        out: output folder (created; must be new or empty).
        scenes: names from :data:`.scenes.SCENES` (default: all).
        quick: three steps, two tolerances, 0.1 s, one repeat (a smoke test).
        duration: simulated time per run, s (default 1 s, 0.1 s with ``quick``).
        repeats: runs per point; the median time counts (default 5, 1 with ``quick``).
        seed: initial-state seed.
        progress: called with one line per finished scene.

    Returns:
        The report written to ``bench.json``.
    """
    names = list(scenes or ALL_SCENES)
    unknown = [name for name in names if name not in ALL_SCENES]
    if unknown:
        raise InvalidArgument(f"unknown bench scene '{unknown[0]}'; valid: {', '.join(ALL_SCENES)}")
    steps, rtols = (QUICK_STEPS, QUICK_RTOLS) if quick else (STEPS, RTOLS)
    controlled_steps, controlled_rtols = ((QUICK_CONTROLLED_STEPS, QUICK_CONTROLLED_RTOLS) if quick
                                          else (CONTROLLED_STEPS, CONTROLLED_RTOLS))
    duration = duration if duration is not None else (0.1 if quick else 1.0)
    repeats = repeats if repeats is not None else (1 if quick else 5)
    # bad names and durations fail before any run
    scenes_built = [controlled_scene(duration) if name == "controlled" else tumbling_scene(name, duration, seed)
                    for name in names]
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InvalidArgument(f"{out}: output folder exists and is not empty")
    out.mkdir(parents=True, exist_ok=True)
    report = {"settings": {"duration_s": duration, "repeats": repeats, "seed": seed, "steps_s": steps,
                           "dopri5_rtols": rtols, "controlled_steps_s": controlled_steps,
                           "controlled_dopri5_rtols": controlled_rtols, "reference": {"integrator": "dopri5", "rtol": REFERENCE_RTOL,
                                                                "atol": REFERENCE_ATOL}},
              "versions": {"freefloat": version("freefloat"), "pin": version("pin"), "mujoco": version("mujoco"),
                           "python": platform.python_version()},
              "scenes": {}}
    rows, lines = [], []
    for scene in scenes_built:
        sweep_methods = (controlled_methods(controlled_steps, controlled_rtols) if scene.name == "controlled"
                         else methods(steps, rtols))
        points, reference_time = sweep(scene, sweep_methods, repeats)
        bands = band_rows(points)
        report["scenes"][scene.name] = {"note": ALL_SCENES[scene.name], "reference_wall_time_s": reference_time,
                                        "points": [_row(scene.name, p) for p in points], "bands": bands}
        rows += [_row(scene.name, p) for p in points]
        lines += summary_lines(scene.name, bands)
        chart(scene.name, points, out / f"{scene.name}.png")
        progress(f"{scene.name}: {len(points)} points")
    report["summary"] = lines
    (out / "bench.json").write_text(json.dumps(report, indent=2))
    with open(out / "bench.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        writer.writeheader()
        writer.writerows(rows)
    (out / "summary.txt").write_text("\n".join(lines) + "\n")
    return report
