"""A batch from a scene to its folder: check everything, plan the seeded runs, run them where
asked, keep each row as it comes, write the table.

The folder (locked and checked before any run, as a run's) gets ``runs.csv`` and ``runs.json``
(one row per run, by run index), ``summary.json`` (status, counts, runs per second, the bands,
seed and workers, the scene and package versions) and ``scene.toml``. Each finished row is
appended to ``runs-partial.jsonl`` as it comes (removed once the table is written), so Ctrl-C or
SIGTERM keeps every finished row in the table, and even a batch killed outright leaves them there.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..outputs import strict_json, versions
from ..run_folder import RunFolder
from ..runner import prepare, signals_deferred, signals_raise_keyboard_interrupt
from ..scenes import MechanismScene, Scene
from ..scenes.as_run import scene_as_run, scene_table
from .bands import Band
from .executors import Workers, executor
from .variations import plan_runs

PARTIAL = "runs-partial.jsonl"
#: Summary keys whose spread over the runs ``summary.json`` and the command line report.
HEADLINE = ("momentum_drift_max", "energy_drift_max", "tracking_rms_overall", "com_drift_max",
            "tracking_error_max[0]", "loop_closure_drift_max")


@dataclass
class BatchResult:
    """A finished (or interrupted) batch: its rows by run index, ``summary.json``'s record and
    the folder."""

    rows: list[dict[str, Any]]
    summary: dict[str, Any]
    folder: Path

    @property
    def completed(self) -> bool:
        """Every run ran and completed."""
        return self.summary["status"] == "completed" and all(r["status"] == "completed" for r in self.rows)


def run_batch(scene: Scene | MechanismScene, out: Path, runs: int, bands: list[Band], seed: int = 0,
              workers: Workers = Workers(), overwrite: bool = False,
              progress: Callable[[dict[str, Any]], None] | None = None,
              started: Callable[[], None] = lambda: None) -> BatchResult:
    """Run ``runs`` seeded variations of ``scene`` into the folder ``out`` (see the module docstring).

    Args:
        progress: called with each row as its run finishes.
        started: called as the runs start (everything checked, the workers up, the folder taken):
            the summary's ``wall_time_s`` starts then.

    Raises:
        FreefloatError: before any run, naming the argument, key or folder at fault (runs < 1, a
            band the scene cannot take, a scene error, a dead scheduler (the folder is not made),
            a folder in use).
    """
    scene = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False, html=False))
    plans = plan_runs(scene, prepare(scene), bands, runs, seed)
    rows: dict[int, dict[str, Any]] = {}
    with executor(workers) as execute, RunFolder(out, overwrite) as folder:
        start = time.perf_counter()
        started()
        folder.write_text("scene.toml", scene_as_run(scene))
        with folder.journal(PARTIAL) as partial:
            def keep(row: dict[str, Any]) -> None:
                rows[row["run"]] = row
                partial.append(json.dumps(row))
                if progress is not None:
                    progress(row)

            status = "completed"
            try:
                with signals_raise_keyboard_interrupt():
                    execute(plans, keep)
            except KeyboardInterrupt:
                status = "interrupted"
        wall = time.perf_counter() - start
        ordered = [rows[i] for i in sorted(rows)]
        if status == "completed" and (len(ordered) < runs or any(r["status"] != "completed" for r in ordered)):
            status = "failed"  # some run failed or stopped early: the batch did not complete
        summary = _summary(scene, ordered, runs, bands, seed, workers, status, wall)
        with signals_deferred():
            _write_table(folder, ordered)
            folder.write_text("summary.json", strict_json(summary))
            (folder.path / PARTIAL).unlink()
    return BatchResult(ordered, summary, Path(out))


def _summary(scene: Scene | MechanismScene, rows: list[dict[str, Any]], runs: int, bands: list[Band], seed: int,
             workers: Workers, status: str, wall: float) -> dict[str, Any]:
    """``summary.json``: what was asked, what came of it, and the spread of the headline keys."""
    counts: dict[str, int] = {}
    for row in rows:
        counts[row["status"]] = counts.get(row["status"], 0) + 1
    spread = {}
    for key in HEADLINE:
        values = [r[key] for r in rows if isinstance(r.get(key), float)]
        if values:
            spread[key] = {"min": min(values), "median": statistics.median(values), "max": max(values)}
    return {
        "status": status, "runs": runs, "finished": len(rows), "not_run": runs - len(rows), "by_status": counts,
        "wall_time_s": wall, "runs_per_second": len(rows) / wall if wall > 0 else None,
        "seed": seed, "vary": {b.key: b.width for b in bands}, "workers": workers.label,
        "spread": spread, "scene": _scene_record(scene), "versions": _versions(workers),
    }


def _scene_record(scene: Scene | MechanismScene) -> Any:
    """The scene as plain JSON values (paths as strings, tuples as lists)."""
    return json.loads(json.dumps(scene_table(scene), default=str))


def _versions(workers: Workers) -> dict[str, str]:
    found = versions()
    if workers.dask:
        from importlib.metadata import version

        found.update(dask=version("dask"), distributed=version("distributed"))
    return found


def _write_table(out: RunFolder, rows: list[dict[str, Any]]) -> None:
    """``runs.json`` (a list of rows) and ``runs.csv`` (columns: every key of any row, in the order
    first seen; a row without one leaves it empty)."""
    out.write_text("runs.json", "[\n" + ",\n".join(strict_json(row, indent=None) for row in rows) + "\n]\n")  # a row a line
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(columns), restval="", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    out.write_text("runs.csv", text.getvalue())
