"""The one writer of run folders: telemetry, summary with provenance, figures, animation page;
and of the reproduce reports."""

from __future__ import annotations

import functools
import json
import math
import platform
import shutil
import sys
import time
from collections.abc import Callable
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from ..errors import FreefloatError, RunFolderError
from . import figure_set
from .experiments.base import Outcome
from .run_folder import RunFolder
from .scenes import MechanismScene, Scene
from .scenes.as_run import scene_as_run, scene_table

PACKAGES = ("freefloat", "pin", "numpy", "scipy", "meshcat", "example-robot-data", "yourdfpy")


def versions() -> dict[str, str]:
    """Versions of Python and of the packages that shape the numbers (a new dict each call)."""
    return dict(_versions())


@functools.cache
def _versions() -> dict[str, str]:
    """:func:`versions`, read once per process (the package metadata scan took about 10 ms a call)."""
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
    (out / "report.json").write_text(strict_json(report))
    (out / "report.md").write_text(markdown(report))
    return report


#: What :func:`write_run` writes, in order, by stage name (its ``stage`` callback's argument):
#: ``figures`` when this process draws them, ``figures_meanwhile`` when the figure helper drew
#: them while the data and the page were written (the stage is then the wait for the rest).
STAGES = {"data": "telemetry.npz, summary.json, scene.toml", "figures": "figures",
          "trajectory.html": "the page trajectory.html", "figures_meanwhile": "figures, drawn meanwhile"}


def write_run(folder: RunFolder, scene: Scene | MechanismScene, outcome: Outcome,
              interrupted: Callable[[], bool] = lambda: False,
              stage: Callable[[str], None] = lambda name: None) -> tuple[list[Path], list[str]]:
    """Write ``telemetry.npz`` (with the outcome's names), any further telemetry,
    ``summary.json`` (summary, scene, provenance, versions; strict JSON), ``scene.toml`` (the
    scene as it ran: :func:`~.scenes.as_run.scene_as_run`),
    the figures the scene chose and its task calls for (:func:`.figure_set.drawn`) and
    ``trajectory.html``, each file atomically.

    The figures go first to the figure helper (:mod:`.viz.rendering`), which draws them while
    this process writes the data and the page, when the outcome's figures are one picklable job
    (a robot run's :class:`~.viz.figure_job.RobotFigures`); else they are drawn here, after the
    data. Written whatever the run's status, so a diverged or interrupted run keeps what it
    computed; figures and page need two samples or more, and are skipped once ``interrupted()``
    is true (a second Ctrl-C while writing) or when drawing them fails (listed with the reason).
    ``stage`` is called with the name of each stage as it starts (:data:`STAGES`).
    Returns the paths written (data, figures, page) and what was skipped.
    """
    tel = outcome.telemetry
    drawn = len(tel.t) >= 2
    figures = drawn and bool(scene.output.figures) and outcome.figures is not None
    meanwhile = _Meanwhile(folder, outcome, scene) if figures and not interrupted() else None
    stage("data")
    written = [folder.save("telemetry.npz", tel, **outcome.names, scene=scene.name)]
    folder.drop_checkpoints()
    for name, extra in outcome.extra_telemetry.items():
        written.append(folder.save(f"telemetry_{name}.npz", extra))
    written.append(folder.write_text("scene.toml", scene_as_run(scene, outcome.summary.get("model_choice"))))
    record = dict(outcome.summary)
    record.update(scene=_jsonable(scene_table(scene)), **outcome.provenance, versions=versions())
    written.append(folder.write_text("summary.json", strict_json(record)))
    drawings = []
    if figures and (meanwhile is None or not meanwhile.sent):
        drawings.append(("figures", lambda: _draw(folder, lambda into: _figures(outcome, scene, into))))
    if drawn and scene.output.html and outcome.page is not None:
        drawings.append(("trajectory.html", lambda: _draw(folder, lambda into: [
            outcome.page(into / "trajectory.html", scene.output.html_fps)])))
    if meanwhile is not None and meanwhile.sent:
        drawings.append(("figures_meanwhile", meanwhile.finish))
    skipped, made = [], {}
    for what, draw in drawings:
        label = "figures" if what == "figures_meanwhile" else what
        if interrupted():
            if what == "figures_meanwhile":
                meanwhile.abandon()
            skipped.append(label)
            continue
        stage(what)
        try:
            made[what] = draw()
        except FreefloatError:
            raise  # the disk refused a file: named, exit 2
        except Exception as exc:  # a drawing that fails must not cost the run its data, already written
            skipped.append(f"{label} (failed: {type(exc).__name__}: {exc})")
    for what in ("figures", "figures_meanwhile", "trajectory.html"):
        written += made.get(what, [])
    return written, skipped


#: Largest figure job sent to the figure helper, bytes pickled (the default job's: 5.7 MB); a
#: larger run's figures are drawn in its own process, from the telemetry it already holds.
JOB_BYTES = 64 * 2**20


class _Meanwhile:
    """A run's figures sent to the figure helper, to be drawn there while this process writes the
    rest (:attr:`sent`; False when the outcome's figures do not pickle or exceed
    :data:`JOB_BYTES`: they are then drawn here)."""

    def __init__(self, folder: RunFolder, outcome: Outcome, scene: Scene | MechanismScene) -> None:
        from .viz import rendering
        from .viz.figure_job import draw_chosen

        self.folder = folder
        self.into = folder.private_dir().absolute()  # the helper's working folder may be another
        self.renderer = rendering.Renderer(draw_chosen)
        self.sent = self.renderer.send(outcome.figures, frozenset(figure_set.drawn(scene)),
                                       scene.output.figure_formats, self.into, max_bytes=JOB_BYTES)
        if not self.sent:
            self.renderer.close()
            shutil.rmtree(self.into, ignore_errors=True)

    def finish(self) -> list[Path]:
        """Wait for the figures (drawn here from the job as sent if the helper failed on it) and
        move each into the folder."""
        try:
            (paths,) = self.renderer.collect()
            return [self.folder.place(path) for path in paths]
        except OSError as exc:
            raise RunFolderError(f"could not write into '{self.folder.path}': {exc.strerror or exc}") from exc
        finally:
            shutil.rmtree(self.into, ignore_errors=True)

    def abandon(self) -> None:
        """Drop the figures: the helper is ended, nothing is placed."""
        self.renderer.abandon()
        shutil.rmtree(self.into, ignore_errors=True)


def _figures(outcome: Outcome, scene: Scene | MechanismScene, into: Path) -> list[Path]:
    """The run's figures that ``[output] figures`` chose and its task calls for
    (:func:`.figure_set.drawn`), in its ``figure_formats``."""
    from .viz.plotting import choose

    with choose(frozenset(figure_set.drawn(scene)), scene.output.figure_formats):
        return outcome.figures(into)


def _draw(folder: RunFolder, draw: Callable[[Path], list[Path]]) -> list[Path]:
    """Files ``draw(into)`` makes in a private subfolder, each moved into ``folder`` when all
    are done (a drawing stopped half-way leaves nothing)."""
    into = folder.private_dir()
    try:
        return [folder.place(path) for path in draw(into)]
    except OSError as exc:
        raise RunFolderError(f"could not write into '{folder.path}': {exc.strerror or exc}") from exc
    finally:
        shutil.rmtree(into, ignore_errors=True)


def strict_json(record: dict, indent: int | None = 2) -> str:
    """``record`` as strict JSON (indented by ``indent``; None: one line each, which Python's
    compiled encoder writes, 5x faster on a large table): NaN and infinities become null."""
    return json.dumps(_finite_or_none(record), indent=indent, allow_nan=False)


def _finite_or_none(value: object) -> object:
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_or_none(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _jsonable(value: object) -> object:
    """Paths to strings, tuples to lists, recursively."""
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return str(value) if isinstance(value, Path) else value
