"""The free-floating bench scenes as :class:`~..race.scene.BenchScene`: what each sweeps and how its
errors are measured.

``four_arm`` and ``dual_arm`` tumble torque-free with non-zero momentum (:mod:`.tumbling`),
``controlled`` follows a quintic under computed torque (:mod:`.controlled`), ``detumbling`` is the
post-capture detumbling (:mod:`.detumbling`). Errors are taken at the end of the run against
freefloat's dopri5 at rtol 1e-13: the state (Pinocchio's ``difference``), the momentum ``[P; L]``
about the inertial origin, the kinetic energy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import pinocchio as pin

from ....dynamics.integrators import swept
from ....errors import InvalidArgument, did_you_mean
from ....robot.conventions import momentum_about_origin
from ..race.scene import Method, Run
from . import notes
from .controlled import controlled_scene
from .detumbling import detumbling_scene
from .methods import MUJOCO, REFERENCE_ATOL, REFERENCE_RTOL, Scene, controlled_methods, method_run, methods, reference
from .tumbling import ROBOTS, tumbling_scene

State = tuple[np.ndarray, np.ndarray]

#: Steps (s) and dopri5 tolerances of a tumbling sweep, full and ``--quick``.
STEPS = (2e-1, 1e-1, 5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4)
RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
QUICK_STEPS = (2e-2, 1e-2, 5e-3)
QUICK_RTOLS = (1e-6, 1e-9)
#: Integration steps of the controlled scenes (s, dividing their 1 ms period) and dopri5 tolerances.
CONTROLLED_STEPS = (1e-3, 5e-4, 2e-4, 1e-4)
CONTROLLED_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10)
QUICK_CONTROLLED_STEPS = (1e-3, 5e-4)
QUICK_CONTROLLED_RTOLS = (1e-6,)
#: The dissertation's hand-built models a tumbling sweep also runs (RKMK4, Python loop), from
#: ``freefloat.dynamics.models.MODELS``: exact (corrected), as printed, conserved momentum.
TUMBLING_MODELS = ("standard_corrected", "standard", "momentum_mono")
#: Steps at which those models run (their cost makes the finest steps long).
MODEL_STEPS = (5e-2, 2e-2, 1e-2, 5e-3, 2e-3, 1e-3)

#: ``Method.model`` of the planar-base variant of a planar scene (controlled, detumbling).
PLANAR = "planar base"

#: Every free-floating bench scene with its note.
NOTES = notes("free_floating")


def invariants(model: pin.Model, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
    """Momentum ``[P; L about the origin]`` (6,) and kinetic energy (J) at ``(q, v)``."""
    data = model.createData()
    return momentum_about_origin(model, data, q, v), float(pin.computeKineticEnergy(model, data, q, v))


def state_errors(model: pin.Model, state: State, ref: State) -> dict[str, float]:
    """``state_error`` ``|[log(q_ref^-1 q); v - v_ref]|`` (Pinocchio's difference, 2-norm),
    ``momentum_error`` ``|h - h_ref|`` (kg m/s, kg m^2/s) and ``energy_error`` ``|E - E_ref|`` (J)."""
    (q, v), (q_ref, v_ref) = state, ref
    h, e = invariants(model, q, v)
    h_ref, e_ref = invariants(model, q_ref, v_ref)
    return {"state_error": float(np.linalg.norm(np.concatenate([pin.difference(model, q_ref, q), v - v_ref]))),
            "momentum_error": float(np.linalg.norm(h - h_ref)), "energy_error": abs(e - e_ref)}


def planar_to_free(q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The free-base Pinocchio state of a planar-base one.

    Planar: ``q = [x, y, cos t, sin t; joints]``, ``v = [vx, vy, wz; joint rates]`` (base frame).
    Free: ``q = [x, y, 0, quat (0, 0, sin t/2, cos t/2); joints]``, ``v = [vx, vy, 0, 0, 0, wz; joint
    rates]`` (base frame). Shapes (nq,), (nv,) in, (nq + 3,), (nv + 3,) out.
    """
    half = 0.5 * np.arctan2(q[3], q[2])
    q_free = np.concatenate([q[:2], [0.0, 0.0, 0.0, np.sin(half), np.cos(half)], q[4:]])
    v_free = np.concatenate([v[:2], [0.0, 0.0, 0.0], v[2:]])
    return q_free, v_free



@dataclass(frozen=True)
class FreeFloatingBench:
    """A free-floating robot's bench scene.

    Attributes:
        scene: what runs (robot, initial state, duration; controller and wrenches if any).
        note: one line for the report.
        sweep: the methods swept.
        settings: the sweep's settings, for ``bench.json``.
        variants: other plants of the same scene by ``Method.model`` (e.g. ``"planar base"``): the
            scene they run and the map of their final state into :attr:`scene`'s coordinates.
    """

    scene: Scene
    note: str
    sweep: tuple[Method, ...]
    settings: dict
    variants: dict[str, tuple[Scene, Callable[[np.ndarray, np.ndarray], State]]] = field(default_factory=dict)
    secondary = ("momentum_error", "momentum error, kg m/s and kg m^2/s")

    @property
    def name(self) -> str:
        """The scene's name."""
        return self.scene.name

    def methods(self) -> list[Method]:
        """The methods swept."""
        return list(self.sweep)

    def run(self, method: Method) -> Run:
        """The run of ``method`` (on a variant's plant when its ``model`` names one)."""
        if method.model in self.variants:
            scene, to_main = self.variants[method.model]
            run = method_run(scene, replace(method, model=""))
            return lambda: to_main(*run())
        return method_run(self.scene, method)

    def reference(self) -> State:
        """Final state by dopri5 at rtol 1e-13 (:func:`.methods.reference`)."""
        return reference(self.scene)

    def errors(self, result: State, reference: State) -> dict[str, float]:
        """State, momentum and energy errors (:func:`state_errors`)."""
        return state_errors(self.scene.model, result, reference)


def _settings(duration: float, steps: tuple[float, ...], rtols: tuple[float, ...], **more) -> dict:
    return {"duration_s": duration, "steps_s": steps, "dopri5_rtols": rtols,
            "reference": {"integrator": "dopri5", "rtol": REFERENCE_RTOL, "atol": REFERENCE_ATOL}, **more}


def _detumbling_methods(steps: tuple[float, ...], rtols: tuple[float, ...]) -> list[Method]:
    """The compiled loop's fixed-step methods and dopri5, the Python loop's RKMK4, the planar
    base (:func:`_planar_methods`), and MuJoCo stepped by freefloat's controller."""
    points = [Method("freefloat", name, h, "compiled") for name in ("euler", "rkmk4", "rkmk8") for h in steps]
    points += [Method("freefloat", name, rtol, "compiled") for name in swept("compiled", True) for rtol in rtols]
    points += [Method("freefloat", "rkmk4", h) for h in steps]
    return points + _planar_methods(steps) + [Method("mujoco", name, h) for name in MUJOCO for h in steps]


def _planar_methods(steps: tuple[float, ...]) -> list[Method]:
    """The compiled loop's Euler and RKMK4 on the scene's planar-base variant."""
    return [Method("freefloat", name, h, "compiled", PLANAR) for name in ("euler", "rkmk4") for h in steps]


def free_floating_scene(name: str, duration: float | None = None, quick: bool = False,
                        seed: int = 0) -> FreeFloatingBench:
    """The bench scene ``name`` of :data:`NOTES`.

    Args:
        duration: simulated time, s (default 1 s; 0.1 s with ``quick``, 0.05 s for detumbling).
        quick: three steps and two tolerances (two and one on controlled scenes): a smoke sweep.
        seed: initial-state seed of the tumbling scenes.

    Raises:
        InvalidArgument: unknown name (lists the valid ones) or a bad duration.
    """
    if name not in NOTES:
        raise InvalidArgument(f"unknown bench scene '{name}'{did_you_mean(name, NOTES)}")
    if name in ROBOTS:
        duration = duration or (0.1 if quick else 1.0)
        steps, rtols = (QUICK_STEPS, QUICK_RTOLS) if quick else (STEPS, RTOLS)
        model_steps = steps if quick else MODEL_STEPS
        sweep = methods(steps, rtols) + [Method("freefloat", "rkmk4", h, model=model)
                                         for model in TUMBLING_MODELS for h in model_steps]
        return FreeFloatingBench(tumbling_scene(name, duration, seed), NOTES[name], tuple(sweep),
                                 _settings(duration, steps, rtols, seed=seed, models=TUMBLING_MODELS,
                                           model_steps_s=model_steps))
    steps, rtols = (QUICK_CONTROLLED_STEPS, QUICK_CONTROLLED_RTOLS) if quick else (CONTROLLED_STEPS, CONTROLLED_RTOLS)
    if name == "controlled":
        duration = duration or (0.1 if quick else 1.0)
        sweep = controlled_methods(steps, rtols) + _planar_methods(steps)
        return FreeFloatingBench(controlled_scene(duration), NOTES[name], tuple(sweep), _settings(duration, steps, rtols),
                                 {PLANAR: (controlled_scene(duration, "planar"), planar_to_free)})
    duration = duration or (0.05 if quick else 1.0)
    planar = detumbling_scene(duration, "planar")
    return FreeFloatingBench(detumbling_scene(duration), NOTES[name], tuple(_detumbling_methods(steps, rtols)),
                             _settings(duration, steps, rtols), {PLANAR: (planar, planar_to_free)})
