"""``simulation`` suite: the one loop's overhead, measured side by side in one run (quote the
ratios, not the absolute times: shared 2-core machines are noisy).

1. Loop overhead, default scene (four-arm robot, computed torque, RKMK4, 1 ms): freefloat's
   :func:`freefloat.dynamics.simulation.run` in its compiled loop (the default) and in its Python
   loop, against an inline Python loop of the same Pinocchio and numpy calls and against the C++
   floor: the compiled loop in one call for the whole run (no Python between chunks), with
   telemetry at every step and with telemetry at the ends only.
2. Model no more than the scene needs: the default scene with a planar and with a free-flyer base.
3. Detumbling: a ``detumble_impulse`` scene (a ramped capture impulse, then the detumbling law, at
   1 ms, RKMK4 with 10 substeps) in the Python loop, in the compiled loop driven one period at a
   time with the Python law and wrench selection, and in whole compiled chunks (law and wrench
   profiles in C++), taking turns within each repeat; and, for the law's share, the same run in
   whole chunks without a controller (impulse only).

4. Pinocchio's convention in the compiled loop: RKMK4 steps of a torque-free run with the plant's
   ABA in the WORLD and in the LOCAL convention, taking turns, on the size sweep's robots (the
   four-arm and dual-arm robots, 4 to 48 spatial arms: nv 18 to 198), and the largest difference
   of their final states.

The integrators' work against precision is the ``integrators`` suite's (and, against MuJoCo, the
``mujoco`` suite's).
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ....app.experiments.robot_run import RobotSetup
from ....app.runner import prepare
from ....app.scenes import DEFAULT_SCENE, Scene, find_scene
from ....dynamics.compiled import CompiledLoop
from ....dynamics.integrators import make_integrator
from ....dynamics.integrators.lie import _dexpinv_se2
from ....dynamics.simulation import run
from ....dynamics.telemetry import Telemetry
from ....space.control import joint_space_dynamics
from .drawing import save, subplots
from .robots import robots
from .timing import side_by_side

#: The detumble scene of part 3.
DETUMBLE_SCENE = "detumble_impulse_arm1_joint4"
#: Arm counts of part 4's generated robots (nv = 6 + 4 arms), full and quick.
CONVENTION_ARMS, QUICK_CONVENTION_ARMS = (4, 8, 16, 32, 48), (4,)


def settings(quick: bool, repeats: int | None) -> dict:
    """Control steps of the default scene's runs (2000; 300 quick), repeats (best of; default 3,
    1 quick), the detumble scene and its simulated time (its own; 0.1 s quick)."""
    return {"steps": 300 if quick else 2000, "repeats": repeats or (1 if quick else 3),
            "detumble_scene": DETUMBLE_SCENE, "detumble_duration_s": 0.1 if quick else None,
            "convention_arm_counts": QUICK_CONVENTION_ARMS if quick else CONVENTION_ARMS,
            "convention_repeats": 3 if quick else 15}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """Parts ``loop_overhead``, ``base_kind``, ``detumbling`` and ``convention``."""
    yield "loop_overhead", loop_overhead(settings["repeats"], settings["steps"])
    yield "base_kind", base_kind(settings["repeats"], settings["steps"])
    yield "detumbling", detumbling(settings["repeats"], settings["detumble_duration_s"])
    yield "convention", convention(settings["convention_arm_counts"], settings["convention_repeats"])


def convention(arm_counts: tuple[int, ...], repeats: int) -> dict:
    """Per robot: seconds per RKMK4 step (1 ms, torque-free, telemetry at the ends) of the compiled
    loop with Pinocchio's WORLD and LOCAL conventions, best of ``repeats`` taking turns, their
    ratio, and the largest difference of their final states."""
    out = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, robot in robots(arm_counts, Path(folder)):
            model = robot.model
            q0, v0 = pin.neutral(model), np.random.default_rng(0).normal(0.0, 0.1, model.nv)
            periods = max(40, 8000 // model.nv)
            chunk = Telemetry.allocate(2, model.nq, model.nv, robot.n_joints, len(robot.end_effectors))
            loops = {}
            for kind in ("world", "local"):
                loops[kind] = CompiledLoop(robot, make_integrator("rkmk4", model), 1e-3, record_every=periods)
                loops[kind].sim.convention = kind
                loops[kind].sim.tree_aba = "pinocchio"  # the convention is Pinocchio's ABA's

            def steps(loop):
                def call():
                    loop.start(q0, v0)
                    loop.run(periods, chunk, 0)
                return call

            best = side_by_side({kind: (steps(loop), 1) for kind, loop in loops.items()}, repeats)
            (qw, vw), (ql, vl) = loops["world"].state, loops["local"].state
            out[name] = {"nv": model.nv, "seconds_per_step": {k: t / periods for k, t in best.items()},
                         "world_over_local": best["world"] / best["local"],
                         "state_difference": float(max(np.abs(qw - ql).max(), np.abs(vw - vl).max()))}
    return out


def bare_loop(prepared: RobotSetup, steps: int, dt: float, telemetry: bool) -> float:
    """The default scene's loop written inline: computed torque + RKMK4 (planar base), s."""
    robot, traj = prepared.robot, prepared.controller.trajectory
    model, data, data_c, data_r = robot.model, robot.model.createData(), robot.model.createData(), robot.model.createData()
    q, v = prepared.q0.copy(), prepared.v0.copy()
    tau = np.zeros(model.nv)
    ee = robot.end_effector_frame_ids
    rows = np.zeros((steps + 1, 7 + model.nq + model.nv + 7 * len(ee)))
    mass = pin.computeTotalMass(model)

    def dexpinv(theta, vel):
        out = vel.copy()
        out[:3] = _dexpinv_se2(theta[:3], vel[:3])
        return out

    start = time.perf_counter()
    for k in range(steps):
        q_d, qd_d, qdd_d = traj(k * dt)
        H, c = joint_space_dynamics(robot, data_c, q, v)
        tau[3:] = H @ (qdd_d + 10.0 * (q_d - q[4:]) + 100.0 * (qd_d - v[3:])) + c
        if telemetry:
            hg = pin.computeCentroidalMomentum(model, data_r, q, v)
            com = data_r.com[0]
            rows[k, :3] = com
            rows[k, 3:6] = hg.linear
            rows[k, 6] = pin.computeKineticEnergy(model, data_r) - mass * model.gravity.linear @ com
            for i, fid in enumerate(ee):
                frame = pin.updateFramePlacement(model, data_r, fid)
                rows[k, 7 + 7 * i:10 + 7 * i] = frame.translation
                rows[k, 10 + 7 * i:14 + 7 * i] = pin.Quaternion(frame.rotation).coeffs()
        h = dt
        a1 = pin.aba(model, data, q, v, tau)
        v2 = v + 0.5 * h * a1
        th2 = 0.5 * h * v
        a2 = pin.aba(model, data, pin.integrate(model, q, th2), v2, tau)
        k2 = dexpinv(th2, v2)
        v3 = v + 0.5 * h * a2
        th3 = 0.5 * h * k2
        a3 = pin.aba(model, data, pin.integrate(model, q, th3), v3, tau)
        k3 = dexpinv(th3, v3)
        v4 = v + h * a3
        th4 = h * k3
        a4 = pin.aba(model, data, pin.integrate(model, q, th4), v4, tau)
        k4 = dexpinv(th4, v4)
        q = pin.integrate(model, q, (h / 6.0) * (v + 2.0 * (k2 + k3) + k4))
        v = v + (h / 6.0) * (a1 + 2.0 * (a2 + a3) + a4)
    return time.perf_counter() - start


def cpp_floor(prepared: RobotSetup, steps: int, dt: float, every: int) -> float:
    """The compiled loop in one call for the whole run (telemetry every ``every`` periods), s."""
    robot = prepared.robot
    loop = CompiledLoop(robot, prepared.integrator, dt, record_every=every, law=prepared.controller.compiled_law())
    chunk = Telemetry.allocate(steps // every + 1, robot.model.nq, robot.model.nv, robot.n_joints,
                               len(robot.end_effectors))
    loop.start(prepared.q0, prepared.v0)
    start = time.perf_counter()
    rows, _ = loop.run(steps, chunk, 0)
    loop.bind(chunk)
    loop.record(rows)
    return time.perf_counter() - start


def loop_overhead(repeats: int, steps: int) -> dict:
    """Time per step (s) of freefloat's loops (compiled, Python), the inline Python loop and the
    C++ floor, with telemetry at every step (``full``) and at the ends only (``ends``), best of
    ``repeats`` taking turns; and their ratios."""
    scene = find_scene(DEFAULT_SCENE)
    dt = scene.simulation.control_period
    kinds = ("compiled", "python", "bare", "cpp")
    results: dict[str, list[float]] = {f"{k}_{label}": [] for k in kinds for label in ("full", "ends")}
    for _ in range(repeats):
        for label, every in (("full", 1), ("ends", steps)):
            for backend in ("compiled", "python"):
                p = prepare(scene)
                res = run(p.robot, p.q0, p.v0, steps * dt, dt, p.integrator, p.model, p.controller, record_every=every,
                          backend=backend)
                results[f"{backend}_{label}"].append(res.wall_time_s / steps)
            results[f"bare_{label}"].append(bare_loop(prepare(scene), steps, dt, label == "full") / steps)
            results[f"cpp_{label}"].append(cpp_floor(prepare(scene), steps, dt, every) / steps)
    best = {k: min(v) for k, v in results.items()}
    return {
        "steps": steps, "seconds_per_step_best": best,
        "compiled_over_cpp_floor_full_telemetry": best["compiled_full"] / best["cpp_full"],
        "compiled_over_cpp_floor_no_telemetry": best["compiled_ends"] / best["cpp_ends"],
        "python_over_compiled_full_telemetry": best["python_full"] / best["compiled_full"],
        "python_over_bare_full_telemetry": best["python_full"] / best["bare_full"],
        "bare_over_compiled_full_telemetry": best["bare_full"] / best["compiled_full"],
    }


def base_kind(repeats: int, steps: int) -> dict:
    """Time per step (s) of the default scene with a planar and with a free-flyer base, best of
    ``repeats``, and their ratio."""
    scene = find_scene(DEFAULT_SCENE)
    out = {}
    for base in ("planar", "free"):
        s = dataclasses.replace(scene, robot=dataclasses.replace(scene.robot, base=base),
                                output=dataclasses.replace(scene.output, html=False))
        dt = s.simulation.control_period
        times = []
        for _ in range(repeats):
            p = prepare(s)
            times.append(run(p.robot, p.q0, p.v0, steps * dt, dt, p.integrator, p.model, p.controller).wall_time_s / steps)
        out[base] = {"seconds_per_step_best": min(times), "nv": p.robot.model.nv}
    out["ratio_free_over_planar"] = out["free"]["seconds_per_step_best"] / out["planar"]["seconds_per_step_best"]
    return out


class PythonLaw:
    """A controller's Python law without its compiled one: the run falls back to one compiled
    period at a time with the law (and the wrench selection) in Python."""

    def __init__(self, controller):
        self.torque, self.reference = controller.torque, controller.reference


#: The loops of :func:`detumbling`: (backend, how the scene's controller is handed to the run).
DETUMBLING_LOOPS = {"python": ("python", lambda c: c), "compiled_per_period": ("compiled", PythonLaw),
                    "compiled_whole_chunks": ("compiled", lambda c: c), "compiled_no_controller": ("compiled", lambda c: None)}


def detumble_scene(duration: float | None) -> Scene:
    """:data:`DETUMBLE_SCENE`, run for ``duration`` s (None: its own)."""
    scene = find_scene(DETUMBLE_SCENE)
    if duration is None:
        return scene
    return dataclasses.replace(scene, simulation=dataclasses.replace(scene.simulation, duration=duration))


def detumbling(repeats: int, duration: float | None) -> dict:
    """Wall time (s) of the detumble scene's whole run in each loop of :data:`DETUMBLING_LOOPS`,
    best of ``repeats`` taking turns, and their ratios."""
    scene = detumble_scene(duration)
    sim = scene.simulation
    walls: dict[str, list[float]] = {loop: [] for loop in DETUMBLING_LOOPS}
    for _ in range(repeats):
        for loop, (backend, hand) in DETUMBLING_LOOPS.items():
            p = prepare(scene)
            res = run(p.robot, p.q0, p.v0, sim.duration, sim.control_period, p.integrator, p.model, hand(p.controller),
                      wrenches=p.wrenches, backend=backend)
            if res.status != "completed" or res.backend != backend:
                raise RuntimeError(f"{DETUMBLE_SCENE} in the {loop} loop: {res.status} on {res.backend} ({res.message})")
            walls[loop].append(res.wall_time_s)
    best = {loop: min(w) for loop, w in walls.items()}
    return {"steps": res.steps, "wall_s_best": best,
            "python_over_whole_chunks": best["python"] / best["compiled_whole_chunks"],
            "per_period_over_whole_chunks": best["compiled_per_period"] / best["compiled_whole_chunks"],
            "python_over_per_period": best["python"] / best["compiled_per_period"],
            "law_share_of_whole_chunks": 1.0 - best["compiled_no_controller"] / best["compiled_whole_chunks"]}


def summary(report: dict) -> list[str]:
    """What the command prints: the headline ratios of each part."""
    loop, base, detumble = report["loop_overhead"], report["base_kind"], report["detumbling"]
    best = loop["seconds_per_step_best"]
    conventions = ", ".join(f"nv {r['nv']} {r['world_over_local']:.3g}" for r in report["convention"].values())
    return [(f"simulation: default scene, {best['compiled_full'] * 1e6:.3g} us per step in the compiled loop: "
             f"{loop['compiled_over_cpp_floor_full_telemetry']:.3g}x the C++ floor with telemetry at every step, "
             f"{loop['compiled_over_cpp_floor_no_telemetry']:.3g}x without; the Python loop "
             f"{loop['python_over_compiled_full_telemetry']:.3g}x the compiled one, "
             f"{loop['python_over_bare_full_telemetry']:.3g}x an inline Python loop"),
            f"simulation: free base / planar base per step {base['ratio_free_over_planar']:.3g}",
            (f"simulation: {DETUMBLE_SCENE}: Python loop {detumble['python_over_whole_chunks']:.3g}x whole compiled "
             f"chunks, the law in Python {detumble['per_period_over_whole_chunks']:.3g}x; the law is "
             f"{detumble['law_share_of_whole_chunks']:.0%} of the whole-chunk run"),
            f"simulation: WORLD / LOCAL convention per step: {conventions}"]


def chart(report: dict, path: Path) -> None:
    """Loop-overhead bars (time per step, log scale), the detumble scene's loops, and WORLD over
    LOCAL per robot size."""
    fig, (ax1, ax2, ax3) = subplots(1, 3, (17, 4.5))
    best = report["loop_overhead"]["seconds_per_step_best"]
    names = {"compiled": "freefloat\ncompiled", "cpp": "C++ floor\n(one call)", "python": "freefloat\nPython loop",
             "bare": "inline Python\nPinocchio loop"}
    x = np.arange(len(names))
    for offset, (label, what) in zip((-0.2, 0.2), (("full", "telemetry every step"), ("ends", "telemetry at the ends"))):
        ax1.bar(x + offset, [best[f"{k}_{label}"] * 1e6 for k in names], width=0.4, label=what)
    ax1.set_xticks(x, list(names.values()), fontsize=8)
    ax1.set_yscale("log")
    ax1.legend(fontsize=8)
    ax1.set_ylabel("time per control step [us]")
    ax1.set_title("Default scene: freefloat's loops, the C++ floor, an inline Python loop")
    det = report["detumbling"]
    labels = {"python": "Python loop", "compiled_per_period": "compiled,\nper period\n(Python law)",
              "compiled_whole_chunks": "compiled,\nwhole chunks\n(C++ law)",
              "compiled_no_controller": "compiled,\nwhole chunks,\nno controller"}
    ax2.bar(list(labels.values()), [det["wall_s_best"][k] for k in labels], color=["C1", "C2", "C0", "C7"])
    ax2.set_ylabel("wall time of the run [s]")
    ax2.set_title(f"{report['settings']['detumble_scene']}: {det['steps']} periods")
    rows = sorted(report["convention"].values(), key=lambda row: row["nv"])
    ax3.plot([row["nv"] for row in rows], [row["world_over_local"] for row in rows], "o-")
    ax3.axhline(1.0, color="grey", linestyle=":")
    ax3.set_xlabel("nv")
    ax3.set_ylabel("time per RKMK4 step, WORLD / LOCAL")
    ax3.set_title("Pinocchio's convention in the compiled loop")
    save(fig, path)
