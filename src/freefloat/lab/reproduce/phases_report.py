"""``freefloat reproduce phases``: a capture scenario run with one model per phase (sec 3.8).

The dissertation recommends, per phase of a capture, the cheapest model valid there: the
stand-alone reduced model before contact (zero momentum), the full numerical (under-actuated)
model during the capture impulse, the conserved non-zero-momentum model afterwards. Here the
sec 5.3 capture (500 N m about z on arm 1's last link, 10 ms from 5 ms with a 5 ms rise, two-arm
robot, free base, detumbling with all joints from 15 ms) is run with that schedule as printed
(reduced -> standard -> momentum_multi), with the corrected schedule
(reduced -> standard_corrected -> momentum_routh), and with ``exact`` throughout, every model in
the compiled core. The schedules take turns ``repeats`` times in one process; the report gives each
schedule's state error against exact at the end of every phase, the final rotation rate of arm 1's
end-effector, and the best wall time per phase and in all, with its ratio to exact's (side by side).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from ...app.outputs import write_report
from ...dynamics import gjm
from ...dynamics.integrators import make_integrator
from ...dynamics.models import make_model
from ...dynamics.simulation import run
from ...dynamics.wrenches import ExternalWrench
from ...paths import URDF_DIR
from ...robot.loading import load_robot
from ...space.control.detumbling_control import DetumblingController
from ...space.detumbling import joint_indices, task_rows
from .interrupts import finished

PHASES = (("pre-capture", 0.0, 0.005), ("capture", 0.005, 0.015), ("post-capture", 0.015, None))
SCHEDULES = {
    "exact": ("exact", "exact", "exact"),
    "as printed": ("reduced", "standard", "momentum_multi"),
    "corrected": ("reduced", "standard_corrected", "momentum_routh"),
}


def run_schedule(robot, models: tuple[str, str, str], duration: float, dt: float) -> dict:
    """One schedule: the three phases chained, one controller throughout; states at phase ends,
    wall time of each phase's loop (s) and its model evaluations."""
    impulse = ExternalWrench("arm1_link4", torque=(0.0, 0.0, 500.0), start=0.005, end=0.015, rise=0.005)
    rows = task_rows(robot, [("arm1_ee", "wz")])
    ctrl = DetumblingController(robot, rows, joint_indices(robot, None), start=0.015, control_period=dt)
    q, v = robot.neutral(), np.zeros(robot.model.nv)
    ends, walls, evaluations = [], [], []
    for (_phase, t0, t1), name in zip(PHASES, models):
        t1 = duration if t1 is None else t1
        res = finished(run(robot, q, v, round((t1 - t0) / dt) * dt, dt, make_integrator("rkmk4", robot.model, substeps=10),
                           make_model(name, robot), ctrl, wrenches=(impulse,), start_time=t0))
        q, v = res.telemetry.q[-1], res.telemetry.v[-1]
        ends.append((q.copy(), v.copy()))
        walls.append(res.wall_time_s)
        evaluations.append(res.evaluations)
    w = gjm.compute(robot, q, v).end_effector_velocity()[rows]
    return {"ends": ends, "wall_time_s": walls, "evaluations": evaluations, "final_rows_speed": float(np.abs(w).max())}


def side_by_side(robot, duration: float, dt: float, repeats: int) -> dict[str, dict]:
    """Every schedule run ``repeats`` times, taking turns; each keeps its best wall time per phase."""
    best: dict[str, dict] = {}
    for _ in range(repeats):
        for name, models in SCHEDULES.items():
            res = run_schedule(robot, models, duration, dt)
            if name in best:
                res["wall_time_s"] = [min(a, b) for a, b in zip(best[name]["wall_time_s"], res["wall_time_s"])]
            best[name] = res
    return best


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run the three schedules side by side and write ``report.json`` and ``report.md``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    robot = load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)
    duration, dt, repeats = (0.05, 1e-3, 1) if quick else (0.5, 1e-3, 3)
    results = side_by_side(robot, duration, dt, repeats)
    ref = results["exact"]["ends"]
    exact_total = sum(results["exact"]["wall_time_s"])
    report = {"settings": {"duration": duration, "dt": dt, "substeps": 10, "repeats": repeats, "backend": "compiled"},
              "schedules": {}}
    for name, res in results.items():
        errors = [float(np.linalg.norm(np.concatenate((pin.difference(robot.model, q_ref, q), v - v_ref))))
                  for (q, v), (q_ref, v_ref) in zip(res["ends"], ref)]
        total = sum(res["wall_time_s"])
        report["schedules"][name] = {
            "models": SCHEDULES[name], "state_error_at_phase_ends": errors, "wall_time_s": res["wall_time_s"],
            "wall_time_total_s": total, "time_over_exact": total / exact_total, "evaluations": res["evaluations"],
            "us_per_evaluation": [1e6 * w / max(n, 1) for w, n in zip(res["wall_time_s"], res["evaluations"])],
            "final_rows_speed": res["final_rows_speed"]}
    lines = ["# One model per capture phase (sec 3.8) against exact throughout", "",
             (f"Two-arm robot, free base, sec 5.3 impulse on arm 1, detumbling with all joints from 15 ms; "
              f"{duration} s, RKMK4 at {dt} s with 10 substeps, compiled models; best of {repeats} runs taking turns."),
             "",
             ("| schedule | models (pre / capture / post) | state error at the end of each phase | final speed of arm 1's wz "
              "| wall time per phase (s) | us per evaluation | total time / exact's |"),
             "|---|---|---|---|---|---|---|"]
    for name, r in report["schedules"].items():
        lines.append(f"| {name} | {' / '.join(r['models'])} | {', '.join(f'{e:.2e}' for e in r['state_error_at_phase_ends'])} | "
                     f"{r['final_rows_speed']:.2e} | {', '.join(f'{w:.3f}' for w in r['wall_time_s'])} | "
                     f"{', '.join(f'{u:.0f}' for u in r['us_per_evaluation'])} | {r['time_over_exact']:.2f} |")
    return write_report(out, report, lambda _: "\n".join(lines) + "\n", start)
