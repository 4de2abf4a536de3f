"""What every experiment kind provides, and what its run leaves for the run folder."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ...dynamics.telemetry import Arrays

#: ``progress(k)``: called with the number of steps done: 0 as the loop starts (when the run's
#: ``wall_time_s`` starts), then about 200 times, the last one at the end of the loop.
Progress = Callable[[int], None]
#: ``checkpoint(chunk)``: called with the telemetry, chunk by chunk, as the run goes.
Checkpoint = Callable[[Arrays], None]


@dataclass
class Outcome:
    """What a run computed, whatever its status, and how to draw it.

    Attributes:
        telemetry: the run's samples (all of them when it stopped early), written as
            ``telemetry.npz``.
        status: ``"completed"``, ``"stopped"``, ``"diverged"`` or ``"interrupted"``.
        message: why the run stopped early (empty when completed).
        steps: control periods (robots) or integration steps (mechanisms) simulated.
        wall_time_s: wall-clock time of the simulation, s.
        summary: figures of merit (SI units) and the run's status, written to ``summary.json``.
        names: names stored beside the arrays in ``telemetry.npz`` (joints, end-effectors,
            actuators), as ``meta_<key>``.
        provenance: what made the run besides the scene and versions (robot or mechanism,
            settings), added to ``summary.json``.
        headline: summary keys the command line prints.
        extra_telemetry: further telemetry, written as ``telemetry_<name>.npz``.
        figures: ``figures(folder) -> files``: the run's figures, or None.
        page: ``page(path, fps) -> path``: the run's animation page, or None.
    """

    telemetry: Arrays
    status: str
    message: str
    steps: int
    wall_time_s: float
    summary: dict[str, Any]
    names: dict[str, Any]
    provenance: dict[str, dict[str, Any]]
    headline: tuple[str, ...]
    extra_telemetry: dict[str, Arrays] = field(default_factory=dict)
    figures: Callable[[Path], list[Path]] | None = None
    page: Callable[[Path, float], Path] | None = None

    @property
    def completed(self) -> bool:
        """True when the run did everything the scene asked."""
        return self.status == "completed"


@dataclass(frozen=True)
class Experiment:
    """One kind of experiment: how a scene of that kind is prepared and run.

    Attributes:
        kind: the scene kind it runs (``scene.kind``).
        description: one line for listings.
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

    kind: str
    description: str
    prepare: Callable[[Any], Any]
    steps: Callable[[Any], int]
    run: Callable[[Any, Progress | None, Checkpoint | None], Outcome]
    headline: tuple[str, ...] = ()
    units: dict[str, str] = field(default_factory=dict)
