"""Bench scenes of the closed-chain mechanisms: the 5R under sliding mode and the 2RSU+PPaP under
computed torque, the plants and controllers of their scene files, the law held over a control
period (the scene file's step for the 5R, 0.1 ms; 1 ms for the 2RSU+PPaP, its scene file's step).

Every method runs the same zero-order hold: the controller (:class:`PlatformControl` on the
nominal model, read in Orsino's coordinates) is evaluated every period and its efforts held
while the plant is integrated at a step that divides the period (:data:`SWEEPS`). Methods:

* ``freefloat``: Orsino's eq 129 (:class:`~freefloat.dynamics.plants.CoupledChainPlant`), model
  ``orsino baumgarte 100`` (lambda = 100 1/s) or ``orsino`` (lambda = 0); loop ``compiled`` (the
  whole closed loop in C++: plant, integrator and law; Euler, RKMK4, RKMK6, RKMK8) or ``python``
  (the one loop in Python on the numpy reference backend; Euler and RKMK4);
* ``pinocchio``: ``pin.constraintDynamics`` on the spanning tree
  (:class:`~freefloat.dynamics.plants.ConstraintDynamicsPlant`, Baumgarte 100) in the same Python
  loop, Euler and RKMK4;
* ``mujoco``: MuJoCo on the same tree with the closures as soft equality constraints
  (:mod:`.mechanism_mjcf`, :mod:`.mechanism_mujoco`), Euler, implicitfast and RK4.

The reference is the same held-law loop with each period integrated by the registry's ``dop853``
(scipy's DOP853, rtol and atol :data:`REFERENCE_TOL`) on Orsino's compiled model, Baumgarte 100. Errors
(:meth:`MechanismBench.errors`) are measured in the spanning tree's terms, the same way for every
method.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...dynamics.integrators import INTEGRATORS
from ...dynamics.plants import ConstraintDynamicsPlant, CoupledChainPlant, Plant
from ...dynamics.sampled import Sampled
from ...dynamics.simulation import run_plant
from ...errors import InvalidArgument, did_you_mean
from ...parallel.closed_loop import steps_per_period
from ..experiments.mechanism import PreparedMechanism, prepare
from ..scenes import find_scene
from .mechanism_mjcf import SOLIMP, TIMECONST_STEPS
from .mechanism_plants import ObservedController, SpanningTree, constraint_dynamics_plant, plant_model, spanning_tree
from .scene import Method, Run

#: Bench scene name -> note (what runs).
MECHANISM_SCENES = {
    "five_bar": "5R (scene five_bar_sliding_mode): sliding mode (eq 153, eq 187's gains) on the nominal model, "
                "plant 15 % off, circle of eq 189; law held over 0.1 ms (the scene file's step)",
    "rsu_ppap": "2RSU+PPaP (scene rsu_ppap_computed_torque, assumed geometry): computed torque (eq 190) on an exact "
                "model, 3 cm circle at 1 Hz; law held over 1 ms (the scene file's step)",
}


@dataclass(frozen=True)
class SweepSettings:
    """What one closed-chain bench scene sweeps.

    Attributes:
        scene: the built-in scene file (plant, controller, start, and the control period: the
            file's ``simulation.step``, over which the law is held).
        duration: default simulated time per run, s.
        steps: integration steps of the full sweep, s (each divides ``period``).
        numpy_steps: the numpy backend's steps (it costs ~150x the compiled core per call).
        quick_steps: the steps of every method with ``quick``.
    """

    scene: str
    duration: float
    steps: tuple[float, ...]
    numpy_steps: tuple[float, ...]
    quick_steps: tuple[float, ...]


#: Each scene's sweep. The 5R's law is held over its scene file's 0.1 ms: held over 1 ms, the
#: sliding-mode loop amplifies any difference ~50x every 50 ms (chattering), so that after 0.2 s
#: RK4's final-state error is O(1) at every step from 1 ms to 0.1 ms.
SWEEPS = {
    "five_bar": SweepSettings("five_bar_sliding_mode", 0.2, (1e-4, 5e-5, 2e-5, 1e-5), (1e-4, 5e-5), (1e-4, 5e-5)),
    "rsu_ppap": SweepSettings("rsu_ppap_computed_torque", 0.3, (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5),
                              (1e-3, 5e-4, 2e-4), (1e-3, 5e-4)),
}
#: Simulated time per run with ``quick``, s.
QUICK_DURATION = 0.02
#: Baumgarte lambda (1/s) of the stabilised models and of the reference.
BAUMGARTE = 100.0
#: DOP853's rtol and atol for the reference.
REFERENCE_TOL = 1e-12
#: freefloat's integrators swept with the compiled loop, and with the Python loops (numpy backend,
#: Pinocchio's constraintDynamics), whose runs cost far more.
COMPILED_INTEGRATORS = ("euler", "rkmk4", "rkmk6", "rkmk8")
PYTHON_INTEGRATORS = ("euler", "rkmk4")
#: MuJoCo's integrators compared (names as in MJCF) and the model label of its soft closures.
MUJOCO = ("Euler", "implicitfast", "RK4")
MUJOCO_MODEL = f"soft closures timeconst {TIMECONST_STEPS:g}h"


@dataclass(frozen=True)
class MechanismResult:
    """One run, in the spanning tree's coordinates.

    Attributes:
        q: tree configuration after every integration step, the start first (N + 1, nq).
        v: tree joint rates at the end (nv,).
    """

    q: np.ndarray
    v: np.ndarray


def held_run(plant: Plant, control: Any, q0: np.ndarray, v0: np.ndarray, duration: float, period: float,
             step: float, integrator: str, to_tree: Callable[[np.ndarray], np.ndarray], backend: str = "auto",
             rtol: float = 1e-10, atol: float = 1e-12) -> MechanismResult:
    """The closed loop from ``(q0, v0)`` (the plant's coordinates) for ``duration`` s in the one
    loop (:func:`~freefloat.dynamics.simulation.run_plant`): the law evaluated every ``period`` s and
    held, ``integrator`` at ``step`` s, a row per step; ``to_tree`` maps the plant's coordinates
    (and rates) to the tree's.

    Raises:
        FloatingPointError: when the run does not complete (a state not finite, the loop come
            apart, a singular pose), with the loop's message.
    """
    hold = steps_per_period(period, step)
    result = run_plant(plant, q0, v0, duration, step, integrator, control if hold == 1 else Sampled(control, hold),
                       rtol=rtol, atol=atol, backend=backend)
    if result.status != "completed":
        raise FloatingPointError(result.message)
    tel = result.telemetry
    return MechanismResult(to_tree(tel.q), to_tree(tel.v[-1]))


class MechanismBench:
    """A closed-chain bench scene (a :class:`~.scene.BenchScene`).

    Attributes:
        name, note, secondary, settings: see :class:`~.scene.BenchScene`.
        prepared: the scene file resolved (plant, nominal controller, assembled start).
        tree: the plant's spanning tree (shared coordinates, drift).
        duration: simulated time per run, s.
        period: control period, s.
        steps, numpy_steps: the sweep's integration steps, s (the numpy backend's).
    """

    secondary = ("constraint_drift", "largest loop-closure gap over the run, m")

    def __init__(self, name: str, prepared: PreparedMechanism, duration: float, period: float,
                 steps: tuple[float, ...], numpy_steps: tuple[float, ...]) -> None:
        self.name, self.note, self.prepared, self.duration = name, MECHANISM_SCENES[name], prepared, duration
        self.period, self.steps, self.numpy_steps = period, steps, numpy_steps
        scene = prepared.scene
        chain = prepared.setup.display
        model = plant_model(chain, scene.mechanism.name, scene.mechanism.plant)
        platform = chain_platform(prepared)
        self.tree: SpanningTree = spanning_tree(chain, model, *platform)
        self.settings = {"duration_s": duration, "control_period_s": period, "steps_s": list(steps),
                         "numpy_steps_s": list(numpy_steps), "baumgarte": BAUMGARTE,
                         "reference": {"integrator": "DOP853 per control period", "model": "orsino baumgarte 100",
                                       "rtol": REFERENCE_TOL, "atol": REFERENCE_TOL},
                         "mujoco": {"solref": f"timeconst {TIMECONST_STEPS:g} x step, dampratio 1",
                                    "solimp": list(SOLIMP)},
                         "state_error": "2-norm of [q#; actuated joints; their rates] at the end (m, rad, m/s, rad/s)"}

    def methods(self) -> list[Method]:
        """freefloat's compiled core with and without Baumgarte, its numpy reference (Baumgarte
        100, the coarser steps) and Pinocchio's constraint dynamics, each with RK4 and Euler;
        MuJoCo's three integrators."""
        out = []
        for integrator in COMPILED_INTEGRATORS:
            out += [Method("freefloat", integrator, h, "compiled", model)
                    for model in (f"orsino baumgarte {BAUMGARTE:g}", "orsino") for h in self.steps]
        for integrator in PYTHON_INTEGRATORS:
            out += [Method("freefloat", integrator, h, "python", f"orsino baumgarte {BAUMGARTE:g}")
                    for h in self.numpy_steps]
            out += [Method("pinocchio", integrator, h, "python", f"constraintDynamics baumgarte {BAUMGARTE:g}")
                    for h in self.steps]
        return out + [Method("mujoco", integrator, h, "python", MUJOCO_MODEL) for integrator in MUJOCO for h in self.steps]

    def plant(self, method: Method) -> CoupledChainPlant | ConstraintDynamicsPlant:
        """The plant ``method`` integrates: Orsino's on the compiled core (``compiled``: the whole
        loop in C++) or on its numpy reference (``python``), or Pinocchio's constraint dynamics.

        Raises:
            InvalidArgument: for a package, loop or model this scene does not have.
        """
        baumgarte = BAUMGARTE if "baumgarte" in method.model else 0.0
        mechanism = self.prepared.setup.plant
        if method.package == "freefloat" and method.loop in ("compiled", "python"):
            return CoupledChainPlant(mechanism if method.loop == "compiled" else mechanism.reference(), baumgarte)
        if method.package == "pinocchio":
            return constraint_dynamics_plant(self.tree, baumgarte)
        raise InvalidArgument(f"bench scene '{self.name}' has no method {method.label}")

    def _from_orsino(self, q: np.ndarray) -> np.ndarray:
        """Tree coordinates (..., nq) of Orsino's ``q`` (..., n_q) (also maps rates)."""
        return q[..., self.tree.from_orsino]

    def run(self, method: Method) -> Run:
        """Each call runs ``method`` from the assembled start.

        Raises:
            InvalidArgument: for an unknown method.
            FreefloatError: when MuJoCo's model does not have the tree's mass matrix.
        """
        control, tree = self.prepared.controller, self.tree
        if method.package == "mujoco" and method.integrator in MUJOCO:
            from .mechanism_mujoco import MujocoMechanism  # mujoco is the optional 'bench' extra

            q0, v0 = self.prepared.q0[tree.from_orsino], self.prepared.qd0[tree.from_orsino]
            sim = MujocoMechanism(tree, method.integrator, method.setting)
            sim.check_inertias(q0)
            observed = ObservedController(control, tree)
            return lambda: MechanismResult(*sim.run(observed, q0, v0, self.duration, self.period, method.setting))
        plant = self.plant(method)
        if method.integrator not in INTEGRATORS:
            raise InvalidArgument(f"bench scene '{self.name}': unknown integrator '{method.integrator}'"
                                  f"{did_you_mean(method.integrator, INTEGRATORS)}")
        q0, v0 = self.prepared.q0, self.prepared.qd0
        backend = "compiled" if method.loop == "compiled" else "python"
        if isinstance(plant, ConstraintDynamicsPlant):
            q0, v0, control = self._from_orsino(q0), self._from_orsino(v0), ObservedController(control, tree)
            return lambda: held_run(plant, control, q0, v0, self.duration, self.period, method.setting,
                                    method.integrator, lambda q: q, backend)
        return lambda: held_run(plant, control, q0, v0, self.duration, self.period, method.setting, method.integrator,
                                self._from_orsino, backend)

    def reference(self) -> MechanismResult:
        """DOP853 (the registry's ``dop853``) per control period on Orsino's compiled model,
        Baumgarte 100; rows at the period ends."""
        plant = CoupledChainPlant(self.prepared.setup.plant, BAUMGARTE)
        return held_run(plant, self.prepared.controller, self.prepared.q0, self.prepared.qd0, self.duration,
                        self.period, self.period, "dop853", self._from_orsino, "python", REFERENCE_TOL, REFERENCE_TOL)

    def errors(self, result: MechanismResult, reference: MechanismResult) -> dict[str, float]:
        """``state_error``: 2-norm of the difference of :meth:`SpanningTree.shared` at the end;
        ``constraint_drift``: the largest closure gap (m) over every step of the run;
        ``tracking_error``: ``|q#_d(T) - q#(T)|``, m, at the end of the run."""
        tree = self.tree
        end = tree.shared(result.q[-1], result.v)
        p = len(tree.axes)
        target = self.prepared.controller.reference(self.duration)
        return {"state_error": float(np.linalg.norm(end - tree.shared(reference.q[-1], reference.v))),
                "constraint_drift": max(tree.gap(q) for q in result.q),
                "tracking_error": float(np.linalg.norm(target - end[:p]))}


def chain_platform(prepared: PreparedMechanism) -> tuple[str, list[str]]:
    """The closure file's platform frame and coordinates (what q# is; :func:`prepare` checked them)."""
    platform = tomllib.loads(prepared.closure.read_text(encoding="utf-8"))["platform"]
    return platform["frame"], platform.get("coordinates", ["x", "y", "z"])


def mechanism_scene(name: str, duration: float | None = None, quick: bool = False) -> MechanismBench:
    """The closed-chain bench scene ``name`` (a key of :data:`MECHANISM_SCENES`).

    Args:
        duration: simulated time per run, s (None: the scene's :attr:`SweepSettings.duration`, or
            :data:`QUICK_DURATION` with ``quick``); a whole number of control periods.
        quick: a smoke sweep: :attr:`SweepSettings.quick_steps` for every method and a short run.

    Raises:
        InvalidArgument: an unknown name (lists the valid ones) or a duration that is not a
            positive whole number of control periods.
    """
    duration = scene_duration(name, MECHANISM_SCENES, "closed-chain", duration, quick, lambda: SWEEPS[name].duration)
    sweep = SWEEPS[name]
    prepared = prepare(find_scene(sweep.scene))
    period = prepared.scene.simulation.step  # the scene file's: the law is held over it
    whole_periods(name, duration, period)
    if quick:
        return MechanismBench(name, prepared, duration, period, sweep.quick_steps, sweep.quick_steps)
    return MechanismBench(name, prepared, duration, period, sweep.steps, sweep.numpy_steps)


def scene_duration(name: str, scenes: Collection[str], kind: str, duration: float | None, quick: bool,
                   default: Callable[[], float]) -> float:
    """The duration (s) a bench scene ``name`` of ``scenes`` runs: ``duration`` if given, else
    :data:`QUICK_DURATION` with ``quick``, else ``default()``.

    Raises:
        InvalidArgument: for a name not in ``scenes`` (the ``kind`` of bench scene, the valid names).
    """
    if name not in scenes:
        raise InvalidArgument(f"unknown {kind} bench scene '{name}'{did_you_mean(name, scenes)}")
    return duration if duration is not None else (QUICK_DURATION if quick else default())


def whole_periods(name: str, duration: float, period: float) -> None:
    """Checks that bench scene ``name``'s ``duration`` (s) is a positive whole number of ``period`` s
    control periods.

    Raises:
        InvalidArgument: when it is not, naming the scene, the period and the duration.
    """
    periods = round(duration / period) if np.isfinite(duration) else 0
    if not duration > 0.0 or periods < 1 or abs(periods * period - duration) > 1e-9:
        raise InvalidArgument(f"bench scene '{name}': duration must be a positive whole number of {period:g} s "
                              f"control periods, got {duration}")
