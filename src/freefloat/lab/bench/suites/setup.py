"""``setup`` suite: what a run costs beside its loop (issue 23, "reuse across runs"), side by
side in one process.

**Per run** (:func:`freefloat.dynamics.simulation.run`, compiled, RKMK4, 1 ms periods, torque-free,
on the size sweep's robots of 4 to 48 spatial arms, nv 22 to 198): the wall time of a run of one
period, which is its fixed cost (the loop, Pinocchio's model and ``Data`` in C++, the check, the
telemetry), once on a new compiled loop (``new loop``: what the first run of a process pays, the
loops kept by :mod:`freefloat.dynamics.compiled` forgotten just before) and on the loop kept from
the previous run (``kept loop``), each over the loop time of a run of 1 s (``RunResult.wall_time_s``).
For scale, one ``pin.Data`` built in Python (each holds four nv^3 tensors).

**Per batch** (``freefloat batch``'s runs, serially in this process, the same seeded plans): each
run as before issue 23's reuse (``fresh``: the robot loaded and checked, a new compiled loop and
the BLAS libraries scanned for every run) and as a worker now runs it (``reused``), taking turns;
runs per second, best of turns, and whether their rows agree (timings aside).
"""

from __future__ import annotations

import statistics
import tempfile
import time
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ....app.batch import TIMINGS, Band, forget_robots, plan_runs, run_one
from ....app.runner import prepare
from ....app.scenes import find_scene
from ....dynamics import compiled, threads
from ....dynamics.integrators import make_integrator
from ....dynamics.models import make_model
from ....dynamics.simulation import run
from .drawing import save, subplots
from .robots import multi_arm_robot

ARM_COUNTS, QUICK_ARM_COUNTS = (4, 8, 16, 32, 48), (4, 16)
SCENES = ("tumbling", "four_arm_joint_space")
BANDS = [Band("joint_rate", 2.0), Band("mass", 0.1)]
#: The aim of issue 23: a run's fixed cost at most this share of a 1 s run's loop at nv 198.
AIM = 0.10


def settings(quick: bool, repeats: int | None) -> dict:
    """Arm counts (nv = 6 + 4 arms), best of ``repeats`` (default 3; 1 quick), the run (1 s at
    1 ms, RKMK4), the batch scenes (quick: tumbling), runs per batch (12; 4 quick)."""
    return {"arm_counts": QUICK_ARM_COUNTS if quick else ARM_COUNTS, "repeats": repeats or (1 if quick else 3),
            "duration_s": 1.0, "control_period_s": 1e-3, "integrator": "rkmk4",
            "scenes": SCENES[:1] if quick else SCENES, "runs": 4 if quick else 12,
            "bands": {b.key: b.width for b in BANDS}, "seed": 0, "aim": AIM}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per robot (:func:`per_run`), then one per batch scene (:func:`per_batch`)."""
    with tempfile.TemporaryDirectory() as folder:
        for arms in settings["arm_counts"]:
            robot = multi_arm_robot(arms, Path(folder))
            yield f"nv{robot.model.nv}", per_run(robot, settings)
    for name in settings["scenes"]:
        yield name, per_batch(name, settings)


def per_run(robot, settings: dict) -> dict:
    """Fixed cost (s) on a new and on a kept loop, the 1 s run's loop (s), their ratios, and one
    Python ``pin.Data`` (s)."""
    model, repeats, period = robot.model, settings["repeats"], settings["control_period_s"]
    integrator, exact = make_integrator(settings["integrator"], model), make_model("exact", robot)
    q0, v0 = pin.neutral(model), np.random.default_rng(0).normal(0.0, 0.1, model.nv)

    def one_period() -> float:
        start = time.perf_counter()
        run(robot, q0, v0, period, period, integrator, exact, backend="compiled")
        return time.perf_counter() - start

    new, kept, loop = [], [], []
    for _ in range(repeats):  # taking turns, so that other load falls on all alike
        compiled.clear_loops()
        new.append(one_period())
        kept.append(one_period())
        loop.append(run(robot, q0, v0, settings["duration_s"], period, integrator, exact,
                        backend="compiled").wall_time_s)
    start = time.perf_counter()
    model.createData()
    data_s = time.perf_counter() - start
    best = {"new_loop": min(new), "kept_loop": min(kept), "loop_1s": min(loop)}
    return {"nv": model.nv, "fixed_s": {"new_loop": new, "kept_loop": kept}, "loop_1s_s": loop, "best_s": best,
            "fixed_over_loop": {k: best[k] / best["loop_1s"] for k in ("new_loop", "kept_loop")},
            "python_data_s": data_s}


def _fresh() -> None:
    """Forget what a worker keeps between runs: loaded robots, compiled loops, the BLAS scan."""
    forget_robots()
    compiled.clear_loops()
    threads._found[1] = -1


def per_batch(name: str, settings: dict) -> dict:
    """Runs per second of the same serial runs, fresh and reused, best of turns; rows identical."""
    scene = find_scene(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plans = plan_runs(scene, prepare(scene), BANDS, settings["runs"], settings["seed"])
    run_one(plans[0])  # imports and first calls, outside the clock
    times: dict[str, list[float]] = {"fresh": [], "reused": []}
    rows: dict[str, list[dict]] = {}
    for _ in range(settings["repeats"]):
        for mode in times:
            _fresh()
            start = time.perf_counter()
            done = []
            for plan in plans:
                if mode == "fresh":
                    _fresh()
                done.append(run_one(plan))
            times[mode].append(time.perf_counter() - start)
            rows[mode] = [{k: v for k, v in r.items() if k not in TIMINGS} for r in done]
    best = {mode: min(t) for mode, t in times.items()}
    simulated = statistics.fmean(r["sim_wall_time_s"] for r in done)
    return {"runs": len(plans), "times_s": times, "best_s": best,
            "runs_per_second": {mode: len(plans) / t for mode, t in best.items()},
            "reused_over_fresh": best["fresh"] / best["reused"],
            "loop_share": {mode: simulated * len(plans) / t for mode, t in best.items()},
            "rows_identical": rows["fresh"] == rows["reused"],
            "completed": sum(r["status"] == "completed" for r in rows["reused"])}


def chart(report: dict, path: Path) -> None:
    """Left: fixed cost over a 1 s run's loop against nv, new and kept loop, the aim drawn.
    Right: a batch's runs per second, fresh and reused."""
    fig, (left, right) = subplots(1, 2, (11.0, 4.0))
    rows = [report[f"nv{6 + 4 * arms}"] for arms in report["settings"]["arm_counts"]]
    nvs = [r["nv"] for r in rows]
    for key, label in (("new_loop", "new loop (first run of a process)"), ("kept_loop", "kept loop (next runs)")):
        left.plot(nvs, [r["fixed_over_loop"][key] for r in rows], "o-", label=label)
    left.axhline(report["settings"]["aim"], color="grey", ls="--", label="aim (10 %)")
    left.set_yscale("log")
    left.set_xlabel("nv")
    left.set_ylabel("fixed cost / loop of a 1 s run")
    left.set_title("Per-run fixed cost (RKMK4, 1 ms, compiled)")
    left.legend(fontsize=8)
    scenes = report["settings"]["scenes"]
    for k, mode in enumerate(("fresh", "reused")):
        right.bar([i + 0.4 * k for i in range(len(scenes))], [report[s]["runs_per_second"][mode] for s in scenes],
                  0.4, label=mode)
    right.set_xticks([i + 0.2 for i in range(len(scenes))],
                     [f"{s}\n{report[s]['reused_over_fresh']:.2f}x" for s in scenes])
    right.set_ylabel("runs per second (serial, best of turns)")
    right.set_title("freefloat batch: each run fresh, or reused per worker")
    right.legend(fontsize=8)
    save(fig, path)
