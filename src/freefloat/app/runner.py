"""The one way from a scene to a run folder: pick the scene's experiment, prepare it, run its
loop under a progress report, write whatever it computed.

The runner owns a run's life cycle. Before anything is simulated the output folder is created
and checked; a run that diverges, or is interrupted by Ctrl-C, SIGTERM or SIGHUP (what
``timeout``, batch schedulers and container stops send), ends with the status and message its
loop gives and keeps every computed sample in the folder.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator

from .experiments import Outcome, Progress, experiment_for
from .outputs import prepare_folder, write_run
from .scenes import MechanismScene, Scene


@dataclass
class SceneRun:
    """A finished run: its outcome and the files written to ``folder``."""

    outcome: Outcome
    folder: Path
    written: list[Path]


def prepare(scene: Scene | MechanismScene) -> Any:
    """Everything ``scene`` resolves to before its loop, by its experiment kind.

    Raises:
        SceneError: naming the key of whatever the scene gets wrong.
    """
    return experiment_for(scene).prepare(scene)


def total_steps(scene: Scene | MechanismScene) -> int:
    """Steps a progress report of ``scene`` counts to."""
    return experiment_for(scene).steps(scene)


def simulate(scene: Scene | MechanismScene, progress: Progress | None = None) -> Outcome:
    """Prepare and run ``scene``; its outcome, nothing written."""
    experiment = experiment_for(scene)
    setup = experiment.prepare(scene)
    with interrupts_as_keyboard_interrupt():
        return experiment.run(setup, progress)


def run_scene(scene: Scene | MechanismScene, folder: Path, progress: Progress | None = None) -> SceneRun:
    """Run ``scene`` and write its folder (telemetry, summary, scene, figures, page) whatever the
    run's status.

    Raises:
        FreefloatError: before anything is simulated, when the scene is wrong (``SceneError``) or
            the folder cannot be written.
    """
    prepare_folder(folder)
    outcome = simulate(scene, progress)
    return SceneRun(outcome, folder, write_run(folder, scene, outcome))


@contextlib.contextmanager
def interrupts_as_keyboard_interrupt() -> Iterator[None]:
    """SIGTERM and SIGHUP raise ``KeyboardInterrupt`` inside the block, as Ctrl-C does, so that a
    loop stopped by either keeps what it computed (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    names = [name for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]
    previous = {name: signal.signal(getattr(signal, name), interrupt) for name in names}
    try:
        yield
    finally:
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)
