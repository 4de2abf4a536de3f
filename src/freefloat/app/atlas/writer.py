"""The files of an atlas's output folder: ``atlas.npz`` (the axes and every array), ``summary.json``
(settings, grid, versions, wall time and the kind's summary), ``summary.csv`` (the summary's scalar
entries) and the kind's figures, each written whole under its name (see
:class:`~freefloat.app.run_folder.RunFolder`)."""

from __future__ import annotations

import csv
import io
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..outputs import strict_json, versions
from ..run_folder import RunFolder
from .grid import Grid

DATA, SUMMARY, TABLE = "atlas.npz", "summary.json", "summary.csv"


def write_outputs(folder: RunFolder, grid: Grid, result: dict[str, np.ndarray], summary: dict, started: float,
                  figures: Callable[[Path], list[Path]]) -> list[Path]:
    """Write the data, the summary (with the wall time since ``started``, a ``perf_counter``
    reading, and the versions) and the figures ``figures(into)`` draws into a private folder;
    the paths written."""
    written = []
    with folder.atomic(DATA) as partial, open(partial, "wb") as file:
        np.savez(file, **{f"axis_{axis.name}": axis.values() for axis in grid.axes}, **result)
    written.append(folder.path / DATA)
    making = folder.private_dir()
    try:
        drawn = [folder.place(path) for path in figures(making)]
    finally:
        shutil.rmtree(making, ignore_errors=True)
    record = {**summary, "figures": [p.name for p in drawn], "wall_time_s": time.perf_counter() - started,
              "versions": versions()}
    written.append(folder.write_text(SUMMARY, strict_json(record)))
    table = io.StringIO()
    csv.writer(table, lineterminator="\n").writerows([("key", "value"), *flat_scalars(record["summary"]).items()])
    written.append(folder.write_text(TABLE, table.getvalue()))
    return written + drawn


def flat_scalars(record: dict, prefix: str = "") -> dict[str, object]:
    """The numbers, strings and booleans of a nested dict, keys joined with ``.``."""
    out: dict[str, object] = {}
    for key, value in record.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flat_scalars(value, name + "."))
        elif isinstance(value, (int, float, str, bool, np.integer, np.floating)):
            out[name] = value
    return out
