"""``batch`` suite: ``freefloat batch``'s runs per second one after another, on 2 threads of one
process, on a pool of 2 processes and on a local Dask cluster of 2 workers, side by side in one
run; and what parallelism the shared machine offers at the time.

For each scene (the default computed-torque task, 5 s; torque-free tumbling, 2 s), the same seeded
batch (joint rates +-2 deg/s and plant masses +-10 %) runs through
:func:`freefloat.app.batch.run_batch` serially, on 2 threads, on a 2-process pool and on a 2-worker
local Dask cluster, taking turns ``repeats`` times so that load from other processes falls on all of
them alike. Each time is the whole batch as a user waits for it: pool or cluster start-up, the
runs, the folder written (in a temporary folder; the scene's nominal preparation excluded). A
fifth column runs the Dask batch on a cluster started (and its workers warmed by a first batch)
before the clock starts, through its scheduler address: the rate once the cluster is up. The rows
of all are checked identical (timings aside). The ceiling: a pure-Python busy loop of
:data:`CEILING_S` s, twice one after another against once on each of 2 processes, taking turns
with the batches: the speed-up any work could get from 2 processes on this machine then. Speed-ups
are paired: serial time over the executor's time within each turn (the median over turns is
charted); quote them beside that turn's ceiling.
"""

from __future__ import annotations

import logging
import os
import statistics
import tempfile
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from ....app.batch import TIMINGS, Band, Workers, run_batch
from ....app.scenes import find_scene
from ....distributed import client
from .drawing import save, subplots

SCENES = ("four_arm_joint_space", "tumbling")
BANDS = [Band("joint_rate", 2.0), Band("mass", 0.1)]
EXECUTORS = {"serial": Workers(1), "threads of 2": Workers(threads=2), "pool of 2": Workers(2),
             "dask local cluster of 2": Workers(2, dask=True)}
#: The executor on the cluster started before the clock.
WARM = "dask cluster already up"
#: Length of one busy loop of the ceiling measurement, s (quick: a quarter).
CEILING_S = 1.0


def settings(quick: bool, repeats: int | None) -> dict:
    """Runs per batch (12; 4 quick), turns of the executors (default 5; 1 quick), the scenes
    (quick: tumbling only), the bands, the seed, the ceiling's busy loop (s)."""
    return {"runs": 4 if quick else 12, "repeats": repeats or (1 if quick else 5),
            "scenes": SCENES[1:] if quick else SCENES, "bands": {b.key: b.width for b in BANDS}, "seed": 0,
            "cores": os.cpu_count(), "ceiling_busy_loop_s": CEILING_S / 4 if quick else CEILING_S}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per scene (:func:`one_scene`), with the warm cluster and the pool of the ceiling
    shared."""
    import distributed  # noqa: F401  -- configures its loggers on import; quieten them after

    logging.getLogger("distributed").setLevel(logging.ERROR)
    with client(None, 2) as warm, ProcessPoolExecutor(2) as pool, tempfile.TemporaryDirectory() as scratch:
        address = warm.scheduler.address
        run_batch(find_scene("tumbling"), Path(scratch) / "warm-up", 2, BANDS, workers=Workers(1, True, address))
        for name in settings["scenes"]:
            yield name, one_scene(name, settings, Path(scratch), address, pool)


def busy(seconds: float) -> int:
    """A pure-Python loop for about ``seconds`` s of one core (the count it reached)."""
    end, n = time.perf_counter() + seconds, 0
    while time.perf_counter() < end:
        n += 1
    return n


def ceiling(pool: ProcessPoolExecutor, seconds: float) -> float:
    """Work done per second by 2 processes against 1, on this machine now (2.0: two free cores),
    from busy loops of ``seconds`` s."""
    alone = busy(seconds) + busy(seconds)  # in 2 seconds
    together = sum(pool.map(busy, [seconds, seconds]))  # in seconds
    return 2.0 * together / alone


def one_scene(scene_name: str, settings: dict, scratch: Path, scheduler: str, pool: ProcessPoolExecutor) -> dict:
    """All and best wall times (s) of the batch per executor, best runs/s, speed-ups over serial
    per turn and their median, whether the rows agree, the load average and the ceiling of each
    turn."""
    runs, scene = settings["runs"], find_scene(scene_name)
    executors = {**EXECUTORS, WARM: Workers(1, dask=True, scheduler=scheduler)}
    times: dict[str, list[float]] = {name: [] for name in executors}
    rows: dict[str, list[dict]] = {}
    ceilings, load = [], os.getloadavg()
    for repeat in range(settings["repeats"]):
        ceilings.append(ceiling(pool, settings["ceiling_busy_loop_s"]))
        for name, workers in executors.items():
            start = time.perf_counter()
            folder = scratch / scene_name / f"{name.replace(' ', '-')}-{repeat}"
            done = run_batch(scene, folder, runs, BANDS, seed=settings["seed"], workers=workers)
            times[name].append(time.perf_counter() - start)
            rows[name] = [{k: v for k, v in r.items() if k not in TIMINGS} for r in done.rows]
    best = {name: min(t) for name, t in times.items()}
    paired = {name: [s / t for s, t in zip(times["serial"], times[name])] for name in times}
    return {
        "runs": runs, "times_s": times, "best_s": best,
        "runs_per_second": {name: runs / t for name, t in best.items()},
        "speed_up_over_serial": {name: statistics.median(r) for name, r in paired.items()},
        "speed_up_per_repeat": paired,
        "rows_identical": all(r == rows["serial"] for r in rows.values()),
        "completed": sum(r["status"] == "completed" for r in rows["serial"]),
        "ceiling_2_processes": ceilings,
        "load_average_before": load, "load_average_after": os.getloadavg(),
    }


def chart(report: dict, path: Path) -> None:
    """Runs per second per scene and executor, bars labelled with the median paired speed-up."""
    results = {name: report[name] for name in report["settings"]["scenes"]}
    fig, ax = subplots(1, 1, (7, 4))
    names = list(next(iter(results.values()))["runs_per_second"])
    width = 0.8 / len(names)
    for k, name in enumerate(names):
        bars = ax.bar([i + k * width for i in range(len(results))], [r["runs_per_second"][name] for r in results.values()],
                      width, label=name)
        for bar, r in zip(bars, results.values()):
            ax.annotate(f"{r['speed_up_over_serial'][name]:.2f}x", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                        ha="center", va="bottom", fontsize=8)
    ax.set_xticks([i + 0.4 - width / 2 for i in range(len(results))],
                  [f"{n}\n(2-process ceiling {min(r['ceiling_2_processes']):.2f}-{max(r['ceiling_2_processes']):.2f}x)"
                   for n, r in results.items()])
    ax.set_ylabel("runs per second (whole batch, best of turns)")
    ax.set_title(f"freefloat batch on {report['settings']['cores']} cores (shared machine); labels: median speed-up\n"
                 "over serial, paired within each turn")
    ax.legend()
    save(fig, path)
