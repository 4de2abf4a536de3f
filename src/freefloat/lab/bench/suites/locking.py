"""``locking`` suite: joint locking and ``simulation.model = "auto"`` on scenes that leave joints
still.

Scenes: the default four-arm task with only arm 1 moving (arms 2-4 held by the controller), and the
UR5 dual-arm satellite with only the left arm moving. For each, measured side by side in one
process (the runs taking turns, best of ``repeats``):

1. the loop's wall time with every joint (``lock = "none"``) and with the held joints locked
   (``lock = "auto"``), both on the exact plant, and the locked run's state error against the
   unlocked one over the whole run (:func:`freefloat.dynamics.models.selection.state_error`);
2. ``model = "auto"``: the whole call (preparation, pilot, run) against the same call with
   ``model = "exact"``, the plant it chose, its predicted error and its actual error over the run.
"""

from __future__ import annotations

import time
import tomllib
from collections.abc import Iterator
from pathlib import Path

from ....app import runner
from ....app.scenes import Scene, builtin_scenes, parse_scene
from ....dynamics.models.selection import state_error
from .drawing import save, subplots

#: (label, built-in scene, the one arm that moves and its displacement in the scene's unit).
SCENES = (("four-arm, arm 1 moving", "four_arm_joint_space", {"arm1_ee": 5.0}),
          ("dual-arm satellite, left arm moving", "satellite_dual_arm", {"left_tool0": 20.0}))
#: The simulation keys of each variant.
VARIANTS = {"unlocked": {"model": "exact", "lock": "none"}, "locked": {"model": "exact", "lock": "auto"},
            "auto": {"model": "auto"}}


def settings(quick: bool, repeats: int | None) -> dict:
    """Repeats (best of; default 3, 1 quick) and the simulated time (quick: 1 s; else the scene's)."""
    return {"repeats": repeats or (1 if quick else 3), "duration_s": 1.0 if quick else None}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part per scene of :data:`SCENES`: :func:`one_scene`."""
    for label, builtin, displacement in SCENES:
        yield label, one_scene(builtin, displacement, settings["duration_s"], settings["repeats"])


def scene_of(builtin: str, displacement: dict, duration: float | None, **simulation) -> Scene:
    """The built-in scene with one arm moving, no figures or page, and the given simulation keys."""
    raw = tomllib.loads(builtin_scenes()[builtin].read_text())
    raw["task"]["displacement"] = displacement
    if duration is not None:
        raw["simulation"]["duration"] = duration
        raw["task"]["duration"] = min(raw["task"]["duration"], duration)
    raw["simulation"].update(simulation)
    raw["output"] = {"figures": False, "html": False}
    return parse_scene(raw)


def one_scene(builtin: str, displacement: dict, duration: float | None, repeats: int) -> dict:
    """Loop and whole-call wall times of each variant of :data:`VARIANTS` (s, best of
    ``repeats``, taking turns), the locked loop's speed-up and error, and what ``auto`` chose."""
    scenes = {name: scene_of(builtin, displacement, duration, **keys) for name, keys in VARIANTS.items()}
    loop = dict.fromkeys(VARIANTS, float("inf"))
    total = dict.fromkeys(VARIANTS, float("inf"))
    outcomes = {}
    for _ in range(repeats):
        for name, scene in scenes.items():
            start = time.perf_counter()
            outcomes[name] = runner.simulate(scene)
            total[name] = min(total[name], time.perf_counter() - start)
            loop[name] = min(loop[name], outcomes[name].wall_time_s)
    full = outcomes["unlocked"].telemetry
    model = runner.prepare(scenes["unlocked"]).robot.model

    def error(name: str) -> float:
        tel = outcomes[name].telemetry
        return state_error(model, full.q, full.v, tel.q, tel.v)

    choice = outcomes["auto"].summary["model_choice"]
    return {"loop_s": loop, "total_s": total, "locked_joints": list(runner.prepare(scenes["locked"]).lock.names),
            "locked_loop_speedup": loop["unlocked"] / loop["locked"],
            "locked_error_over_run": error("locked"),
            "auto_choice": {"model": choice["model"], "lock": choice["lock"], "pilot_speedup": choice["speedup"],
                            "predicted_error": choice["predicted_error"], "tolerance": choice["tolerance"],
                            "pilot_duration": choice["pilot_duration"], "actual_error_over_run": error("auto")},
            "auto_total_over_exact_total": total["auto"] / total["unlocked"]}


def chart(report: dict, path: Path) -> None:
    """Bars: loop and whole-call wall times per scene and variant."""
    fig, axes = subplots(1, len(SCENES), (5 * len(SCENES), 3.8), squeeze=False)
    for ax, (label, _, _) in zip(axes[0], SCENES):
        r = report[label]
        ax.bar([n + "\nloop" for n in VARIANTS], [r["loop_s"][n] for n in VARIANTS], color="#4878a8")
        ax.bar([n + "\ncall" for n in VARIANTS], [r["total_s"][n] for n in VARIANTS], color="#a8a8a8")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel("wall time, s (best of runs taking turns)")
        ax.tick_params(axis="x", labelsize=7)
    save(fig, path)
