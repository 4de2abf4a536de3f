"""``freefloat bench``: sweep the scenes and write ``bench.json``, ``bench.csv``,
``<scene>.png`` (log-log work-precision chart) and ``summary.txt`` into one folder."""

from __future__ import annotations

import csv
import json
import math
import platform
from importlib.metadata import version
from pathlib import Path

from ...dynamics.threads import single_blas_thread
from ...errors import InvalidArgument
from ..run_folder import Journal, RunFolder
from ..runner import signals_raise_keyboard_interrupt
from .free_floating import NOTES, free_floating_scene
from .mechanisms import MECHANISM_SCENES, mechanism_scene
from .scene import BenchScene
from .summary import band_rows, summary_lines
from .chart import chart
from .sweep import Point, sweep, timed_reference

#: Every bench scene with its note: the free-floating robots, then the closed-chain mechanisms.
ALL_SCENES = {**NOTES, **MECHANISM_SCENES}
#: Each measured point, one JSON line (a row of bench.csv), appended as it comes: what a bench
#: killed outright leaves.
JOURNAL = "points.jsonl"
CSV_FIELDS = ("scene", "package", "integrator", "model", "loop", "setting", "wall_time_s", "state_error",
              "momentum_error", "energy_error", "constraint_drift")


def bench_scene(name: str, duration: float | None, quick: bool, seed: int) -> BenchScene:
    """The bench scene ``name`` of :data:`ALL_SCENES` (:func:`.free_floating.free_floating_scene`,
    :func:`.mechanisms.mechanism_scene`; the seed applies to the tumbling scenes)."""
    if name in MECHANISM_SCENES:
        return mechanism_scene(name, duration, quick)
    return free_floating_scene(name, duration, quick, seed)


def _row(scene: str, p: Point) -> dict:
    """One point as a flat record; a diverged run's errors are None."""
    errors = {key: value if math.isfinite(value) else None for key, value in p.errors.items()}
    return {"scene": scene, "package": p.method.package, "integrator": p.method.integrator, "model": p.method.model,
            "loop": p.method.loop, "setting": p.method.setting, "wall_time_s": p.wall_time, **errors}


@single_blas_thread  # once for the whole bench: a limit per run costs 2-6 ms, small matrices run slower threaded
def bench(out: Path, scenes: list[str] | None = None, quick: bool = False, duration: float | None = None,
          repeats: int | None = None, seed: int = 0, progress=print) -> dict:
    """Run the sweep for each scene in this process and write the folder ``out``.

    Args:
        out: output folder (created; must be new or empty). Each point is appended to
            :data:`JOURNAL` there as it is measured (removed once the files are written), so a
            bench killed outright keeps every point measured.
        scenes: names from :data:`ALL_SCENES` (default: all).
        quick: each scene's smoke sweep (a few steps, a short duration) and one repeat.
        duration: simulated time per run, s (default: each scene's own).
        repeats: runs per point; the median time counts (default 5, 1 with ``quick``).
        seed: initial-state seed of the tumbling scenes.
        progress: called with a line as each scene starts and as it ends.

    Returns:
        The report written to ``bench.json``; its ``status`` is ``"completed"``, or says where
        Ctrl-C, SIGTERM or SIGHUP stopped the bench (the files then hold every point measured
        before; they are rewritten after each scene as the bench goes).
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
    with RunFolder(out) as folder, folder.journal(JOURNAL) as journal:
        report = _measure(folder, journal, built, repeats, quick, seed, progress)
    (out / JOURNAL).unlink()
    return report


def _measure(out: RunFolder, journal: Journal, built: list[BenchScene], repeats: int, quick: bool, seed: int,
             progress) -> dict:
    """The sweeps of :func:`bench` into the held folder ``out``, each point journaled as measured."""
    report = {"settings": {"repeats": repeats, "quick": quick, "seed": seed},
              "versions": {"freefloat": version("freefloat"), "pin": version("pin"), "mujoco": version("mujoco"),
                           "python": platform.python_version()},
              "status": "running", "scenes": {}}
    points: dict[str, list[Point]] = {}
    charted = None
    try:
        with signals_raise_keyboard_interrupt():
            for scene in built:
                report["scenes"][scene.name] = {"note": scene.note, "settings": scene.settings}
                points[scene.name] = []
                progress(f"{scene.name}: measuring {len(scene.methods())} methods, {repeats} runs each")
                ref, report["scenes"][scene.name]["reference_wall_time_s"] = timed_reference(scene)
                for point in sweep(scene, ref, repeats):
                    points[scene.name].append(point)
                    journal.append(json.dumps(_row(scene.name, point)))
                _write(out, report, built, points, scene.name)
                progress(f"{scene.name}: {len(points[scene.name])} points")
        report["status"] = "completed"
    except KeyboardInterrupt as stop:
        current = list(points)[-1]
        done = sum(len(p) for p in points.values())
        report["status"] = f"interrupted ({str(stop) or 'SIGINT'}) after {done} points, in scene {current}"
        charted = current if points[current] else None
    _write(out, report, built, points, charted)
    return report


def _write(out: RunFolder, report: dict, scenes: list[BenchScene], points: dict[str, list[Point]],
           charted: str | None) -> None:
    """``bench.json``, ``bench.csv`` and ``summary.txt`` from the points so far, and the chart of
    the scene ``charted`` (None: no chart)."""
    rows, lines = [], []
    for name, measured in points.items():
        bands = band_rows(measured)
        report["scenes"][name].update(points=[_row(name, p) for p in measured], bands=bands)
        rows += report["scenes"][name]["points"]
        lines += summary_lines(name, bands)
    report["summary"] = lines
    out.write_text("bench.json", json.dumps(report, indent=2))
    with out.atomic("bench.csv") as partial, open(partial, "w", newline="") as f:
        extra = sorted({key for row in rows for key in row} - set(CSV_FIELDS))
        writer = csv.DictWriter(f, fieldnames=CSV_FIELDS + tuple(extra))
        writer.writeheader()
        writer.writerows(rows)
    out.write_text("summary.txt", "\n".join(lines) + "\n")
    if charted is not None:
        chart(next(s for s in scenes if s.name == charted), points[charted], out.claim(f"{charted}.png"))
