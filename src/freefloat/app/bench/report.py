"""``freefloat bench``: sweep the scenes and write ``bench.json``, ``bench.csv``,
``<scene>.png`` (log-log work-precision chart) and ``summary.txt`` into one folder."""

from __future__ import annotations

import csv
import itertools
import json
import math
import platform
from importlib.metadata import version
from pathlib import Path

from ...dynamics.threads import single_blas_thread
from ...errors import InvalidArgument
from .free_floating import NOTES, free_floating_scene
from .mechanisms import MECHANISM_SCENES, mechanism_scene
from .scene import BenchScene
from .summary import band_rows, summary_lines
from .sweep import Point, sweep

#: Every bench scene with its note: the free-floating robots, then the closed-chain mechanisms.
ALL_SCENES = {**NOTES, **MECHANISM_SCENES}
CSV_FIELDS = ("scene", "package", "integrator", "model", "loop", "setting", "wall_time_s", "state_error",
              "momentum_error", "energy_error", "constraint_drift")


def bench_scene(name: str, duration: float | None, quick: bool, seed: int) -> BenchScene:
    """The bench scene ``name`` of :data:`ALL_SCENES` (:func:`.free_floating.free_floating_scene`,
    :func:`.mechanisms.mechanism_scene`; the seed applies to the tumbling scenes)."""
    if name in MECHANISM_SCENES:
        return mechanism_scene(name, duration, quick)
    return free_floating_scene(name, duration, quick, seed)


#: Line style per (package, loop) in the charts.
STYLES = {("freefloat", "compiled"): "-o", ("freefloat", "python"): ":o", ("pinocchio", "python"): "-.^",
          ("mujoco", "python"): "--s", ("mujoco", "native"): "-.s"}


def _row(scene: str, p: Point) -> dict:
    """One point as a flat record; a diverged run's errors are None."""
    errors = {key: value if math.isfinite(value) else None for key, value in p.errors.items()}
    return {"scene": scene, "package": p.method.package, "integrator": p.method.integrator, "model": p.method.model,
            "loop": p.method.loop, "setting": p.method.setting, "wall_time_s": p.wall_time, **errors}


def _style(method) -> str:
    """Line style of a method's curve: by package and loop; diamonds for a named plant model."""
    style = STYLES[(method.package, method.loop)]
    return style[:-1] + "d" if method.model else style


def chart(scene: BenchScene, points: list[Point], path: Path) -> None:
    """Log-log work-precision chart: wall time against final-state error (left) and against the
    scene's secondary error (right: momentum, or constraint drift), one curve per method (points
    joined from the coarsest step or tolerance to the finest)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 6.5), sharey=True)
    curves: dict[str, list[Point]] = {}
    for p in points:
        curves.setdefault(p.method.label, []).append(p)
    colors = plt.get_cmap("tab20").colors
    for ax, (key, what) in zip(axes, (("state_error", "final-state error"), scene.secondary)):
        for color, (label, curve) in zip(itertools.cycle(colors), curves.items()):
            curve = sorted(curve, key=lambda p: -p.method.setting)
            ax.loglog([p.errors[key] for p in curve], [p.wall_time * 1e3 for p in curve], _style(curve[0].method),
                      color=color, label=label, ms=4)
        ax.set_xlabel(what)
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("wall time per run, ms (median)")
    rows = -(-len(curves) // 3)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=7, frameon=False)
    names = {"freefloat": "freefloat", "pinocchio": "a bare Pinocchio loop", "mujoco": "MuJoCo"}
    present = [names[p] for p in names if any(q.method.package == p for q in points)]
    together = f" ({', '.join(present[:-1])} and {present[-1]} in one process)" if len(present) > 1 else ""
    fig.suptitle(f"{scene.name}: work against precision{together}; errors against a tight reference")
    fig.tight_layout(rect=(0.0, 0.03 * rows + 0.02, 1.0, 1.0))
    fig.savefig(path, dpi=120)
    plt.close(fig)


@single_blas_thread  # once for the whole bench: a limit per run costs 2-6 ms, small matrices run slower threaded
def bench(out: Path, scenes: list[str] | None = None, quick: bool = False, duration: float | None = None,
          repeats: int | None = None, seed: int = 0, progress=print) -> dict:
    """Run the sweep for each scene in this process and write the folder ``out``.

    Args:
        out: output folder (created; must be new or empty).
        scenes: names from :data:`ALL_SCENES` (default: all).
        quick: each scene's smoke sweep (a few steps, a short duration) and one repeat.
        duration: simulated time per run, s (default: each scene's own).
        repeats: runs per point; the median time counts (default 5, 1 with ``quick``).
        seed: initial-state seed of the tumbling scenes.
        progress: called with one line per finished scene.

    Returns:
        The report written to ``bench.json``.
    """
    names = list(scenes or ALL_SCENES)
    unknown = [name for name in names if name not in ALL_SCENES]
    if unknown:
        raise InvalidArgument(f"unknown bench scene '{unknown[0]}'; valid: {', '.join(ALL_SCENES)}")
    if duration is not None and not duration > 0.0:
        raise InvalidArgument(f"duration must be > 0 s, got {duration}")
    repeats = repeats if repeats is not None else (1 if quick else 5)
    if not (isinstance(repeats, int) and repeats >= 1):
        raise InvalidArgument(f"repeats must be an integer >= 1, got {repeats!r}")
    built = [bench_scene(name, duration, quick, seed) for name in names]  # bad scenes fail before any run
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InvalidArgument(f"{out}: output folder exists and is not empty")
    out.mkdir(parents=True, exist_ok=True)
    report = {"settings": {"repeats": repeats, "quick": quick},
              "versions": {"freefloat": version("freefloat"), "pin": version("pin"), "mujoco": version("mujoco"),
                           "python": platform.python_version()},
              "scenes": {}}
    rows, lines = [], []
    for scene in built:
        points, reference_time = sweep(scene, repeats)
        bands = band_rows(points)
        report["scenes"][scene.name] = {"note": scene.note, "settings": scene.settings,
                                        "reference_wall_time_s": reference_time,
                                        "points": [_row(scene.name, p) for p in points], "bands": bands}
        rows += [_row(scene.name, p) for p in points]
        lines += summary_lines(scene.name, bands)
        chart(scene, points, out / f"{scene.name}.png")
        progress(f"{scene.name}: {len(points)} points")
    report["summary"] = lines
    (out / "bench.json").write_text(json.dumps(report, indent=2))
    with open(out / "bench.csv", "w", newline="") as f:
        extra = sorted({key for row in rows for key in row} - set(CSV_FIELDS))
        writer = csv.DictWriter(f, fieldnames=CSV_FIELDS + tuple(extra))
        writer.writeheader()
        writer.writerows(rows)
    (out / "summary.txt").write_text("\n".join(lines) + "\n")
    return report
