"""What every experiment kind provides, and what its run leaves for the run folder."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...dynamics.result import Result
from ...dynamics.telemetry import Arrays

#: ``progress(k)``: called with the number of steps done: 0 as the loop starts (when the run's
#: ``wall_time_s`` starts), then about 200 times, the last one at the end of the loop.
Progress = Callable[[int], None]
#: ``checkpoint(chunk)``: called with the telemetry, chunk by chunk, as the run goes.
Checkpoint = Callable[[Arrays], None]


@dataclass(kw_only=True)
class Outcome(Result):
    """A scene's result: what its run computed, whatever its status (the fields of
    :class:`~freefloat.dynamics.result.Result`: ``telemetry`` written as ``telemetry.npz``,
    ``summary`` as ``summary.json``, ``folder`` once written), and how to write and draw it.

    Attributes:
        names: names stored beside the arrays in ``telemetry.npz`` (joints, end-effectors,
            actuators), as ``meta_<key>``.
        provenance: what made the run besides the scene and versions (robot or mechanism,
            settings), added to ``summary.json``.
        headline: summary keys the command line prints.
        extra_telemetry: further telemetry, written as ``telemetry_<name>.npz``.
        figures: ``figures(folder) -> files``: the run's figures, or None.
        page: ``page(path, fps) -> path``: the run's animation page, or None.
        written: the files written into ``folder`` (none when nothing was written).
        skipped: the drawings left out (an interrupt while writing).
        interrupted_writing: an interrupt (Ctrl-C, SIGTERM, SIGHUP) came while the folder was
            written.
    """

    names: dict[str, Any]
    provenance: dict[str, dict[str, Any]]
    headline: tuple[str, ...]
    extra_telemetry: dict[str, Arrays] = field(default_factory=dict)
    figures: Callable[[Path], list[Path]] | None = None
    page: Callable[[Path, float], Path] | None = None
    written: list[Path] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    interrupted_writing: bool = False


@dataclass(frozen=True)
class Experiment:
    """One kind of experiment: which scenes it takes, and how one is prepared and run.

    Attributes:
        name: the kind (``scene.kind`` of the scenes it runs).
        description: one line for listings.
        scenes: which scenes it takes, in words (the message refusing a scene's ``kind``).
        takes: ``takes(scene) -> bool``: whether it runs ``scene``, from the scene's sections
            (never from its ``kind``): exactly one registered experiment takes a scene that does
            not name its ``kind`` (:func:`freefloat.app.scenes.kinds.kind_of`).
        sections: scene sections it reads besides the built-in ones (a plug-in's own tables):
            name -> frozen dataclass whose fields are the section's keys (defaults; units in its
            docstring), validated as a built-in section is; the parsed settings are
            ``scene.sections[name]``. It never takes a scene with a section it does not read.
        prepare: ``prepare(scene) -> setup``: everything resolved before the loop (files,
            robot or mechanism, initial state, controller); raises ``SceneError`` naming the key.
        steps: ``steps(scene) -> int``: how many steps ``progress`` counts to.
        run: ``run(setup, progress, checkpoint) -> Outcome``: the loop, its summary and its
            drawings; a run that diverges or is interrupted returns what it computed.
        headline: every summary key the command line may print for a run of this kind (an
            outcome's ``headline`` is those its run has).
        units: the unit of each summary key of this kind's runs ("" for a pure number or a text),
            from the modules that compute them; the command line prints it beside the value.
    """

    name: str
    description: str
    scenes: str
    takes: Callable[[Any], bool]
    prepare: Callable[[Any], Any]
    steps: Callable[[Any], int]
    run: Callable[[Any, Progress | None, Checkpoint | None], Outcome]
    headline: tuple[str, ...] = ()
    units: dict[str, str] = field(default_factory=dict)
    sections: dict[str, type] = field(default_factory=dict)
