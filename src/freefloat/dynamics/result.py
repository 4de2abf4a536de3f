"""What a run leaves behind: the one result type of the engine (:func:`freefloat.run`) and of a
scene (:func:`freefloat.simulate`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .telemetry import Arrays


@dataclass
class Result:
    """What a run computed, whatever its status.

    Attributes:
        telemetry: the recorded samples, all of them when the run stopped early:
            :class:`~.telemetry.Telemetry` for a robot, :class:`~.telemetry.PlantTelemetry` for a
            plant, a scene's own (e.g. :class:`~.telemetry.MechanismTelemetry`) for a scene.
        status: ``"completed"``, ``"stopped"`` (by the ``stop`` event), ``"diverged"`` or
            ``"interrupted"``.
        message: why the run stopped early (empty when completed).
        steps: control periods (robots) or integration steps (mechanisms) simulated.
        wall_time_s: wall-clock time of the loop, s.
        evaluations: dynamics-model calls made by the integrator (0 when not counted).
        backend: the loop that ran: ``"compiled"`` (:mod:`freefloat.dynamics.compiled`) or
            ``"python"``.
        summary: figures of merit (SI units) and the run's status: a scene's (what its
            ``summary.json`` holds), or, when none is given, the loop's own record
            (:meth:`loop_summary`).
        folder: the run folder written, or None when nothing was written.
    """

    telemetry: Arrays
    status: str
    message: str
    steps: int
    wall_time_s: float
    evaluations: int = 0
    backend: str = "python"
    summary: dict[str, Any] = field(default_factory=dict)
    folder: Path | None = None

    def __post_init__(self) -> None:
        if not self.summary:
            self.summary = self.loop_summary()

    def loop_summary(self) -> dict[str, Any]:
        """The loop's own record under the keys a scene's summary gives it: ``status``,
        ``message``, ``steps``, ``sim_wall_time_s`` (s), ``model_evaluations`` and ``loop``."""
        return {"status": self.status, "message": self.message, "steps": self.steps,
                "sim_wall_time_s": self.wall_time_s, "model_evaluations": self.evaluations, "loop": self.backend}

    @property
    def completed(self) -> bool:
        """True when the run did everything it was asked."""
        return self.status == "completed"
