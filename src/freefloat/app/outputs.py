"""The one writer of run folders: telemetry, summary with provenance, figures, animation page;
and of the reproduce reports."""

from __future__ import annotations

import dataclasses
import json
import platform
import sys
import time
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Callable

from ..errors import FreefloatError
from .experiments.base import Outcome
from .scenes import MechanismScene, Scene

PACKAGES = ("freefloat", "pin", "numpy", "scipy", "meshcat", "example-robot-data", "yourdfpy")


def versions() -> dict[str, str]:
    """Versions of Python and of the packages that shape the numbers."""
    out = {"python": sys.version.split()[0], "platform": platform.platform()}
    for name in PACKAGES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def write_report(out: Path, report: dict, markdown: Callable[[dict], str], start: float) -> dict:
    """Stamp ``versions`` and ``wall_time_s`` (seconds since ``start``, a ``time.perf_counter()``
    reading) on a reproduce report, then write ``report.json`` and ``report.md`` (the text of
    ``markdown(report)``) into ``out``. Returns the report."""
    report["versions"] = versions()
    report["wall_time_s"] = time.perf_counter() - start
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.json").write_text(json.dumps(report, indent=2))
    (out / "report.md").write_text(markdown(report))
    return report


def prepare_folder(folder: Path) -> None:
    """Create the output folder before a run and check that files can be written there.

    Raises:
        FreefloatError: naming the folder when it is a file, sits under one, or is not writable.
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".freefloat-write-check"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise FreefloatError(f"output folder '{folder}' cannot be written: {exc.strerror or exc}") from exc


def write_run(out_dir: Path, scene: Scene | MechanismScene, outcome: Outcome) -> list[Path]:
    """Write ``telemetry.npz`` (with the outcome's names), any further telemetry,
    ``summary.json`` (summary, scene, provenance, versions), the scene file as run, the figures
    and ``trajectory.html``.

    Written whatever the run's status, so a diverged or interrupted run keeps what it computed;
    figures and page need two samples or more. Returns the paths written.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    tel = outcome.telemetry
    written = [out_dir / "telemetry.npz"]
    tel.save(written[0], **outcome.names, scene=scene.name)
    for name, extra in outcome.extra_telemetry.items():
        extra.save(out_dir / f"telemetry_{name}.npz")
        written.append(out_dir / f"telemetry_{name}.npz")
    written += _write_provenance(out_dir, scene, outcome.summary, **outcome.provenance)
    if len(tel.t) >= 2 and scene.output.figures and outcome.figures is not None:
        written += outcome.figures(out_dir)
    if len(tel.t) >= 2 and scene.output.html and outcome.page is not None:
        written.append(outcome.page(out_dir / "trajectory.html", scene.output.html_fps))
    return written


def _write_provenance(out_dir: Path, scene: Scene | MechanismScene, summary: dict[str, object],
                      **described: dict) -> list[Path]:
    """``scene.toml`` (the file as run, when there is one) and ``summary.json``: the summary plus
    the scene, the ``described`` parts (robot or mechanism, settings) and the package versions."""
    written = []
    if scene.source is not None:
        (out_dir / "scene.toml").write_text(scene.source.read_text())
        written.append(out_dir / "scene.toml")
    record = dict(summary)
    record.update(scene=_jsonable(dataclasses.asdict(scene)), **described, versions=versions())
    (out_dir / "summary.json").write_text(json.dumps(record, indent=2))
    return written + [out_dir / "summary.json"]


def _jsonable(value: object) -> object:
    """Paths to strings, tuples to lists, recursively."""
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return str(value) if isinstance(value, Path) else value
