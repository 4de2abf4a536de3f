"""What ``freefloat bench`` needs of a scene: the methods it sweeps, a run per method, a tight
reference and the errors of a run against it.

Every bench scene (free-floating robots in :mod:`..scenes.free_floating`, closed-chain mechanisms in
:mod:`..scenes.mechanisms`) is a :class:`BenchScene`; :mod:`.sweep` times the runs and :mod:`.report`
writes the folder, neither knowing what a scene simulates.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

#: A run of one method: built once, then each call simulates the scene from its initial state and
#: returns its result (whatever the scene's ``errors`` reads). A run that blows up raises an
#: ``ArithmeticError`` (or ``SimulationDiverged``) and then counts as diverged.
Run = Callable[[], Any]


@dataclass(frozen=True)
class Method:
    """One point of a sweep.

    Attributes:
        package: ``"freefloat"``, ``"pinocchio"`` (a bare Python loop of its calls) or ``"mujoco"``.
        integrator: integrator name in that package.
        setting: step h in s (fixed-step) or rtol (adaptive).
        loop: freefloat's ``"python"`` or ``"compiled"`` loop; for MuJoCo on a controlled scene,
            ``"python"`` (stepped by freefloat's Python-side controller) or ``"native"`` (the law on
            MuJoCo's own mass matrix and bias forces).
        model: the plant model when a scene sweeps several (a name of
            :data:`freefloat.dynamics.models.MODELS`, a mechanism formulation, a locked-joint
            reduction); empty for the scene's one exact model.
    """

    package: str
    integrator: str
    setting: float
    loop: str = "python"
    model: str = ""

    @property
    def label(self) -> str:
        """``package integrator [model] [loop]``, the curve a point belongs to."""
        return " ".join(part for part in (self.package, self.integrator, self.model,
                                          "" if self.loop == "python" else self.loop) if part)


class BenchScene(Protocol):
    """A scene the bench sweeps.

    Attributes:
        name: scene name (the CLI argument, file names).
        note: one line saying what runs and what differs from the document or URDF.
        secondary: ``(errors key, chart axis label)`` of the second chart panel (momentum for a
            free-floating robot, constraint drift for a closed chain).
        settings: the sweep's settings for ``bench.json`` (steps, tolerances, duration, ...).
        turns: optional; when true the methods take turns, one run each per round
            (:func:`.sweep.taking_turns`), instead of each method's runs in a row.
    """

    name: str
    note: str
    secondary: tuple[str, str]
    settings: dict

    def methods(self) -> list[Method]:
        """Every method of the sweep."""

    def run(self, method: Method) -> Run:
        """The run of ``method`` on this scene."""

    def reference(self) -> Any:
        """The tight reference result the errors are measured against."""

    def errors(self, result: Any, reference: Any) -> dict[str, float]:
        """Errors of ``result`` against ``reference``; ``"state_error"`` (the accuracy bands' metric)
        and the ``secondary`` key always, more if the scene has them."""
