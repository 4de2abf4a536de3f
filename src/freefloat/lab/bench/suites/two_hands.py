"""``two_hands`` suite: the two-hand capture's post-grasp phase (issue 20) in the Python and the
compiled loop, against the single-arm capture's, per simulated second, side by side in one process.

The post-grasp phase of ``capture_two_hands_satellite`` (the merged robot with its loop closure
as plant, :class:`~freefloat.dynamics.closures.ClosedModel` with the scene's Baumgarte rate, and
:class:`~freefloat.space.control.loop_detumbling.LoopDetumblingController`) runs from the state
right after the grasp, once by the Python loop and once by the compiled one (closure plant and law
in C++); the post-grasp phase of ``capture_satellite`` (one hand: the exact tree and the
detumbling controller) runs compiled from its own grasp. Each run is a call of
:func:`freefloat.dynamics.simulation.run` with a new controller (the compiled loop kept between
runs, as in a process that runs several); the methods take turns within each repeat, and each
reports the best wall time of the call per simulated second. The two loops' final states are
compared (they agree to round-off).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from ....app.experiments.detumbling import mission_joints, rows_spec
from ....app.experiments.robot_run import APPROACH_MARGIN
from ....app.experiments.two_hand_capture import _joints, _rows
from ....app.runner import prepare
from ....app.scenes import find_scene
from ....dynamics.closures import ClosedModel
from ....dynamics.integrators import make_integrator
from ....dynamics.models import ExactModel
from ....dynamics.simulation import run
from ....space.capture import TARGET_FRAME, capture_and_detumble
from ....space.control.detumbling_control import DetumblingController
from ....space.control.loop_detumbling import LoopDetumblingController
from ....space.detumbling import joint_indices, task_rows
from ....space.dual_capture import capture_with_two_hands
from .drawing import save, subplots

TWO_HANDS, ONE_HAND = "capture_two_hands_satellite", "capture_satellite"
METHODS = ("two_hands python", "two_hands compiled", "one_hand compiled")
#: The issue's aim: two-hand capture and detumbling compiled at most this many times the cost of
#: the single-arm capture per simulated second.
AIM = 2.0


def settings(quick: bool, repeats: int | None) -> dict:
    """The scenes, the post-grasp phase simulated (1 s, the scenes' duration; 0.05 s quick) and the
    repeats (best of; default 5, 1 quick)."""
    return {"two_hands": TWO_HANDS, "one_hand": ONE_HAND, "duration_s": 0.05 if quick else 1.0,
            "repeats": repeats or (1 if quick else 5), "aim": AIM}


def _two_hands(duration: float) -> dict[str, Callable]:
    """The two-hand scene's post-grasp run, one callable per loop (each returns its RunResult)."""
    scene = find_scene(TWO_HANDS)
    setup, sim, ctrl, tg = prepare(scene), scene.simulation, scene.controller, scene.target
    rows, joints = _rows(setup), _joints(setup)
    grasp = capture_with_two_hands(setup.robot, setup.target, setup.hands, setup.second_grasp, rows, joints,
                                   sim.control_period, tg.contact_time + APPROACH_MARGIN, sim.control_period, tg.tolerance,
                                   sim.integrator, setup.q0, setup.v0, ctrl.kp, ctrl.kd, sim.baumgarte, ctrl.squeeze,
                                   ctrl.torque_limit or 0.0)
    merged, closure, law = grasp.merged, grasp.closure, grasp.controller
    q, v = grasp.post.q[0], grasp.post.v[0]

    def post(backend: str) -> Callable:
        def one():
            controller = LoopDetumblingController(merged, closure, TARGET_FRAME, law.mass, np.diag(law.inertia), rows,
                                                  joints, sim.control_period, ctrl.kd, sim.baumgarte, ctrl.squeeze,
                                                  ctrl.torque_limit or 0.0)
            return run(merged, q, v, duration, sim.control_period, make_integrator(sim.integrator, merged.model),
                       ClosedModel(merged, [closure], sim.baumgarte), controller, backend=backend)
        return one

    return {"two_hands python": post("python"), "two_hands compiled": post("compiled")}


def _one_hand(duration: float) -> Callable:
    """The single-arm capture's post-grasp run, compiled."""
    scene = find_scene(ONE_HAND)
    setup, sim, ctrl, tg = prepare(scene), scene.simulation, scene.controller, scene.target
    grasp = capture_and_detumble(setup.robot, setup.target, tg.end_effector, rows_spec(scene), mission_joints(scene),
                                 scene.task.method, sim.control_period, tg.contact_time + APPROACH_MARGIN, sim.control_period,
                                 tg.tolerance, integrator=sim.integrator, q0=setup.q0, v0=setup.v0, kp=ctrl.kp,
                                 kd=ctrl.kd, model=ctrl.model)
    merged = grasp.merged
    q, v = grasp.post.q[0], grasp.post.v[0]
    rows, joints = task_rows(merged, rows_spec(scene)), joint_indices(merged, mission_joints(scene))

    def one():
        controller = DetumblingController(merged, rows, joints, start=0.0, control_period=sim.control_period,
                                          method=scene.task.method, kp=ctrl.kp, kd=ctrl.kd, model=ctrl.model)
        return run(merged, q, v, duration, sim.control_period, make_integrator(sim.integrator, merged.model),
                   ExactModel(merged), controller, backend="compiled")

    return one


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part: per method the wall times of its calls (s), the best per simulated second, the
    loop that ran, the ratios, and the two-hand loops' final-state difference."""
    duration = settings["duration_s"]
    methods = {**_two_hands(duration), "one_hand compiled": _one_hand(duration)}
    for one in methods.values():
        one()  # first calls (imports, the compiled loop built and checked) outside the clock
    times: dict[str, list[float]] = {name: [] for name in methods}
    results = {}
    for _ in range(settings["repeats"]):
        for name, one in methods.items():  # taking turns, so that other load falls on all alike
            start = time.perf_counter()
            results[name] = one()
            times[name].append(time.perf_counter() - start)
    per_second = {name: min(t) / duration for name, t in times.items()}
    python, compiled = (results[f"two_hands {b}"].telemetry for b in ("python", "compiled"))
    yield "post_grasp", {
        "times_s": times, "per_simulated_second_s": per_second,
        "loop": {name: r.backend for name, r in results.items()},
        "status": {name: r.status for name, r in results.items()},
        "python_over_compiled": per_second["two_hands python"] / per_second["two_hands compiled"],
        "two_hands_over_one_hand": per_second["two_hands compiled"] / per_second["one_hand compiled"],
        "final_state_difference": float(max(np.abs(python.q[-1] - compiled.q[-1]).max(),
                                            np.abs(python.v[-1] - compiled.v[-1]).max())),
    }


def chart(report: dict, path: Path) -> None:
    """Bars (log scale): wall time per simulated second of each post-grasp run, the aim (2x the
    one-hand run) drawn."""
    part = report["post_grasp"]
    fig, ax = subplots(1, 1, (7.0, 3.5))
    labels = list(part["per_simulated_second_s"])
    ax.barh(labels, [part["per_simulated_second_s"][k] for k in labels])
    ax.axvline(report["settings"]["aim"] * part["per_simulated_second_s"]["one_hand compiled"], color="grey",
               ls="--", label=f"aim: {report['settings']['aim']:g}x one hand")
    ax.set_xscale("log")
    ax.set_xlabel(f"wall time per simulated second (s, log scale), best of {report['settings']['repeats']}")
    ax.set_title(f"Post-grasp phase: two hands (loop closure) {part['two_hands_over_one_hand']:.2f}x one hand; "
                 f"compiled {part['python_over_compiled']:.1f}x faster", fontsize=9)
    ax.legend(fontsize=8)
    save(fig, path)
