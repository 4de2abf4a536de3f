"""Benchmark the simulation loop against bare Pinocchio loops, and accuracy against cost.

Writes ``bench_simulation.json`` and ``bench_simulation.png`` to an output folder (default
``runs/bench-simulation-<time>``), with versions and settings. Everything compared is measured side by side
in one run: quote the ratios, not the absolute times (shared 2-core machines are noisy).

1. Loop overhead, default scene (four-arm robot, computed torque, RKMK4, 1 ms):
   freefloat's :func:`freefloat.simulation.run` in its compiled loop (the default) and in its
   Python loop, against an inline Python loop of the same Pinocchio and numpy calls and against the
   C++ floor: the compiled loop in one call for the whole run (no Python between chunks), with
   telemetry at every step and with telemetry at the ends only.
2. Work-precision: a torque-free tumbling four-arm robot (free base), 1 s, every integrator over
   a range of steps (dopri5 over tolerances): final-state error against a tight dopri5 reference
   versus wall time and dynamics evaluations.
3. Model no more than the scene needs: the default scene with a planar vs a free-flyer base.
4. Detumbling: a ``detumble_impulse`` scene (a ramped capture impulse, then the detumbling law, 1 s
   at 1 ms, RKMK4 with 10 substeps) in the Python loop, in the compiled loop driven one period at a
   time with the Python law and wrench selection (the mode before the law was compiled), and in
   whole compiled chunks (law and wrench profiles in C++), taking turns within each repeat; and,
   for the law's share, the same run in whole chunks without a controller (impulse only).

Usage: ``python3 scripts/bench_simulation.py [--out DIR] [--repeats N] [--quick]``
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
from bench_common import parser, save_chart, write_json

from freefloat import load_robot
from freefloat.app.runner import prepare
from freefloat.app.scenes import DEFAULT_SCENE, find_scene
from freefloat.dynamics.compiled import CompiledLoop
from freefloat import make_integrator
from freefloat.dynamics.integrators.lie import _dexpinv_se2
from freefloat.dynamics.models import ExactModel
from freefloat.dynamics.simulation import run
from freefloat.dynamics.telemetry import Telemetry
from freefloat.paths import URDF_DIR
from freefloat.space.control import joint_space_dynamics


def bare_loop(prepared, steps: int, dt: float, telemetry: bool) -> float:
    """The default scene's loop written inline: computed torque + RKMK4 (planar base), seconds."""
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
        t = k * dt
        q_d, qd_d, qdd_d = traj(t)
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


def cpp_floor(prepared, steps: int, dt: float, every: int) -> float:
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
    """Time per step of freefloat's loops (compiled, Python), the inline Python loop and the C++
    floor, with telemetry at every step and at the ends only."""
    scene = find_scene(DEFAULT_SCENE)
    dt = scene.simulation.control_period
    kinds = ("compiled", "python", "bare", "cpp")
    results: dict[str, list[float]] = {f"{k}_{label}": [] for k in kinds for label in ("full", "ends")}
    for _ in range(repeats):
        for label, every in (("full", 1), ("ends", steps)):
            for backend in ("compiled", "python"):
                prepared = prepare(scene)
                res = run(prepared.robot, prepared.q0, prepared.v0, steps * dt, dt, prepared.integrator,
                          prepared.model, prepared.controller, record_every=every, backend=backend)
                results[f"{backend}_{label}"].append(res.wall_time_s / steps)
            results[f"bare_{label}"].append(bare_loop(prepare(scene), steps, dt, label == "full") / steps)
            results[f"cpp_{label}"].append(cpp_floor(prepare(scene), steps, dt, every) / steps)
    best = {k: min(v) for k, v in results.items()}
    return {
        "steps": steps, "repeats": repeats, "seconds_per_step_best": best,
        "compiled_over_cpp_floor_full_telemetry": best["compiled_full"] / best["cpp_full"],
        "compiled_over_cpp_floor_no_telemetry": best["compiled_ends"] / best["cpp_ends"],
        "python_over_compiled_full_telemetry": best["python_full"] / best["compiled_full"],
        "python_over_bare_full_telemetry": best["python_full"] / best["bare_full"],
        "bare_over_compiled_full_telemetry": best["bare_full"] / best["compiled_full"],
    }


def work_precision(quick: bool) -> list[dict]:
    """Final-state error vs cost for each integrator on a tumbling four-arm robot (free base)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    model = ExactModel(robot)
    rng = np.random.default_rng(7)
    q0 = robot.neutral()
    q0[7:] = rng.uniform(-0.5, 0.5, robot.n_joints)
    v0 = rng.uniform(-0.3, 0.3, robot.model.nv)
    v0[3:6] = [0.4, -0.3, 1.0]  # tumbling base
    tau = np.zeros(robot.model.nv)
    f = lambda q, v: model.acceleration(q, v, tau)  # noqa: E731
    q_ref, v_ref = make_integrator("dopri5", robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 1.0)
    rows = []
    substeps = [100, 300, 1000] if quick else [50, 100, 200, 400, 1000, 2000, 4000]
    settings = [(n, 1e-10, 1e-12) for n in substeps]
    for name in ("euler", "rk4_naive", "rkmk4", "dopri5"):
        grid = [(1, r, r * 1e-2) for r in ([1e-6, 1e-9, 1e-12] if quick else [1e-5, 1e-7, 1e-9, 1e-11, 1e-12])] \
            if name == "dopri5" else settings
        for n, rtol, atol in grid:
            integrator = make_integrator(name, robot.model, substeps=n, rtol=rtol, atol=atol)
            start = time.perf_counter()
            q, v = integrator.advance(f, q0, v0, 1.0)
            wall = time.perf_counter() - start
            err = float(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
            rows.append({"integrator": name, "substeps": n, "rtol": rtol if name == "dopri5" else None,
                         "error": err, "wall_s": wall, "evaluations": integrator.evaluations()})
    return rows


def base_kind(repeats: int, steps: int) -> dict:
    """Time per step of the default scene with a planar and with a free-flyer base."""
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


def detumbling(repeats: int, name: str = "detumble_impulse_arm1_joint4") -> dict:
    """Wall time of a detumble scene's whole run in the Python loop, in per-period compiled mode, in
    whole compiled chunks, and in whole chunks without the controller; the loops take turns
    within each repeat."""
    scene = find_scene(name)
    sim = scene.simulation
    walls: dict[str, list[float]] = {loop: [] for loop in DETUMBLING_LOOPS}
    for _ in range(repeats):
        for loop, (backend, hand) in DETUMBLING_LOOPS.items():
            p = prepare(scene)
            res = run(p.robot, p.q0, p.v0, sim.duration, sim.control_period, p.integrator, p.model, hand(p.controller),
                      wrenches=p.wrenches, backend=backend)
            assert res.status == "completed" and res.backend == backend
            walls[loop].append(res.wall_time_s)
    best = {loop: min(w) for loop, w in walls.items()}
    return {"scene": name, "steps": res.steps, "repeats": repeats, "wall_s_best": best,
            "python_over_whole_chunks": best["python"] / best["compiled_whole_chunks"],
            "per_period_over_whole_chunks": best["compiled_per_period"] / best["compiled_whole_chunks"],
            "python_over_per_period": best["python"] / best["compiled_per_period"],
            "law_share_of_whole_chunks": 1.0 - best["compiled_no_controller"] / best["compiled_whole_chunks"]}


def chart(report: dict, path: Path) -> None:
    """Work-precision chart and loop-overhead bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(17, 4.5))
    for name in ("euler", "rk4_naive", "rkmk4", "dopri5"):
        rows = [r for r in report["work_precision"] if r["integrator"] == name]
        ax1.loglog([r["wall_s"] for r in rows], [max(r["error"], 1e-16) for r in rows], "o-", label=name)
    ax1.set_xlabel("wall time for 1 s simulated [s]")
    ax1.set_ylabel("final state error vs reference")
    ax1.set_title("Work-precision, tumbling four-arm robot (free base)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend()
    best = report["loop_overhead"]["seconds_per_step_best"]
    names = {"compiled": "freefloat\ncompiled", "cpp": "C++ floor\n(one call)", "python": "freefloat\nPython loop",
             "bare": "inline Python\nPinocchio loop"}
    x = np.arange(len(names))
    for offset, (label, what) in zip((-0.2, 0.2), (("full", "telemetry every step"), ("ends", "telemetry at the ends"))):
        ax2.bar(x + offset, [best[f"{k}_{label}"] * 1e6 for k in names], width=0.4, label=what)
    ax2.set_xticks(x, list(names.values()), fontsize=8)
    ax2.set_yscale("log")
    ax2.legend(fontsize=8)
    ax2.set_ylabel("time per control step [us]")
    ax2.set_title("Default scene: freefloat's loops, the C++ floor, an inline Python loop")
    det = report["detumbling"]
    labels = {"python": "Python loop", "compiled_per_period": "compiled,\nper period\n(Python law)",
              "compiled_whole_chunks": "compiled,\nwhole chunks\n(C++ law)",
              "compiled_no_controller": "compiled,\nwhole chunks,\nno controller"}
    ax3.bar(list(labels.values()), [det["wall_s_best"][k] for k in labels], color=["C1", "C2", "C0", "C7"])
    ax3.set_ylabel("wall time of the run [s]")
    ax3.set_title(f"{det['scene']}: {det['steps']} periods")
    save_chart(fig, path)


def main() -> None:
    cli = parser(__doc__, "simulation")
    cli.add_argument("--repeats", type=int, default=3)
    cli.add_argument("--quick", action="store_true", help="fewer points (for a smoke run)")
    args = cli.parse_args()
    steps = 300 if args.quick else 2000
    report = {
        "loop_overhead": loop_overhead(args.repeats, steps),
        "base_kind": base_kind(args.repeats, steps),
        "detumbling": detumbling(args.repeats),
        "work_precision": work_precision(args.quick),
        "settings": {"repeats": args.repeats, "steps": steps, "quick": args.quick},
    }
    write_json(args.out, "simulation", report)
    chart(report, args.out / "bench_simulation.png")
    lo, bk, det = report["loop_overhead"], report["base_kind"], report["detumbling"]
    print(f"compiled / C++ floor, full telemetry: {lo['compiled_over_cpp_floor_full_telemetry']:.2f}; no telemetry: "
          f"{lo['compiled_over_cpp_floor_no_telemetry']:.2f}; Python loop / compiled: "
          f"{lo['python_over_compiled_full_telemetry']:.1f}")
    print(f"free/planar base time per step: {bk['ratio_free_over_planar']:.2f}")
    print(f"{det['scene']}: Python loop / whole compiled chunks {det['python_over_whole_chunks']:.1f}, "
          f"per-period compiled / whole chunks {det['per_period_over_whole_chunks']:.1f}, "
          f"the law's share of the whole-chunk run {det['law_share_of_whole_chunks']:.0%}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
