"""``rollout`` suite: a batch's runs per second on 1 and 2 threads against ``mujoco.rollout``'s on
the same robot, runs and duration, side by side in one run (issue 23's aim: per core >= 1.5x
MuJoCo's, and >= 1.8x from 1 to 2 cores).

The work: ``runs`` runs of 1 s of torque-free tumbling at 1 ms (1000 steps) of the four-arm robot
(nv 22; its inertias balanced on both sides, as MuJoCo refuses the URDF's), each from its own
initial state: the ``tumbling`` scene's, joint rates varied within +-2 deg/s (the batch's seeded
plans). Four ways, each on 1 and on 2 threads, taking turns ``repeats`` times so that load from
other processes falls on all alike:

- ``freefloat batch``: :func:`freefloat.app.batch.run_batch` with ``Workers(threads=K)``, the
  whole batch as a user waits for it (scene checked, plans, each run prepared, simulated (compiled
  RKMK4, one telemetry row per step; the runs many at a time in one call on K C++ threads,
  :mod:`freefloat.app.batch.compiled_runs`) and reduced to its row, the folder written).
- ``freefloat run_many``: the bare compiled batch, :func:`freefloat.dynamics.many_runs.run_many`
  of the prepared initial states (prepared outside the clock) on K C++ threads (in lockstep, its
  default here), every run's telemetry kept: the call that compares with ``mujoco.rollout``.
- ``freefloat loop``: the bare per-run loop, :func:`freefloat.dynamics.simulation.run` of each
  plan's prepared setup (prepared outside the clock) on a pool of K threads: what a batch costs
  without its per-run setup and summary.
- ``mujoco.rollout``: MuJoCo's RK4 at 1 ms from the same initial states (Pinocchio's state mapped
  to MuJoCo's), one ``Rollout`` call over K ``MjData`` (its persistent pool of K threads; 1: the
  calling thread), returning every step's state (runs x 1000 x nstate).

Rates are best of turns; ratios freefloat over MuJoCo at equal threads ("per core"), and each
way's 2-thread over 1-thread rate paired within each turn (median; the aim is 1.8x), quoted beside
each turn's ceiling (:func:`.batch.ceiling`: what 2 processes of pure Python get over 1 then) and
the load average. The rows of the batch on 1 and 2 threads are checked identical (timings aside),
and the final base positions and joint angles of the loop and of MuJoCo compared (RKMK4 against
RK4, both at 1 ms).
"""

from __future__ import annotations

import dataclasses
import os
import statistics
import tempfile
import time
import warnings
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np

from ....app.batch import TIMINGS, Band, Workers, plan_runs, run_batch
from ....app.runner import prepare, resolved_setup
from ....app.scenes import find_scene
from ....app.signals import imported_whole
from ....dynamics.many_runs import run_many
from ....dynamics.simulation import run
from ..in_mujoco.mjcf import mjcf_from_model
from ..in_mujoco.state import from_mujoco, to_mujoco
from .batch import ceiling
from .drawing import save, subplots

BANDS = [Band("joint_rate", 2.0)]
THREADS = (1, 2)
WAYS = ("freefloat batch", "freefloat run_many", "freefloat loop", "mujoco.rollout")
FREEFLOAT = WAYS[:-1]
#: Issue 23's aims: runs/s per core over MuJoCo's, and 2-thread over 1-thread runs/s.
AIMS = {"per_core_over_mujoco": 1.5, "scaling_1_to_2": 1.8}


def settings(quick: bool, repeats: int | None) -> dict:
    """Runs per batch (24; 4 quick), turns (default 5; 1 quick), the run (1 s at 1 ms), the bands,
    the seed, the ceiling's busy loop (s), the aims."""
    return {"runs": 4 if quick else 24, "repeats": repeats or (1 if quick else 5), "duration_s": 1.0,
            "control_period_s": 1e-3, "robot": "four_arm_planar (inertias balanced)",
            "bands": {b.key: b.width for b in BANDS}, "seed": 0, "threads": list(THREADS),
            "cores": os.cpu_count(), "ceiling_busy_loop_s": 0.25 if quick else 1.0, "aims": AIMS}


def scene(settings: dict):
    """The ``tumbling`` scene for 1 s at 1 ms with balanced inertias, no figures."""
    base = find_scene("tumbling")
    return dataclasses.replace(
        base, robot=dataclasses.replace(base.robot, inertias="balanced"),
        simulation=dataclasses.replace(base.simulation, duration=settings["duration_s"],
                                       control_period=settings["control_period_s"]),
        output=dataclasses.replace(base.output, figures=False, html=False))


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part, ``tumbling``: :func:`compare`."""
    yield "tumbling", compare(settings)


def compare(settings: dict) -> dict:
    """Times (s) per way and threads, turn by turn; best runs/s; ratios and scaling (see the
    module docstring); whether the batch rows agree; the final-state gap; ceilings and load."""
    mujoco, rollout = imported_whole("mujoco"), imported_whole("mujoco.rollout")

    tumbling, runs = scene(settings), settings["runs"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plans = plan_runs(tumbling, prepare(tumbling), BANDS, runs, settings["seed"])
        setups = [resolved_setup(plan.scene) for plan in plans]
    robot, steps = setups[0].robot, round(settings["duration_s"] / settings["control_period_s"])
    model = mujoco.MjModel.from_xml_string(mjcf_from_model(robot.model, "four_arm", settings["control_period_s"], "RK4"))
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    initial = np.zeros((runs, mujoco.mj_stateSize(model, spec)))
    data = mujoco.MjData(model)
    for i, setup in enumerate(setups):
        data.qpos[:], data.qvel[:] = to_mujoco(setup.q0, setup.v0)
        mujoco.mj_getState(model, data, initial[i], spec)

    q0, v0 = np.array([s.q0 for s in setups]), np.array([s.v0 for s in setups])

    def many(k: int) -> list:
        first = setups[0]
        return run_many(first.robot, q0, v0, settings["duration_s"], settings["control_period_s"], first.integrator,
                        first.model, threads=k)

    def loop(setup):
        return run(setup.robot, setup.q0, setup.v0, settings["duration_s"], settings["control_period_s"],
                   setup.integrator, setup.model, backend="compiled")

    times = {f"{way}, {k}": [] for way in WAYS for k in THREADS}
    rows: dict[int, list[dict]] = {}
    finals: dict[str, np.ndarray] = {}
    ceilings, loads = [], [os.getloadavg()]
    pools = {k: rollout.Rollout(nthread=0 if k == 1 else k) for k in THREADS}
    datas = {k: [mujoco.MjData(model) for _ in range(k)] for k in THREADS}
    with tempfile.TemporaryDirectory() as scratch, ProcessPoolExecutor(2) as processes, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the scene's warnings, once per batch
        loop(setups[0])  # imports, the compiled loop and the thread pools made, outside the clock
        run_batch(tumbling, Path(scratch) / "warm-up", len(THREADS), BANDS, workers=Workers(threads=max(THREADS)))
        for k in THREADS:
            pools[k].rollout(model, datas[k], initial, nstep=1)
        for repeat in range(settings["repeats"]):
            ceilings.append(ceiling(processes, settings["ceiling_busy_loop_s"]))
            for k in THREADS:
                start = time.perf_counter()
                done = run_batch(tumbling, Path(scratch) / f"batch-{k}-{repeat}", runs, BANDS, settings["seed"],
                                 Workers(threads=k))
                times[f"freefloat batch, {k}"].append(time.perf_counter() - start)
                rows[k] = [{key: v for key, v in r.items() if key not in TIMINGS} for r in done.rows]

                start = time.perf_counter()
                many_results = many(k)
                times[f"freefloat run_many, {k}"].append(time.perf_counter() - start)
                finals["run_many"] = many_results[0].telemetry.q[-1]

                start = time.perf_counter()
                with ThreadPoolExecutor(k) as threads:
                    results = list(threads.map(loop, setups))
                times[f"freefloat loop, {k}"].append(time.perf_counter() - start)
                finals["freefloat"] = results[0].telemetry.q[-1]

                start = time.perf_counter()
                states, _ = pools[k].rollout(model, datas[k], initial, nstep=steps)
                times[f"mujoco.rollout, {k}"].append(time.perf_counter() - start)
                finals["mujoco"] = states[0, -1, 1:1 + model.nq]
            loads.append(os.getloadavg())
    for pool in pools.values():
        pool.close()
    best = {name: min(t) for name, t in times.items()}
    rate = {name: runs / t for name, t in best.items()}
    scaling = {way: statistics.median(one / two for one, two in zip(times[f"{way}, 1"], times[f"{way}, 2"]))
               for way in WAYS}
    mujoco_q = from_mujoco(finals["mujoco"], np.zeros(model.nv))[0]
    gap = np.r_[finals["freefloat"][:3] - mujoco_q[:3], finals["freefloat"][7:] - mujoco_q[7:]]  # position, joints
    return {
        "runs": runs, "steps": steps, "times_s": times, "best_s": best, "runs_per_second": rate,
        "per_core_over_mujoco": {f"{way}, {k}": rate[f"{way}, {k}"] / rate[f"mujoco.rollout, {k}"]
                                 for way in FREEFLOAT for k in THREADS},
        "scaling_1_to_2": scaling,
        "scaling_per_repeat": {way: [one / two for one, two in zip(times[f"{way}, 1"], times[f"{way}, 2"])]
                               for way in WAYS},
        "rows_identical": rows[1] == rows[2], "completed": sum(r["status"] == "completed" for r in rows[1]),
        "final_position_and_joints_difference": float(np.max(np.abs(gap))),
        "run_many_equals_loop": bool(np.array_equal(finals["run_many"], finals["freefloat"])),
        "ceiling_2_processes": ceilings, "load_average": loads,
    }


def chart(report: dict, path: Path) -> None:
    """Left: runs per second per way on 1 and 2 threads (labels: over MuJoCo at equal threads).
    Right: each way's 2-thread over 1-thread speed-up per turn, the aim and the ceilings drawn."""
    r = report["tumbling"]
    fig, (left, right) = subplots(1, 2, (13, 4))
    width = 0.8 / len(THREADS)
    for j, k in enumerate(THREADS):
        bars = left.bar([i + j * width for i in range(len(WAYS))], [r["runs_per_second"][f"{w}, {k}"] for w in WAYS],
                        width, label=f"{k} thread{'s' if k > 1 else ''}")
        for bar, way in zip(bars, FREEFLOAT):
            left.annotate(f"{r['per_core_over_mujoco'][f'{way}, {k}']:.2f}x", (bar.get_x() + bar.get_width() / 2,
                          bar.get_height()), ha="center", va="bottom", fontsize=8)
    left.set_xticks([i + width / 2 for i in range(len(WAYS))], list(WAYS))
    left.set_ylabel("runs per second (best of turns)")
    left.set_title(f"{r['runs']} runs of 1 s tumbling at 1 ms, nv 22\nlabels: over mujoco.rollout at equal threads "
                   f"(aim {AIMS['per_core_over_mujoco']}x)")
    left.legend()
    for way in WAYS:
        right.plot(r["scaling_per_repeat"][way], "o-", label=way)
    right.plot(r["ceiling_2_processes"], "k--", label="2-process ceiling (pure Python)")
    right.axhline(AIMS["scaling_1_to_2"], color="grey", lw=0.8, label=f"aim {AIMS['scaling_1_to_2']}x")
    turns = range(len(r["ceiling_2_processes"]))
    right.set_xticks(list(turns), [str(t + 1) for t in turns])
    right.set_xlabel("turn")
    right.set_ylabel("runs/s on 2 threads over 1")
    right.set_title(f"1 to 2 threads, {report['settings']['cores']} cores (shared machine)")
    right.legend(fontsize=8)
    save(fig, path)
