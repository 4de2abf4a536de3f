"""``freefloat bench``: sweep the scenes and write ``bench.json``, ``bench.csv``,
``<scene>.png`` (log-log work-precision chart) and ``summary.txt`` into one folder."""

from __future__ import annotations

import csv
import functools
import json
import platform
from collections.abc import Callable
from importlib.metadata import version
from pathlib import Path

from ....app.run_folder import Journal, RunFolder
from ....app.signals import imported_whole, signals_deferred, signals_held, signals_raise_keyboard_interrupt
from ....dynamics.threads import single_blas_thread
from ..options import SMOKE, Options
from ..scenes import SCENES
from .chart import chart
from .scene import BenchScene
from .summary import band_rows, summary_lines
from .sweep import RECORD_KEYS, Point, sweep, timed_reference

#: Each measured point, one JSON line (a row of bench.csv), appended as it comes: what a bench
#: killed outright leaves.
JOURNAL = "points.jsonl"
CSV_FIELDS = RECORD_KEYS + ("state_error", "momentum_error", "energy_error", "constraint_drift")


def bench(out: Path, scenes: list[str] | None = None, quick: bool = False, duration: float | None = None,
          repeats: int | None = None, seed: int = 0, progress=print) -> dict:
    """Run the sweep for each scene in this process and write the folder ``out``.

    Args:
        out: output folder (created; must be new or empty). Each point is appended to
            :data:`JOURNAL` there as it is measured (removed once the files are written), so a
            bench killed outright keeps every point measured.
        scenes: names of :data:`~..scenes.SCENES` (default: its default ones).
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
    measure = prepared(Options(quick, repeats, tuple(scenes or ()), duration, seed))
    with RunFolder(out) as folder:
        return measure(folder, progress)


def prepared(options: Options) -> Callable[[RunFolder, Callable[[str], None]], dict]:
    """The scenes of ``options`` built, so that a bad one fails before any folder is made; the
    measurement ``(folder, progress) -> report`` that sweeps them into a held folder (see
    :func:`bench`).

    Raises:
        UnknownName: a scene not in :data:`~..scenes.SCENES`, the nearest named.
    """
    names = options.scenes or [entry.name for entry in SCENES.values() if entry.default]
    entries = [SCENES.get(name) for name in names]
    repeats = options.repeats if options.repeats is not None else (1 if options.quick else 5)
    built = [entry.build(options.duration, options.quick, options.seed) for entry in entries]
    return functools.partial(_into, built, repeats, options.quick, options.seed)


@single_blas_thread  # once for the whole bench: a limit per run costs 2-6 ms, small matrices run slower threaded
def _into(built: list[BenchScene], repeats: int, quick: bool, seed: int, out: RunFolder, progress) -> dict:
    """The sweeps of :func:`bench` into the held folder ``out``, the journal removed at the end."""
    with out.journal(JOURNAL) as journal:
        report = _measure(out, journal, built, repeats, quick, seed, progress)
    (out.path / JOURNAL).unlink()
    return report


def _measure(out: RunFolder, journal: Journal, built: list[BenchScene], repeats: int, quick: bool, seed: int,
             progress) -> dict:
    """The sweeps of :func:`bench` into the held folder ``out``, each point journaled as measured."""
    mujoco = imported_whole("mujoco")  # the bench extra, checked before any work (suites.Suite.needs)

    report = {**({"smoke_test": SMOKE} if quick else {}), "settings": {"repeats": repeats, "quick": quick, "seed": seed},
              "versions": {"freefloat": version("freefloat"), "pin": version("pin"), "mujoco": mujoco.__version__,
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
                    journal.append(json.dumps(point.record(scene.name)))
                with signals_held():  # a drawing cut by a signal would fail the final one
                    _write(out, report, built, points, scene.name)
                progress(f"{scene.name}: {len(points[scene.name])} points")
        report["status"] = "completed"
    except KeyboardInterrupt as stop:
        current = list(points)[-1]
        done = sum(len(p) for p in points.values())
        report["status"] = f"interrupted ({str(stop) or 'SIGINT'}) after {done} points, in scene {current}"
        charted = current if points[current] else None
    with signals_deferred():  # a second signal does not cut what the first kept
        _write(out, report, built, points, charted)
    return report


def _write(out: RunFolder, report: dict, scenes: list[BenchScene], points: dict[str, list[Point]],
           charted: str | None) -> None:
    """``bench.json``, ``bench.csv`` and ``summary.txt`` from the points so far, and the chart of
    the scene ``charted`` (None: no chart); a ``--quick`` run's say it is a smoke test."""
    smoke = report.get("smoke_test")
    rows, lines = [], [smoke] if smoke else []
    for name, measured in points.items():
        bands = band_rows(measured)
        report["scenes"][name].update(points=[p.record(name) for p in measured], bands=bands)
        rows += report["scenes"][name]["points"]
        lines += [f"{line} (smoke test)" if smoke else line for line in summary_lines(name, bands)]
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
        if smoke:
            from ..suites.drawing import mark_smoke

            mark_smoke(out.path / f"{charted}.png")
