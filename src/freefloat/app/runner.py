"""The one way from a scene to a run folder: pick the scene's experiment, prepare it, run its
loop under a progress report, write whatever it computed.

The runner owns a run's life cycle:

- before anything is simulated, the scene is prepared (errors name the key) and the output
  folder is created, locked and checked (:class:`~freefloat.app.run_folder.RunFolder`);
- while the loop runs, telemetry is checkpointed into the folder chunk by chunk, and SIGTERM and
  SIGHUP (what ``timeout``, batch schedulers and container stops send) interrupt it as Ctrl-C
  does: the loop ends with the status and message it gives and keeps every computed sample;
- a run whose summary is not finite is a failure, whatever its loop said, and so is a completed
  run that breaks a conservation law its scene promises (:mod:`.conservation_check`);
- only the first interrupt stops the run (:func:`~freefloat.app.signals.stop_once`); a second
  one, or any that comes after the loop, skips the drawings still to come instead of losing the
  telemetry and summary.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..arguments import an_object
from ..dynamics.integrators import integrator_spec
from ..robot.loading import remembered_loads
from .conservation_check import check, checked
from .experiments import Outcome, Progress, experiment_for
from .experiments.model_choice import describe, resolve, with_plant
from .outputs import write_run
from .run_folder import RunFolder
from .scenes import DEFAULT_SCENE, MechanismScene, Scene, find_scene
from .scenes.mechanism_schema import ALIASES as MECHANISM_INTEGRATORS
from .signals import STOP_SIGNALS, signals_deferred, signals_raise_keyboard_interrupt, stop_once

__all__ = ["STOP_SIGNALS", "choose_plant", "fail_if_not_finite", "fail_if_unbalanced", "note_model_choice", "prepare",
           "resolved_setup", "signals_deferred", "signals_raise_keyboard_interrupt", "simulate", "total_steps"]



def prepare(scene: Scene | MechanismScene) -> Any:
    """Everything ``scene`` resolves to before its loop, by its experiment kind. A robot scene
    with ``simulation.model = "auto"`` is prepared with the exact plant here; :func:`simulate`
    then chooses its plant by a pilot run (:func:`choose_plant`).

    Raises:
        SceneError: naming the key of whatever the scene gets wrong.
    """
    if _auto(scene):
        scene = with_plant(scene, "exact", scene.simulation.lock)
    return experiment_for(scene).prepare(scene)


def choose_plant(scene: Scene | MechanismScene, setup: Any) -> Any:
    """The setup of ``scene`` with the plant ``simulation.model = "auto"`` chooses
    (:func:`~freefloat.app.experiments.model_choice.resolve`), carrying the record of the choice;
    ``setup`` itself when the scene names its model or the choice is made. The robot is loaded and
    checked once for the pilots and the chosen plant (:func:`~freefloat.robot.loading.remembered_loads`)."""
    if not _auto(scene) or setup.model_choice is not None:
        return setup
    with remembered_loads({}):
        resolved, record = resolve(scene)
        same = (record["model"], record["lock"]) == ("exact", scene.simulation.lock)  # what prepare() built
        chosen = setup if same else experiment_for(resolved).prepare(resolved)
    chosen.model_choice = record
    return chosen


def resolved_setup(scene: Scene | MechanismScene) -> Any:
    """The setup of ``scene`` with its plant chosen: :func:`prepare`, then :func:`choose_plant`.
    The one place ``simulation.model = "auto"`` is resolved, for every driver that runs a scene
    (:func:`simulate`, ``freefloat batch``'s runs).

    Raises:
        SceneError: naming the key of whatever the scene gets wrong.
    """
    return choose_plant(scene, prepare(scene))


def _auto(scene: Scene | MechanismScene) -> bool:
    return isinstance(scene, Scene) and scene.simulation.model == "auto"


def note_model_choice(outcome: Outcome, setup: Any) -> Outcome:
    """``outcome`` with the plant choice of ``setup`` (if it made one) in its summary:
    ``model_choice`` (the record) and ``model_auto`` (one line)."""
    record = getattr(setup, "model_choice", None)
    if record is not None:
        outcome.summary.update(model_choice=record, model_auto=describe(record))
    return outcome


def total_steps(scene: Scene | MechanismScene) -> int:
    """Steps a progress report of ``scene`` counts to."""
    return experiment_for(scene).steps(scene)


def simulate(scene: Scene | MechanismScene | str | Path = DEFAULT_SCENE, *, out: str | Path | None = None,
             overwrite: bool = False, progress: Progress | None = None,
             checkpoint: Callable[[Any], None] | None = None, setup: Any = None,
             stage: Callable[[str], None] = lambda name: None,
             summarised: Callable[[Outcome], None] = lambda outcome: None) -> Outcome:
    """Prepare and run ``scene``: the one way to run a scene, from Python as from
    ``freefloat simulate``. Nothing is written unless ``out`` is given; then ``out`` receives
    the run folder (telemetry, summary, the scene as run, figures, page), whatever the run's
    status, its telemetry checkpointed chunk by chunk as the run goes.

    Args:
        scene: a scene, a built-in scene's name or a scene file (default: the default job's).
        out: the run folder to write (a new or empty folder, or one of freefloat's runs with
            ``overwrite``), or None to write nothing.
        overwrite: replace the previous run freefloat wrote in ``out``.
        progress: as :data:`~.experiments.Progress`.
        checkpoint: given the telemetry chunk by chunk as the run goes (a live viewer).
        setup: the scene already prepared (:func:`prepare`), or None to prepare it here.
        stage: with ``out``, called as each writing stage starts (:data:`~.outputs.STAGES`), the
            first one when the simulation has ended.
        summarised: with ``out``, called with the outcome once its summary and status are final,
            before anything is written (``freefloat simulate`` prints the summary then, so that
            neither the files nor the figures hold it up).

    Returns:
        The :class:`~freefloat.dynamics.result.Result` (an :class:`~.experiments.Outcome`):
        ``summary``, ``telemetry``, ``status``, ``message``; with ``out`` also ``folder``, the
        files ``written`` and the drawings ``skipped``.

    Raises:
        FreefloatError: before anything is simulated, when the scene is wrong (``SceneError``) or
            ``out`` cannot be used; after the run, when the disk refuses a file.
    """
    scene = _scene(scene)
    if out is None:
        setup = resolved_setup(scene) if setup is None else choose_plant(scene, setup)
        with signals_raise_keyboard_interrupt():
            outcome = experiment_for(scene).run(setup, progress, checkpoint)
        return fail_if_unbalanced(fail_if_not_finite(note_model_choice(outcome, setup)), scene)
    folder = Path(an_object("out", out, "None or a folder's path", (str, os.PathLike)))
    setup = prepare(scene) if setup is None else setup
    if scene.output.figures:
        from .viz import rendering

        rendering.warm_up()  # the figure helper starts while the run simulates
    with RunFolder(folder, overwrite) as written, stop_once() as interrupts:
        try:
            setup = choose_plant(scene, setup)
        except KeyboardInterrupt:  # during the pilot: stop the run at its first report instead
            progress = _stop_at_first_report
        save = written.checkpoint if checkpoint is None else lambda chunk: (written.checkpoint(chunk), checkpoint(chunk))
        outcome = experiment_for(scene).run(setup, progress, save)
        seen = interrupts.defer()  # from here on an interrupt only skips the drawings, as a second one does
        outcome = fail_if_unbalanced(fail_if_not_finite(note_model_choice(outcome, setup)), scene)
        interrupted = lambda: interrupts.count >= 2 or interrupts.count > seen  # noqa: E731
        summarised(outcome)
        outcome.written, outcome.skipped = write_run(written, scene, outcome, interrupted, stage)
    outcome.folder, outcome.interrupted_writing = folder, interrupted()
    return outcome


def _scene(scene: Scene | MechanismScene | str | Path) -> Scene | MechanismScene:
    """``scene``, or the scene a built-in name or a file names (:func:`~.scenes.find_scene`)."""
    if isinstance(scene, (Scene, MechanismScene)):
        return scene
    return find_scene(an_object("scene", scene, "a Scene, a built-in scene's name or a scene file's path",
                                (str, os.PathLike)))


def _stop_at_first_report(done: int) -> None:
    """A progress callback that interrupts the run at its first periods done (the user asked to
    stop before it started; the rows so far are kept)."""
    if done:
        raise KeyboardInterrupt


def fail_if_not_finite(outcome: Outcome) -> Outcome:
    """``outcome``, marked ``"diverged"`` when a number of its summary is NaN or infinite (the
    state left the range where its numbers mean anything)."""
    bad = [key for key, value in outcome.summary.items() if not _finite(value)]
    if bad and outcome.status in ("completed", "stopped"):
        outcome.status = "diverged"
        outcome.message = f"non-finite results: {', '.join(bad)}"
        outcome.summary.update(status=outcome.status, message=outcome.message)
    return outcome


def fail_if_unbalanced(outcome: Outcome, scene: Scene | MechanismScene) -> Outcome:
    """``outcome`` with the integrator's order and step, the recorded rows' spacing and the scene's
    duration in its summary (``integrator_order``, ``integrator_step`` s, ``record_step`` s,
    ``duration`` s), the largest value over bound of
    its conserved quantities (``conservation_margin``), and marked ``"failed"`` when a completed run
    breaks one (:func:`~.conservation_check.check`: the message names the quantity, its value and
    its bound)."""
    sim = scene.simulation
    if isinstance(scene, MechanismScene):
        step, rows, integrator = sim.step, sim.step, MECHANISM_INTEGRATORS.get(sim.integrator, sim.integrator)
    else:
        step, rows, integrator = sim.control_period / sim.substeps, sim.control_period * sim.record_every, sim.integrator
    summary = outcome.summary
    summary.update(integrator_order=integrator_spec(integrator).order, integrator_step=float(step),
                   record_step=float(rows), duration=float(sim.duration))
    margins = checked(summary)
    if margins:
        summary["conservation_margin"] = max(c.margin for c in margins)
    message = check(summary)
    if message is not None and outcome.status == "completed":
        outcome.status, outcome.message = "failed", message
        summary.update(status=outcome.status, message=outcome.message)
    return outcome


def _finite(value: object) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, (list, tuple)):
        return all(_finite(v) for v in value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    return True
