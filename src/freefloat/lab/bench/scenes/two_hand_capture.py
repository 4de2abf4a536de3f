"""Bench scene ``capture_two_hands_satellite``: the two-hand capture's post-grasp phase against
MuJoCo, work against precision.

Both hands of the UR5 dual-arm satellite grasp a spinning 50 kg box at once (the scene file of
that name, arms bent); afterwards the box rides on the left hand's body (the merged robot, its
inertia added) and a weld between the right tool and the box's second grasp frame closes the
loop. Every method starts from the state right after the grasp's impulse
(:func:`~freefloat.space.dual_capture.capture_with_two_hands`, run for one control period past
it) and runs the same zero-order hold: the loop law
(:class:`~freefloat.space.control.loop_detumbling.LoopDetumblingController`, a new one per run)
evaluated every control period (the scene's 1 ms) and held while the plant is integrated at a
step that divides it. Methods:

* ``freefloat``: the merged robot with its weld,
  :class:`~freefloat.dynamics.closures.ClosedModel` (Baumgarte the scene's), in the compiled loop
  of :func:`~freefloat.dynamics.simulation.run` (plant, integrator and the loop law in C++), every
  fixed-step integrator the registry compiles;
* ``mujoco``: the same tree as MJCF (:mod:`..in_mujoco.mechanism_mjcf`: a free joint, the box's inertia on
  the left hand's body, the weld a stiff soft ``<weld>`` equality), Euler, implicitfast and RK4;
  the law evaluated in Python each period on the merged robot's Pinocchio state read from
  MuJoCo's ``qpos``/``qvel`` (:mod:`..in_mujoco.mechanism`).

The reference is the same held-law loop with each period integrated by scipy's DOP853 (rtol and
atol :data:`~.mechanisms.REFERENCE_TOL`) on the same plant in the Python loop. Errors are those of
the moving-base mechanisms (:func:`.floating_mechanisms.tree_errors`) at the control-period ends.
The methods take turns (:attr:`TwoHandCaptureBench.turns`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ....app.experiments.robot_run import APPROACH_MARGIN
from ....app.experiments.two_hand_capture import _joints, _rows
from ....app.runner import prepare
from ....app.scenes import find_scene
from ....dynamics.closures import ClosedModel, Closure
from ....dynamics.integrators import INTEGRATORS, make_integrator, swept
from ....dynamics.simulation import run
from ....errors import InvalidArgument
from ....parallel.closed_chain import pinocchio_constraints
from ....parallel.closed_loop import steps_per_period
from ....robot.robot import Robot
from ....space.capture import TARGET_FRAME
from ....space.control.loop_detumbling import LoopDetumblingController
from ....space.dual_capture import capture_with_two_hands
from ..race.scene import Method, Run
from . import notes
from .floating_mechanisms import MUJOCO_SETTINGS, ClosedTree, swept_methods, tree_errors
from .mechanisms import MUJOCO, REFERENCE_TOL, MechanismResult, scene_duration, whole_periods

#: Bench scene name (the scene file's) -> note (what runs).
CAPTURE_SCENES = notes("two_hand_capture")
#: Simulated time per run, s (the post-grasp phase's first 0.3 s).
DURATION = 0.3
#: Steps of MuJoCo's integrators and of freefloat's first-order ones, s; of its higher-order
#: ones (RKMK4 is at 2e-13 of the reference at 1 ms already); of every method with ``quick``.
STEPS = (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5)
HIGH_ORDER_STEPS = (1e-3, 5e-4)
QUICK_STEPS = (1e-3, 5e-4)
#: freefloat's plant label.
PLANT = "ClosedModel baumgarte {:g}"


@dataclass(frozen=True)
class PostGrasp:
    """The two-hand capture just after the grasp.

    Attributes:
        merged: the robot with the box on the first hand's body; closure: the loop's weld.
        q0, v0: the merged robot's state right after the grasp impulse (nq,), (nv,).
        period: control period, s; baumgarte: the closure's Baumgarte rate, 1/s.
        law_args: :class:`LoopDetumblingController`'s arguments after the closure.
    """

    merged: Robot
    closure: Closure
    q0: np.ndarray
    v0: np.ndarray
    period: float
    baumgarte: float
    law_args: tuple

    def law(self) -> LoopDetumblingController:
        """A new loop law (it keeps the previous period's rates and closure force)."""
        return LoopDetumblingController(self.merged, self.closure, *self.law_args)


def post_grasp(name: str) -> PostGrasp:
    """The built-in two-hand capture scene ``name`` run through its grasp."""
    scene = find_scene(name)
    setup, sim, ctrl, tg = prepare(scene), scene.simulation, scene.controller, scene.target
    rows, joints, period = _rows(setup), _joints(setup), sim.control_period
    limit = ctrl.torque_limit or 0.0
    grasp = capture_with_two_hands(setup.robot, setup.target, setup.hands, setup.second_grasp, rows, joints, period,
                                   tg.contact_time + APPROACH_MARGIN, period, tg.tolerance, sim.integrator, setup.q0,
                                   setup.v0, ctrl.kp, ctrl.kd, sim.baumgarte, ctrl.squeeze, limit)
    law_args = (TARGET_FRAME, tg.mass, np.asarray(tg.inertia, float), rows, joints, period, ctrl.kd, sim.baumgarte,
                ctrl.squeeze, limit)
    return PostGrasp(grasp.merged, grasp.closure, grasp.post.q[0], grasp.post.v[0], period, sim.baumgarte, law_args)


class TwoHandCaptureBench:
    """The two-hand capture's post-grasp phase as a bench scene (a :class:`~..race.scene.BenchScene`).

    Attributes:
        name, note, secondary, settings: see :class:`~..race.scene.BenchScene`.
        turns: the methods take turns, one run each per round (:func:`..race.sweep.sweep`).
        start: the post-grasp state and the law.
        tree: the merged robot and its weld as MuJoCo is written from (efforts on every joint but
            the base's).
        duration: simulated time per run, s.
        steps: freefloat's steps per integrator, s; mujoco_steps: MuJoCo's.
    """

    secondary = ("constraint_drift", "largest loop-closure gap at the control-period ends, m")
    turns = True

    def __init__(self, name: str, duration: float, quick: bool) -> None:
        self.name, self.note, self.duration = name, CAPTURE_SCENES[name], duration
        self.start = start = post_grasp(name)
        model = start.merged.model
        self.tree = ClosedTree(model, pinocchio_constraints(model, start.closure), np.arange(6, model.nv))
        self.steps = {integrator: QUICK_STEPS if quick else STEPS if INTEGRATORS[integrator].order < 4
                      else HIGH_ORDER_STEPS for integrator in swept("compiled", adaptive=False)}
        self.mujoco_steps = QUICK_STEPS if quick else STEPS
        self.model_label = PLANT.format(start.baumgarte)
        self.settings = {"duration_s": duration, "control_period_s": start.period, "steps_s": self.steps,
                         "mujoco_steps_s": list(self.mujoco_steps), "baumgarte": start.baumgarte,
                         "reference": {"integrator": "DOP853 per control period, python loop",
                                       "model": self.model_label, "rtol": REFERENCE_TOL, "atol": REFERENCE_TOL},
                         "mujoco": {**MUJOCO_SETTINGS, "law": "LoopDetumblingController in Python each period"},
                         "state_error": "2-norm of [difference(q_ref, q); v - v_ref] on the merged robot, base "
                                        "included, at the end (m, rad, m/s, rad/s)"}

    def methods(self) -> list[Method]:
        """freefloat's compiled loop with each integrator; MuJoCo's three integrators."""
        return swept_methods(self.steps, "compiled", self.model_label, self.mujoco_steps)

    def _freefloat(self, integrator: str, step: float, backend: str, rtol: float = 1e-10,
                   atol: float = 1e-12) -> MechanismResult:
        """One held-law run of freefloat's plant, rows at the period ends.

        Raises:
            FloatingPointError: when the run does not complete, with the loop's message.
        """
        s = self.start
        substeps = steps_per_period(s.period, step)
        result = run(s.merged, s.q0, s.v0, self.duration, s.period,
                     make_integrator(integrator, s.merged.model, substeps, rtol, atol),
                     ClosedModel(s.merged, [s.closure], s.baumgarte), s.law(), backend=backend)
        if result.status != "completed":
            raise FloatingPointError(result.message)
        return MechanismResult(result.telemetry.q, result.telemetry.v[-1])

    def run(self, method: Method) -> Run:
        """Each call runs ``method`` from the post-grasp state with a new law.

        Raises:
            InvalidArgument: for a method this scene does not have.
            FreefloatError: when MuJoCo's model does not have the merged robot's mass matrix.
        """
        s, h = self.start, method.setting
        if method.package == "mujoco" and method.integrator in MUJOCO:
            from ..in_mujoco.mechanism import MujocoMechanism  # mujoco is the optional 'bench' extra

            sim = MujocoMechanism(self.tree, method.integrator, h)
            sim.check_inertias(s.q0)
            hold = steps_per_period(s.period, h)

            def mujoco_run() -> MechanismResult:
                q, v = sim.run(s.law(), s.q0, s.v0, self.duration, s.period, h)
                return MechanismResult(q[::hold], v)
            return mujoco_run
        if method.package != "freefloat" or method.integrator not in self.steps:
            raise InvalidArgument(f"bench scene '{self.name}' has no method {method.label}")
        return lambda: self._freefloat(method.integrator, h, "compiled")

    def reference(self) -> MechanismResult:
        """DOP853 per control period on freefloat's plant, the Python loop."""
        return self._freefloat("dop853", self.start.period, "python", REFERENCE_TOL, REFERENCE_TOL)

    def errors(self, result: MechanismResult, reference: MechanismResult) -> dict[str, float]:
        """:func:`.floating_mechanisms.tree_errors`."""
        return tree_errors(self.tree.model, self.tree.constraints, result, reference)


def two_hand_capture_scene(name: str, duration: float | None = None, quick: bool = False) -> TwoHandCaptureBench:
    """The bench scene ``name`` (a key of :data:`CAPTURE_SCENES`).

    Args:
        duration: simulated time per run, s (None: :data:`DURATION`, or
            :data:`~.mechanisms.QUICK_DURATION` with ``quick``); whole control periods.
        quick: a smoke sweep: two steps per method and a short run.

    Raises:
        InvalidArgument: an unknown name (lists the valid ones) or a duration that is not a
            positive whole number of control periods.
    """
    duration = scene_duration(name, CAPTURE_SCENES, "two-hand capture", duration, quick, lambda: DURATION)
    bench = TwoHandCaptureBench(name, duration, quick)
    whole_periods(name, duration, bench.start.period)
    return bench
