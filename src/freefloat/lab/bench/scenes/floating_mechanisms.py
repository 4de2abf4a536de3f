"""Bench scenes of a mechanism on a moving base: the scene files ``five_bar_free_base`` (the 5R
on a planar base, sliding mode) and ``rsu_ppap_free_base`` (the 2RSU+PPaP on a free base,
computed torque), at zero gravity, against MuJoCo.

Every method runs the scene's closed loop with the same zero-order hold: the fixed-base law read
in the base frame (:class:`~freefloat.parallel.free_base.BaseFrameControl`, called from Python,
the law itself its compiled form) evaluated every control period (the scene file's step) and held
while the plant is integrated at a step that divides the period. Methods:

* ``freefloat``: the scenes' plant, freefloat's constrained dynamics on the spanning tree with its
  root joint (``closed_tree``: :meth:`~freefloat.parallel.free_base.FloatingMechanism.closed_model`,
  Baumgarte the scene's lambda) in the compiled robot loop, as a scene runs it
  (:func:`~freefloat.parallel.free_base.run_compiled`), Euler, RKMK4 and RKMK8, one row per period;
* ``mujoco``: the same tree as MJCF (:mod:`..in_mujoco.mechanism_mjcf`: the planar root as two slides and a
  hinge, the free root as a free joint) with the closures as stiff soft equalities, Euler,
  implicitfast and RK4 (:mod:`..in_mujoco.mechanism`).

The reference is the same held-law loop with each period integrated by scipy's DOP853 (rtol and
atol :data:`~.mechanisms.REFERENCE_TOL`) on freefloat's plant in the Python loop
(:class:`~freefloat.dynamics.plants.ClosedTreePlant`, numpy). Errors are measured on the tree's
state at the period ends, the same way for every method (:meth:`FloatingMechanismBench.errors`).
The methods take turns (:attr:`FloatingMechanismBench.turns`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ....app.experiments.mechanism import prepare
from ....app.scenes import find_scene
from ....errors import InvalidArgument
from ....parallel.closed_loop import steps_per_period
from ....parallel.free_base import BaseFrameControl, run_compiled
from ..in_mujoco.mechanism_mjcf import SOLIMP, TIMECONST_STEPS
from ..race.scene import Method, Run
from . import notes
from .mechanisms import MUJOCO, MUJOCO_MODEL, REFERENCE_TOL, MechanismResult, held_run, scene_duration, whole_periods

#: Bench scene name (the scene file's) -> note (what runs).
FLOATING_SCENES = notes("floating_mechanisms")


@dataclass(frozen=True)
class FloatingSweep:
    """What one moving-base bench scene sweeps.

    Attributes:
        duration: default simulated time per run, s.
        steps: MuJoCo's and freefloat's Euler steps, s (each divides the period).
        rk4_steps: freefloat's RKMK4 steps, s; rk8_steps: its RKMK8 steps.
        quick_steps: every method's steps with ``quick``.
    """

    duration: float
    steps: tuple[float, ...]
    rk4_steps: tuple[float, ...]
    rk8_steps: tuple[float, ...]
    quick_steps: tuple[float, ...]


#: Each scene's sweep.
SWEEPS = {
    "five_bar_free_base": FloatingSweep(0.2, (1e-4, 5e-5, 2e-5, 1e-5), (1e-4, 5e-5, 2e-5), (1e-4,), (1e-4, 5e-5)),
    "rsu_ppap_free_base": FloatingSweep(0.3, (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5), (1e-3, 5e-4, 2e-4, 1e-4),
                                        (1e-3, 5e-4), (1e-3, 5e-4)),
}
#: freefloat's model label: the scenes' plant.
PLANT = "closed tree baumgarte {:g}"
#: MuJoCo's closures, as ``bench.json`` records them.
MUJOCO_SETTINGS = {"solref": f"timeconst {TIMECONST_STEPS:g} x step, dampratio 1", "solimp": list(SOLIMP)}


def swept_methods(steps: dict[str, tuple[float, ...]], loop: str, model: str,
                  mujoco_steps: tuple[float, ...]) -> list[Method]:
    """freefloat's methods (each integrator of ``steps`` at its steps, s, in ``loop``, plant label
    ``model``), then MuJoCo's three integrators at ``mujoco_steps``."""
    out = [Method("freefloat", integrator, h, loop, model) for integrator, own in steps.items() for h in own]
    return out + [Method("mujoco", integrator, h, "python", MUJOCO_MODEL)
                  for integrator in MUJOCO for h in mujoco_steps]


@dataclass(frozen=True)
class ClosedTree:
    """A tree with its closures, as :class:`..in_mujoco.mechanism.MujocoMechanism` takes it.

    Attributes:
        model: the Pinocchio tree (a planar or free-flyer root joint, or a fixed base).
        constraints: ``RigidConstraintModel`` s of the closures (point or frame).
        actuated: velocity index of each effort (k,).
    """

    model: pin.Model
    constraints: list
    actuated: np.ndarray


def tree_errors(model: pin.Model, constraints: list, result: MechanismResult,
                reference: MechanismResult) -> dict[str, float]:
    """``state_error``: ``|[difference(q_ref, q); v - v_ref]|`` at the end (Pinocchio's
    ``difference`` on the whole tree, root joint included; m, rad, m/s, rad/s);
    ``constraint_drift``: the largest closure gap (m) over every recorded configuration."""
    data = model.createData()

    def gap(q: np.ndarray) -> float:
        pin.forwardKinematics(model, data, q)
        return max(float(np.linalg.norm(data.oMi[c.joint1_id].act(c.joint1_placement.translation)
                                        - data.oMi[c.joint2_id].act(c.joint2_placement.translation)))
                   for c in constraints)

    difference = pin.difference(model, reference.q[-1], result.q[-1])
    return {"state_error": float(np.linalg.norm(np.concatenate((difference, result.v - reference.v)))),
            "constraint_drift": max(gap(q) for q in result.q)}


class FloatingMechanismBench:
    """A moving-base mechanism bench scene (a :class:`~..race.scene.BenchScene`).

    Attributes:
        name, note, secondary, settings: see :class:`~..race.scene.BenchScene`.
        floating: the mechanism on its base (tree, closures, plant, base-frame kinematics).
        law: the fixed-base law read in the base frame.
        q0, v0: the tree's start (the base at rest at the origin).
        duration, period: simulated time and control period, s.
    """

    secondary = ("constraint_drift", "largest loop-closure gap at the control-period ends, m")
    turns = True

    def __init__(self, name: str, duration: float, quick: bool) -> None:
        prepared = prepare(find_scene(name))
        sim = prepared.scene.simulation
        self.name, self.note, self.floating = name, FLOATING_SCENES[name], prepared.floating
        self.law = BaseFrameControl(prepared.controller, self.floating)
        self.q0, self.v0 = self.floating.tree_state(prepared.q0, prepared.qd0)
        self.duration, self.period, self.baumgarte = duration, sim.step, sim.baumgarte
        sweep = SWEEPS[name]
        quick_steps = sweep.quick_steps
        self.steps = {"euler": sweep.steps, "rkmk4": sweep.rk4_steps, "rkmk8": sweep.rk8_steps}
        self.mujoco_steps = quick_steps if quick else sweep.steps
        if quick:
            self.steps = dict.fromkeys(self.steps, quick_steps)
        self.model_label = PLANT.format(self.baumgarte)
        self.settings = {"duration_s": duration, "control_period_s": self.period, "steps_s": self.steps,
                         "mujoco_steps_s": list(self.mujoco_steps), "baumgarte": self.baumgarte,
                         "base": self.floating.base.kind,
                         "reference": {"integrator": "DOP853 per control period, python loop",
                                       "model": self.model_label,
                                       "rtol": REFERENCE_TOL, "atol": REFERENCE_TOL},
                         "mujoco": MUJOCO_SETTINGS,
                         "state_error": "2-norm of [difference(q_ref, q); v - v_ref] on the tree, root joint "
                                        "included, at the end (m, rad, m/s, rad/s)"}

    def methods(self) -> list[Method]:
        """freefloat's plant with Euler, RKMK4 and RKMK8 (compiled loop); MuJoCo's three integrators."""
        return swept_methods(self.steps, "compiled", self.model_label, self.mujoco_steps)

    def tree(self) -> ClosedTree:
        """The tree MuJoCo is written from."""
        f = self.floating
        return ClosedTree(f.model, f.constraints, f.actuated)

    def run(self, method: Method) -> Run:
        """Each call runs ``method`` from the scene's start.

        Raises:
            InvalidArgument: for a method this scene does not have.
            FreefloatError: when MuJoCo's model does not have the tree's mass matrix.
        """
        if method.package == "mujoco" and method.integrator in MUJOCO:
            from ..in_mujoco.mechanism import MujocoMechanism  # mujoco is the optional 'bench' extra

            sim = MujocoMechanism(self.tree(), method.integrator, method.setting)
            sim.check_inertias(self.q0)
            hold = steps_per_period(self.period, method.setting)

            def mujoco_run() -> MechanismResult:
                q, v = sim.run(self.law, self.q0, self.v0, self.duration, self.period, method.setting)
                return MechanismResult(q[::hold], v)
            return mujoco_run
        if method.package != "freefloat" or method.integrator not in self.steps:
            raise InvalidArgument(f"bench scene '{self.name}' has no method {method.label}")
        return lambda: self._freefloat(method.integrator, method.setting)

    def _freefloat(self, integrator: str, step: float) -> MechanismResult:
        """One held-law run in the compiled loop, rows at the period ends.

        Raises:
            FloatingPointError: when the run does not complete, with the loop's message.
        """
        result = run_compiled(self.floating, self.law, self.q0, self.v0, self.duration, self.period, self.baumgarte,
                              integrator, steps_per_period(self.period, step))
        if result.status != "completed":
            raise FloatingPointError(result.message)
        return MechanismResult(result.telemetry.q, result.telemetry.v[-1])

    def reference(self) -> MechanismResult:
        """DOP853 per control period on freefloat's plant, the Python loop."""
        return held_run(self.floating.plant(self.baumgarte, dynamics="closed_tree"), self.law, self.q0, self.v0,
                        self.duration, self.period, self.period, "dop853", lambda q: q, "python", REFERENCE_TOL,
                        REFERENCE_TOL)

    def errors(self, result: MechanismResult, reference: MechanismResult) -> dict[str, float]:
        """:func:`tree_errors`."""
        return tree_errors(self.floating.model, self.floating.constraints, result, reference)


def floating_mechanism_scene(name: str, duration: float | None = None, quick: bool = False) -> FloatingMechanismBench:
    """The moving-base bench scene ``name`` (a key of :data:`FLOATING_SCENES`).

    Args:
        duration: simulated time per run, s (None: the sweep's, or :data:`~.mechanisms.QUICK_DURATION`
            with ``quick``); a positive whole number of control periods.
        quick: a smoke sweep: two steps per method and a short run.

    Raises:
        InvalidArgument: an unknown name (lists the valid ones) or a duration that is not a
            positive whole number of control periods.
    """
    duration = scene_duration(name, FLOATING_SCENES, "moving-base", duration, quick, lambda: SWEEPS[name].duration)
    bench = FloatingMechanismBench(name, duration, quick)
    whole_periods(name, duration, bench.period)
    return bench
