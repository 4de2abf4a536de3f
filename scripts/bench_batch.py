"""Benchmark ``freefloat batch``: runs per second one after another, on a pool of 2 processes and
on a local Dask cluster of 2 workers, side by side in one run; and what parallelism the shared
machine offers at the time.

Writes ``bench_batch.json`` and ``bench_batch.png`` (default ``runs/bench-batch-<time>``) with
versions and settings. For each scene (the default computed-torque task, 5 s; torque-free
tumbling, 2 s), the same seeded batch (``--runs`` runs, joint rates +-2 deg/s and plant masses
+-10 %) runs through :func:`freefloat.app.batch.run_batch` serially, on a 2-process pool and on
a 2-worker local Dask cluster, the three taking turns ``--repeats`` times so that load from other
processes falls on all of them alike. Each time is the whole batch as a user waits for it: pool
or cluster start-up, the runs, the folder written (the scene's nominal preparation excluded).
A fourth column runs the Dask batch on a cluster started (and its workers warmed by a first
batch) before the clock starts, through its scheduler address (``--scheduler``): the rate once the
cluster is up. The rows of all are checked identical (timings aside). The ceiling: a pure-Python
busy loop of ``CEILING_S`` s, twice one after another against once on each of 2 processes, taking
turns with the batches: the speed-up any work could get from 2 processes on this machine then.
Speed-ups are paired: serial time over the executor's time within each turn (the median over
turns is charted); quote them beside that turn's ceiling.
"""

from __future__ import annotations

import logging
import os
import shutil
import statistics
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

from bench_common import parser, save_chart, write_json

from freefloat.app.batch import Band, Workers, run_batch
from freefloat.app.batch.one_run import TIMINGS
from freefloat import find_scene
from freefloat.distributed import client

SCENES = ("four_arm_joint_space", "tumbling")
BANDS = [Band("joint_rate", 2.0), Band("mass", 0.1)]
EXECUTORS = {"serial": Workers(1), "pool of 2": Workers(2), "dask local cluster of 2": Workers(2, dask=True)}
WARM = "dask cluster already up"
#: Length of one busy loop of the ceiling measurement, s.
CEILING_S = 1.0


def busy(seconds: float) -> int:
    """A pure-Python loop for about ``seconds`` s of one core (the count it reached)."""
    end, n = time.perf_counter() + seconds, 0
    while time.perf_counter() < end:
        n += 1
    return n


def ceiling(pool: ProcessPoolExecutor) -> float:
    """Work done per second by 2 processes against 1, on this machine now (2.0: two free cores)."""
    alone = busy(CEILING_S) + busy(CEILING_S)  # in 2 CEILING_S
    together = sum(pool.map(busy, [CEILING_S, CEILING_S]))  # in CEILING_S
    return 2.0 * together / alone


def measure(scene_name: str, runs: int, repeats: int, out, scheduler: str, pool: ProcessPoolExecutor) -> dict:
    """All and best wall times (s) of the batch per executor, best runs/s, speed-ups over serial
    per turn and their median, whether the rows agree, and the ceiling of each turn."""
    scene = find_scene(scene_name)
    executors = {**EXECUTORS, WARM: Workers(1, dask=True, scheduler=scheduler)}
    times: dict[str, list[float]] = {name: [] for name in executors}
    rows: dict[str, list[dict]] = {}
    ceilings = []
    for repeat in range(repeats):
        ceilings.append(ceiling(pool))
        for name, workers in executors.items():
            folder = out / scene_name / f"{name.replace(' ', '-')}-{repeat}"
            start = time.perf_counter()
            done = run_batch(scene, folder, runs, BANDS, seed=0, workers=workers)
            times[name].append(time.perf_counter() - start)
            rows[name] = [{k: v for k, v in r.items() if k not in TIMINGS} for r in done.rows]
            shutil.rmtree(folder)
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
    }


def chart(results: dict, path) -> None:
    """Runs per second per scene and executor, bars labelled with the median paired speed-up."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    names = list(next(iter(results.values()))["runs_per_second"])
    width = 0.8 / len(names)
    for k, name in enumerate(names):
        xs = [i + k * width for i in range(len(results))]
        rates = [r["runs_per_second"][name] for r in results.values()]
        bars = ax.bar(xs, rates, width, label=name)
        for bar, r in zip(bars, results.values()):
            ax.annotate(f"{r['speed_up_over_serial'][name]:.2f}x", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                        ha="center", va="bottom", fontsize=8)
    ax.set_xticks([i + 0.4 - width / 2 for i in range(len(results))],
                  [f"{n}\n(2-process ceiling {min(r['ceiling_2_processes']):.2f}-{max(r['ceiling_2_processes']):.2f}x)"
                   for n, r in results.items()])
    ax.set_ylabel("runs per second (whole batch, best of turns)")
    ax.set_title(f"freefloat batch on {os.cpu_count()} cores (shared machine); labels: median speed-up\n"
                 "over serial, paired within each turn")
    ax.legend()
    save_chart(fig, path)


def main() -> None:
    args = parser(__doc__, "batch")
    args.add_argument("--runs", type=int, default=12, help="runs per batch (default 12)")
    args.add_argument("--repeats", type=int, default=5, help="turns of the executors (default 5)")
    args.add_argument("--quick", action="store_true", help="4 runs, one repeat, the tumbling scene only")
    ns = args.parse_args()
    runs, repeats, scenes = (4, 1, ("tumbling",)) if ns.quick else (ns.runs, ns.repeats, SCENES)
    load = os.getloadavg()
    import distributed  # noqa: F401  -- configures its loggers on import; quieten them after

    logging.getLogger("distributed").setLevel(logging.ERROR)
    with warnings.catch_warnings(), client(None, 2) as warm, ProcessPoolExecutor(2) as pool:
        warnings.simplefilter("ignore")
        address = warm.scheduler.address
        run_batch(find_scene("tumbling"), ns.out / "warm-up", 2, BANDS, workers=Workers(1, True, address))
        shutil.rmtree(ns.out / "warm-up")
        results = {name: measure(name, runs, repeats, ns.out, address, pool) for name in scenes}
    report = {"settings": {"runs": runs, "repeats": repeats, "bands": {b.key: b.width for b in BANDS}, "seed": 0,
                           "cores": os.cpu_count(), "ceiling_busy_loop_s": CEILING_S, "load_average_before": load, "load_average_after": os.getloadavg()},
              "scenes": results}
    path = write_json(ns.out, "batch", report)
    chart(results, ns.out / "bench_batch.png")
    for name, r in results.items():
        print(f"{name}: best runs/s {', '.join(f'{k} {v:.2f}' for k, v in r['runs_per_second'].items())}; "
              f"rows identical: {r['rows_identical']}")
        for turn, ceiling_ in enumerate(r["ceiling_2_processes"]):
            ups = ", ".join(f"{k} {v[turn]:.2f}x" for k, v in r["speed_up_per_repeat"].items() if k != "serial")
            print(f"  turn {turn}: 2-process ceiling {ceiling_:.2f}x; over serial: {ups}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
