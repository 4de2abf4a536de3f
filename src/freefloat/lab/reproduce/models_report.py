"""``freefloat reproduce models``: which dynamics model matches the exact dynamics, and where.

Four parts, all against Pinocchio's ABA (``exact``), written as JSON, Markdown and PNG figures:

1. accelerations of every variant at random states of the four-arm robot (free-flyer base), with
   zero momentum, with angular momentum only (P = 0), and with linear and angular momentum; and
   each variant's cost per evaluation;
2. the dissertation's chapter-5.1 experiment (four-arm joint-space task, computed torque,
   Kp = 10 I, Kd = 100 I, 5 s, 1 ms) as a grid of plant x controller model, with the
   dissertation's semi-implicit Euler, plus the exact plant with RKMK4; Table 1 is the cell
   (plant nidc; controllers nidc and standard);
3. a torque-free tumbling robot (non-zero momentum) simulated with each model, against exact;
4. the base attitude as Euler angles (eqs 9-11) against the Lie group near theta = 90 deg.
"""

from __future__ import annotations

import json
import time
import warnings
from concurrent.futures import as_completed
from pathlib import Path

import numpy as np
import pinocchio as pin

from ...app.outputs import write_report
from ...app.runner import prepare
from ...distributed import process_pool
from ...dynamics.integrators import make_integrator
from ...dynamics.metrics import momentum_drift, summarize
from ...dynamics.models import MODELS, make_model
from ...dynamics.simulation import run
from ...paths import URDF_DIR
from ...robot import attitude
from ...robot.loading import FreefloatWarning, load_robot
from .interrupts import finished
from .models_cases import EXACT_PLANT_CONTROLLERS, GRID_MODELS, REGIMES, TUMBLING_MODELS
from .models_output import figures, markdown
from .series_report import chapter_four_scene
from .states import state_with_momentum
from .study_journal import entries


def robot_notes_silenced() -> None:
    """In a pool worker: the robot's load-time notes silenced, as :func:`~freefloat.lab.reproduce.folders.run_study`
    silences them in this process (each worker printed them, with their source lines)."""
    warnings.filterwarnings("ignore", category=FreefloatWarning)


def four_arm_free():
    """The four-arm robot with a free-flyer base (the GJM models are 3-D)."""
    return load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)


def accuracy(samples: int, seed: int) -> dict:
    """Max relative acceleration error of each variant per momentum regime, and cost per call."""
    robot = four_arm_free()
    models = {name: make_model(name, robot) for name in MODELS}
    rng = np.random.default_rng(seed)
    out: dict = {"samples": samples, "errors": {}, "seconds_per_evaluation": {}}
    for regime, (P, L) in REGIMES.items():
        worst = dict.fromkeys(MODELS, 0.0)
        for _ in range(samples):
            q, v = state_with_momentum(robot, rng, None if P is None else np.array(P), None if L is None else np.array(L))
            tau = np.concatenate((np.zeros(6), rng.normal(size=robot.n_joints)))
            exact = models["exact"].acceleration(q, v, tau)
            for name, model in models.items():
                err = np.abs(model.acceleration(q, v, tau) - exact).max() / np.abs(exact).max()
                worst[name] = max(worst[name], float(err))
        out["errors"][regime] = worst
    q, v = state_with_momentum(robot, rng)
    tau = np.concatenate((np.zeros(6), rng.normal(size=robot.n_joints)))
    for name, model in models.items():
        calls, start = 20, time.perf_counter()
        for _ in range(calls):
            model.acceleration(q, v, tau)
        out["seconds_per_evaluation"][name] = (time.perf_counter() - start) / calls
    return out


def grid_cell(plant: str, controller: str, integrator: str, duration: float) -> dict:
    """One run of the chapter-5.1 task with the given plant, controller model and integrator."""
    scene = chapter_four_scene(plant, controller, integrator, duration)
    p = prepare(scene)
    result = finished(run(p.robot, p.q0, p.v0, duration, scene.simulation.control_period, p.integrator, p.model,
                          p.controller))
    s = summarize(result.telemetry, p.robot)
    return {"plant": plant, "controller": controller, "integrator": integrator, "status": result.status,
            "tracking_rms_overall": s.get("tracking_rms_overall"),
            "tracking_rms_per_arm": list(s.get("tracking_rms_per_arm", {}).values()),
            "com_drift_max": s["com_drift_max"], "momentum_drift_max": s["momentum_drift_max"],
            "base_displacement": s["base_displacement"], "wall_time_s": result.wall_time_s}


def tumbling_run(model_name: str, case: str, duration: float, seed: int) -> dict:
    """Torque-free motion from a state with momentum; final-state error against exact."""
    robot = four_arm_free()
    P, L = REGIMES[case]
    q0, v0 = state_with_momentum(robot, np.random.default_rng(seed), None if P is None else np.array(P),
                                 None if L is None else np.array(L), joint_range=0.8)
    v0 *= 0.3
    results = {}
    for name in ("exact", model_name):
        integrator = make_integrator("rkmk4", robot.model)
        results[name] = finished(run(robot, q0, v0, duration, 1e-3, integrator, make_model(name, robot)))
    ref, tel = results["exact"].telemetry, results[model_name].telemetry
    rows = min(len(ref.t), len(tel.t))
    error = [float(np.linalg.norm(np.concatenate((pin.difference(robot.model, ref.q[k], tel.q[k]), tel.v[k] - ref.v[k]))))
             for k in range(rows)]
    return {"model": model_name, "case": case, "status": results[model_name].status,
            "final_state_error": error[-1], "error_curve": error[:: max(1, rows // 100)],
            "momentum_drift_max": momentum_drift(tel.momentum),
            "exact_momentum_drift_max": momentum_drift(ref.momentum),
            "wall_time_s": results[model_name].wall_time_s}


def attitude_study() -> dict:
    """Euler-angle vs Lie-group integration of constant spins passing near theta = 90 deg."""
    rows = []
    for eps in (1e-1, 1e-2, 1e-3, 1e-4):
        w = np.array([eps, 1.0, eps])
        exact = np.array([pin.exp3(w * t) for t in np.arange(3001) * 1e-3])
        _, angles = attitude.integrate_euler_angles(lambda t: w, np.zeros(3), 3.0, 1e-3)
        euler = attitude.rotation_error(np.array([attitude.rotation_zyx(a) for a in angles]), exact)
        lie = attitude.rotation_error(attitude.integrate_rotation(lambda t: w, np.eye(3), 3.0, 1e-3), exact)
        closest = float(np.abs(np.cos(np.arcsin(np.clip(-exact[:, 2, 0], -1, 1)))).min())
        rows.append({"spin": w.tolist(), "min_abs_cos_theta": closest,
                     "euler_max_error_rad": float(np.nanmax(euler)), "lie_max_error_rad": float(lie.max())})
    rng = np.random.default_rng(0)
    printed = []
    for _ in range(100):
        angles, rates = rng.uniform(-1.4, 1.4, 3), rng.normal(size=3)
        truth = attitude.euler_rate_matrix(angles) @ rates
        printed.append(np.abs((attitude.euler_rate_matrix(angles, printed=True) @ rates)[::-1] - truth).max() / np.abs(truth).max())
    return {"spins": rows, "eq11_printed_max_relative_error": float(np.max(printed))}


#: Each finished part of the study, one JSON line (``{"settings", "part", "result"}``), so that an
#: interrupted or killed study keeps them and a rerun into the same folder resumes from them.
JOURNAL = "parts.jsonl"


def _journaled(path: Path, settings: dict) -> dict[str, dict]:
    """The parts an earlier run into the same folder journaled with the same settings, by part.

    Raises:
        RunFolderError: naming the journal's line that is not a part of these settings
            (:func:`~.study_journal.entries`).
    """
    def wrong(record: dict) -> str | None:
        if not isinstance(record.get("part"), list) or not isinstance(record.get("result"), dict):
            return "is not a part of this study (a 'part' list and a 'result' table)"
        return None

    return {json.dumps(record["part"]): record["result"] for record in entries(path, settings, wrong)}


def reproduce(out: Path, quick: bool = False, workers: int = 2, seed: int = 0, journal: Path | None = None) -> dict:
    """Run all parts and write ``report.json``, ``report.md`` and figures into ``out``.

    Each finished part (the accuracy table, each grid cell, each tumbling run, the attitude study)
    is appended to ``journal`` (default ``out /`` :data:`JOURNAL`) as it comes in; rerun with the
    same journal and settings, the study takes the parts journaled there instead of recomputing
    them.
    """
    out.mkdir(parents=True, exist_ok=True)
    duration = 0.5 if quick else 5.0
    start = time.perf_counter()
    settings = {"quick": quick, "seed": seed, "grid_duration_s": duration}
    report: dict = {"settings": {**settings, "workers": workers}}
    journal = out / JOURNAL if journal is None else journal
    done = _journaled(journal, settings)
    with open(journal, "a") as log:
        def keep(part: list, result: dict) -> dict:
            log.write(json.dumps({"settings": settings, "part": part, "result": result}) + "\n")
            log.flush()
            done[json.dumps(part)] = result
            return result

        def part(key: list, compute) -> dict:
            return done[json.dumps(key)] if json.dumps(key) in done else keep(key, compute())

        report["accuracy"] = part(["accuracy"], lambda: accuracy(3 if quick else 20, seed))
        cells = [(p, c, "euler") for p in GRID_MODELS for c in GRID_MODELS] + [("exact", c, "rkmk4") for c in EXACT_PLANT_CONTROLLERS]
        cases = [(m, case) for case in list(REGIMES)[1:] for m in TUMBLING_MODELS]
        keys = [["grid", *cell] for cell in cells] + [["tumbling", *case] for case in cases]
        with process_pool(workers, initializer=robot_notes_silenced) as pool:
            futures = {pool.submit(grid_cell, *cell, duration): key for key, cell in zip(keys, cells)
                       if json.dumps(key) not in done}
            futures.update({pool.submit(tumbling_run, *case, 0.1 if quick else 1.0, seed): key
                            for key, case in zip(keys[len(cells):], cases) if json.dumps(key) not in done})
            for future in as_completed(futures):
                keep(futures[future], future.result())
        report["grid"] = [done[json.dumps(key)] for key in keys[:len(cells)]]
        report["tumbling"] = [done[json.dumps(key)] for key in keys[len(cells):]]
        report["attitude"] = part(["attitude"], attitude_study)
    write_report(out, report, markdown, start)
    figures(report, out)
    return report
