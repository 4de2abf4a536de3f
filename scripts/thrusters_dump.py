"""Thrusters and momentum dumping (issue 39 item 2), measured: the built-in satellite_momentum_dump
scene (the UR5 satellite's wheels braked while twelve thrusters hold the base) at three minimum
impulse bits. Prints one table, writes runs/thrusters-<time>/thrusters.json and the figure
docs/img/thrusters.png (the runs' own ``thrusters`` figure: thrust per thruster and propellant
burnt, at the scene's bit); docs/thrusters.md quotes both.

    python3 scripts/thrusters_dump.py
"""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from freefloat.app.experiments.robot_run import run_loop
from freefloat.app.runner import prepare
from freefloat.app.scenes import find_scene
from freefloat.dynamics.metrics import summarize
from freefloat.space.thrusters import thruster_summary

BITS = (0.0, 2e-4, 2e-3)  # N s


def dump(bit: float) -> dict:
    """The scene with the minimum impulse bit ``bit`` (N s): its rows and numbers."""
    scene = find_scene("satellite_momentum_dump")
    entry = scene.environment[0]
    scene = dataclasses.replace(scene, environment=(dataclasses.replace(
        entry, settings=dataclasses.replace(entry.settings, min_impulse_bit=bit)),))
    setup = prepare(scene)
    start = time.perf_counter()
    tel = run_loop(setup, None, None).telemetry
    wall = time.perf_counter() - start
    thrusters, wheels = setup.environment[0], setup.wheels
    rotation = np.array([np.linalg.norm(pin.log3(pin.Quaternion(q[3:7]).toRotationMatrix())) for q in tel.q])
    numbers = {
        "min_impulse_bit": bit, "wall_s": wall, "base_rotation_max": float(rotation.max()),
        "wheel_momentum_final": wheels.momenta(tel.v[-1]).tolist(),
        "momentum_balance_max": summarize(tel, setup.plant, (), scene.simulation.control_period,
                                          setup.environment)["momentum_balance_max"],
        **thruster_summary(thrusters, setup.plant, tel),
    }
    return {"numbers": numbers, "figure": (tel.t, *thrusters.rows(tel.t), thrusters.specific_impulse)}


def figure(run: dict) -> None:
    """docs/img/thrusters.png: the run's ``thrusters`` figure (thrust per thruster, propellant)."""
    from freefloat.app.viz.plotting import save
    from freefloat.app.viz.thruster_figures import thruster_figure

    save(thruster_figure(*run["figure"]), Path(__file__).resolve().parents[1] / "docs" / "img", "thrusters")


def main() -> None:
    out = Path("runs") / f"thrusters-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    runs = {bit: dump(bit) for bit in BITS}
    keys = ("base_rotation_max", "thruster_impulse_total", "propellant_mass", "thruster_delta_v", "thruster_firings",
            "momentum_balance_max", "wall_s")
    print("min_impulse_bit  " + "  ".join(keys))
    for bit, run in runs.items():
        print(f"{bit:<16g} " + "  ".join(f"{run['numbers'][k]:.4g}" for k in keys))
    (out / "thrusters.json").write_text(json.dumps([run["numbers"] for run in runs.values()], indent=1))
    figure(runs[2e-4])
    print(f"-> {out}/thrusters.json, docs/img/thrusters.png")


if __name__ == "__main__":
    main()
