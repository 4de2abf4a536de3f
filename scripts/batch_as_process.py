"""Issue 40's end-to-end batch aim, as a user meets it: `freefloat batch` of N runs as a whole
process against a MuJoCo user's script doing the same runs with `mujoco.rollout` (load the MJCF
and the start states, RK4 at 1 ms, keep every step's state, save the final ones), each robot's two
commands taking turns, CPU time of each finished process (its own accounting: per core).

The runs: the `tumbling` scene (balanced inertias, which MuJoCo needs), joint rates drawn within
+-2 deg/s by the batch's seeded plan; 1 s on the four-arm robot (nv 22) and the dual-arm
satellite (nv 18), 0.2 s on 32 spatial arms (nv 134). The MJCF and the start states are written
before the clock (a MuJoCo user has their model file). Writes batch_as_process.json and .png.

    python3 scripts/batch_as_process.py --out runs/batch-as-process [--runs 256] [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

#: (name, URDF or arm count, duration s) of each robot.
ROBOTS = (("four_arm", "four_arm_planar.urdf", 1.0), ("dual_arm", "dual_arm_satellite.urdf", 1.0),
          ("arms32", 32, 0.2))
#: The issue's aim: MuJoCo's CPU time over freefloat's, end to end.
AIM = 1.5
SCENE = """name = "{name}"
description = "tumbling, balanced inertias, for the end-to-end batch comparison"
angle_unit = "deg"
[robot]
urdf = "{urdf}"
base = "free"
inertias = "balanced"
[initial]
base_linear_velocity = [0.01, 0.0, -0.02]
base_angular_velocity = [5.0, -3.0, 8.0]
[task]
kind = "none"
[controller]
kind = "none"
[simulation]
duration = {duration}
control_period = 0.001
model = "exact"
integrator = "rkmk4"
[output]
figures = false
html = false
"""
MUJOCO_USER = """import sys, numpy as np, mujoco
from mujoco import rollout
model = mujoco.MjModel.from_xml_path(sys.argv[1])
states, _ = rollout.rollout(model, mujoco.MjData(model), np.load(sys.argv[2]), nstep=int(sys.argv[3]))
np.save(sys.argv[4], states[:, -1])
"""


def prepare(folder: Path, name: str, urdf: str | int, duration: float, runs: int) -> tuple[Path, Path, Path]:
    """The scene file, the MJCF of the same Pinocchio model and the runs' start states (runs, nstate)."""
    import mujoco

    from freefloat.app.batch import Band, plan_runs
    from freefloat.app.runner import prepare as prepare_scene
    from freefloat.app.runner import resolved_setup
    from freefloat.app.scenes import load_scene
    from freefloat.lab.bench.in_mujoco.mjcf import mjcf_from_model
    from freefloat.lab.bench.in_mujoco.state import to_mujoco
    from freefloat.lab.bench.suites.robots import multi_arm_robot

    if isinstance(urdf, int):
        urdf = str(multi_arm_robot(urdf, folder).urdf_path)
    scene_file = folder / f"{name}.toml"
    scene_file.write_text(SCENE.format(name=name, urdf=urdf, duration=duration))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = load_scene(scene_file)
        setups = [resolved_setup(plan.scene) for plan in plan_runs(scene, prepare_scene(scene),
                                                                   [Band("joint_rate", 2.0)], runs, 0)]
    xml = folder / f"{name}.xml"
    xml.write_text(mjcf_from_model(setups[0].robot.model, name, 1e-3, "RK4"))
    model = mujoco.MjModel.from_xml_path(str(xml))
    data, spec = mujoco.MjData(model), mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = np.zeros((runs, mujoco.mj_stateSize(model, spec)))
    for i, setup in enumerate(setups):
        data.qpos[:], data.qvel[:] = to_mujoco(setup.q0, setup.v0)
        mujoco.mj_getState(model, data, states[i], spec)
    np.save(folder / f"{name}_start.npy", states)
    return scene_file, xml, folder / f"{name}_start.npy"


def timed(argv: list[str]) -> tuple[float, float]:
    """(CPU s, wall s) of the finished process ``argv`` (its children included)."""
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, wall


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="output folder (created; must not exist)")
    parser.add_argument("--runs", type=int, default=256, help="runs per batch (default 256)")
    parser.add_argument("--repeats", type=int, default=5, help="turns of each pair of commands (default 5)")
    args = parser.parse_args()
    args.out.mkdir(parents=True)
    (args.out / "mujoco_user.py").write_text(MUJOCO_USER)
    freefloat = [sys.executable, "-m", "freefloat"]
    report = {"runs": args.runs, "repeats": args.repeats, "aim": AIM, "load": [os.getloadavg()], "robots": {}}
    for name, urdf, duration in ROBOTS:
        scene, xml, start = prepare(args.out, name, urdf, duration, args.runs)
        ways = {"freefloat batch": [*freefloat, "batch", str(scene), "--runs", str(args.runs), "--vary", "joint_rate=2",
                                    "--out", str(args.out / f"{name}_batch"), "--overwrite", "--quiet"],
                "mujoco.rollout script": [sys.executable, str(args.out / "mujoco_user.py"), str(xml), str(start),
                                          str(round(duration / 1e-3)), str(args.out / f"{name}_final.npy")]}
        times = {way: [] for way in ways}
        for _ in range(args.repeats + 1):  # the first turn warms the caches and is not kept
            for way, argv in ways.items():
                times[way].append(timed(argv))
        cpu = {way: [c for c, _ in t[1:]] for way, t in times.items()}
        ratios = [m / f for f, m in zip(cpu["freefloat batch"], cpu["mujoco.rollout script"])]
        report["robots"][name] = {"cpu_s": cpu, "wall_s": {way: [w for _, w in t[1:]] for way, t in times.items()},
                                  "mujoco_over_freefloat_cpu": ratios, "median": statistics.median(ratios)}
        print(f"{name}: MuJoCo's CPU over freefloat's, median of pairs {statistics.median(ratios):.2f}x "
              f"({min(ratios):.2f}-{max(ratios):.2f}; aim {AIM}x)")
    report["load"].append(os.getloadavg())
    (args.out / "batch_as_process.json").write_text(json.dumps(report, indent=2))
    _chart(report, args.out / "batch_as_process.png")
    return 0


def _chart(report: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(report["robots"])
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    medians = [report["robots"][n]["median"] for n in names]
    spread = np.array([[m - min(report["robots"][n]["mujoco_over_freefloat_cpu"]),
                        max(report["robots"][n]["mujoco_over_freefloat_cpu"]) - m] for n, m in zip(names, medians)]).T
    ax.bar(names, medians, yerr=spread, color="tab:blue", capsize=4)
    ax.axhline(report["aim"], color="k", linestyle="--", linewidth=0.8, label=f"aim {report['aim']}x")
    ax.set_ylabel("MuJoCo CPU / freefloat CPU (x)")
    ax.set_title(f"{report['runs']} runs as whole processes: freefloat batch vs mujoco.rollout", fontsize="medium")
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    sys.exit(main())
