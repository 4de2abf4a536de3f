"""The output folder of a run: telemetry, summary with provenance, figures, animation."""

from __future__ import annotations

import dataclasses
import json
import platform
import sys
import time
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Callable

import numpy as np

from .mechanism_runner import MechanismRun, PreparedMechanism
from .parallel.closed_chain import ClosedChain
from .runner import Prepared
from .scenes import MechanismScene, Scene
from .simulation import RunResult

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


def write_run(
    out_dir: Path, scene: Scene, prepared: Prepared, result: RunResult, summary: dict[str, object]
) -> list[Path]:
    """Write ``telemetry.npz``, ``summary.json``, the scene, figures and ``trajectory.html``.

    Written whatever the run's status, so a diverged or interrupted run keeps what it computed.
    Returns the paths written.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    robot, tel = prepared.robot, result.telemetry
    written = [out_dir / "telemetry.npz"]
    tel.save(
        written[0], joint_names=list(robot.joint_names), end_effectors=list(robot.end_effectors),
        scene=scene.name,
    )
    for name, extra in prepared.extra_telemetry.items():
        extra.save(out_dir / f"telemetry_{name}.npz")
        written.append(out_dir / f"telemetry_{name}.npz")
    written += _write_provenance(out_dir, scene, summary, robot={
        "urdf": str(robot.urdf_path), "base": robot.base, "nq": robot.model.nq, "nv": robot.model.nv,
        "end_effectors": list(robot.end_effectors), "loader_notes": list(robot.warnings)},
        settings={"integrator": prepared.integrator.name, "model": prepared.model.name,
                  "control_period": scene.simulation.control_period})
    if len(tel.t) >= 2 and scene.output.figures:
        from .viz.figures import write_figures

        written += write_figures(robot, tel, out_dir)
    if len(tel.t) >= 2 and scene.output.html:
        from .viz.meshcat_html import write_trajectory_html

        t, q = prepared.animation or (tel.t, tel.q)
        written.append(write_trajectory_html(robot, t, q, out_dir / "trajectory.html", fps=scene.output.html_fps,
                                             extra=prepared.extra_bodies or None))
    return written


def write_mechanism_run(out_dir: Path, scene: MechanismScene, prepared: PreparedMechanism, run: MechanismRun,
                        summary: dict[str, object]) -> list[Path]:
    """Write a mechanism run: ``telemetry.npz`` (:class:`~freefloat.telemetry.MechanismTelemetry`,
    with the joint and actuator names), ``summary.json``, the scene, figures and
    ``trajectory.html``, whatever the run's status. Returns the paths written."""
    from .viz.mechanism import write_mechanism_figures, write_mechanism_html

    out_dir.mkdir(parents=True, exist_ok=True)
    chain, tel = prepared.setup.display, run.telemetry
    joints = _joint_names(chain, len(prepared.q0))
    actuated = [chain.model.names[j] for j in chain.actuated]
    written = [out_dir / "telemetry.npz"]
    tel.save(written[0], joint_names=joints, actuated=actuated, scene=scene.name)
    written += _write_provenance(out_dir, scene, summary, mechanism={
        "name": scene.mechanism.name, "closure": str(prepared.closure), "plant": scene.mechanism.plant,
        "platform_coordinates": prepared.setup.nominal.p, "joints": joints, "actuated": actuated},
        settings={"integrator": scene.simulation.integrator, "step": scene.simulation.step,
                  "baumgarte": scene.simulation.baumgarte, "controller": scene.controller.kind})
    if len(tel.t) >= 2 and scene.output.figures:
        written += write_mechanism_figures(tel, out_dir)
    if len(tel.t) >= 2 and scene.output.html:
        q = np.hstack((tel.platform, tel.joints))
        written.append(write_mechanism_html(chain, tel.t, q, out_dir / "trajectory.html", scene.output.html_fps))
    return written


def _joint_names(chain: ClosedChain, n_q: int) -> list[str]:
    """Name of the tree joint behind each of Orsino's joint coordinates ``q°`` (n_q - p), from
    :attr:`ClosedChain.joint_coordinates` (the first joint where several share one coordinate)."""
    owner = {i: chain.model.names[j] for j, i in sorted(chain.joint_coordinates.items(), reverse=True)}
    return [owner.get(i, "?") for i in range(chain.mechanism.p, n_q)]


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
