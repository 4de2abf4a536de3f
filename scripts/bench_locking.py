"""Benchmark joint locking and ``simulation.model = "auto"`` on scenes that leave joints still.

Writes ``bench_locking.json`` and ``bench_locking.png`` to an output folder (default
``runs/bench-locking-<time>``), with versions and settings. Scenes: the default four-arm task with
only arm 1 moving (arms 2-4 held by the controller), and the UR5 dual-arm satellite with only the
left arm moving. For each, measured side by side in one process (the runs taking turns, best of
``--repeats``):

1. the loop's wall time with every joint (``lock = "none"``) and with the held joints locked
   (``lock = "auto"``), both on the exact plant, and the locked run's state error against the
   unlocked one over the whole run (``freefloat.dynamics.models.selection.state_error``);
2. ``model = "auto"``: the whole call (preparation, pilot, run) against the same call with
   ``model = "exact"``, the plant it chose, its predicted error and its actual error over the run.

Usage: ``python3 scripts/bench_locking.py [--out DIR] [--repeats N] [--quick]``
"""

from __future__ import annotations

import time
import tomllib
import warnings

from bench_common import parser, write_json

from freefloat.app import runner
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.dynamics.models.selection import state_error

#: (label, built-in scene, the one arm that moves and its displacement in the scene's unit).
SCENES = (("four-arm, arm 1 moving", "four_arm_joint_space", {"arm1_ee": 5.0}),
          ("dual-arm satellite, left arm moving", "satellite_dual_arm", {"left_tool0": 20.0}))


def scene_of(builtin: str, displacement: dict, duration: float | None, **simulation):
    """The built-in scene with one arm moving, no figures or page, and the given simulation keys."""
    raw = tomllib.loads(builtin_scenes()[builtin].read_text())
    raw["task"]["displacement"] = displacement
    if duration is not None:
        raw["simulation"]["duration"] = duration
        raw["task"]["duration"] = min(raw["task"]["duration"], duration)
    raw["simulation"].update(simulation)
    raw["output"] = {"figures": False, "html": False}
    return parse_scene(raw)


def timed(scene) -> tuple[float, object]:
    """Wall time of the whole ``runner.simulate`` call, s, and its outcome."""
    start = time.perf_counter()
    outcome = runner.simulate(scene)
    return time.perf_counter() - start, outcome


def measure(builtin: str, displacement: dict, duration: float | None, repeats: int) -> dict:
    """Locked against unlocked loops and auto against exact calls, taking turns, best of ``repeats``."""
    variants = {"unlocked": {"model": "exact", "lock": "none"}, "locked": {"model": "exact", "lock": "auto"},
                "auto": {"model": "auto"}}
    scenes = {name: scene_of(builtin, displacement, duration, **sim) for name, sim in variants.items()}
    loop = dict.fromkeys(variants, float("inf"))
    total = dict.fromkeys(variants, float("inf"))
    outcomes = {}
    for _ in range(repeats):
        for name, scene in scenes.items():
            seconds, outcome = timed(scene)
            total[name], loop[name] = min(total[name], seconds), min(loop[name], outcome.wall_time_s)
            outcomes[name] = outcome
    full = outcomes["unlocked"].telemetry
    setup = runner.prepare(scenes["unlocked"])

    def error(name: str) -> float:
        tel = outcomes[name].telemetry
        return state_error(setup.robot.model, full.q, full.v, tel.q, tel.v)

    choice = outcomes["auto"].summary["model_choice"]
    return {"loop_s": loop, "total_s": total, "locked_joints": list(runner.prepare(scenes["locked"]).lock.names),
            "locked_loop_speedup": loop["unlocked"] / loop["locked"],
            "locked_error_over_run": error("locked"),
            "auto_choice": {"model": choice["model"], "lock": choice["lock"], "pilot_speedup": choice["speedup"],
                            "predicted_error": choice["predicted_error"], "tolerance": choice["tolerance"],
                            "pilot_duration": choice["pilot_duration"], "actual_error_over_run": error("auto")},
            "auto_total_over_exact_total": total["auto"] / total["unlocked"]}


def chart(report: dict, path) -> None:
    """Bars: loop and whole-call wall times per scene and variant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(report["scenes"]), figsize=(5 * len(report["scenes"]), 3.8), squeeze=False)
    for ax, (label, r) in zip(axes[0], report["scenes"].items()):
        names = ["unlocked", "locked", "auto"]
        ax.bar([n + "\nloop" for n in names], [r["loop_s"][n] for n in names], color="#4878a8")
        ax.bar([n + "\ncall" for n in names], [r["total_s"][n] for n in names], color="#a8a8a8")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel("wall time, s (best of runs taking turns)")
        ax.tick_params(axis="x", labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    args = parser(__doc__, "locking")
    args.add_argument("--repeats", type=int, default=3)
    args.add_argument("--quick", action="store_true", help="1 s runs, 1 repeat")
    opts = args.parse_args()
    warnings.simplefilter("ignore")
    duration, repeats = (1.0, 1) if opts.quick else (None, opts.repeats)
    report = {"settings": {"repeats": repeats, "duration": duration or "the scene's"},
              "scenes": {label: measure(builtin, disp, duration, repeats) for label, builtin, disp in SCENES}}
    path = write_json(opts.out, "locking", report)
    chart(report, opts.out / "bench_locking.png")
    for label, r in report["scenes"].items():
        c = r["auto_choice"]
        print(f"{label}: locked loop {r['locked_loop_speedup']:.2f}x faster, error {r['locked_error_over_run']:.2g}; "
              f"auto chose {c['model']} (lock {c['lock']}), predicted {c['predicted_error']:.2g}, actual "
              f"{c['actual_error_over_run']:.2g}; auto call / exact call {r['auto_total_over_exact_total']:.2f}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
