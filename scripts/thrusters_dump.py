"""Thrusters and momentum dumping (issue 39 item 2), measured: the built-in satellite_momentum_dump
scene (the UR5 satellite's wheels braked while twelve thrusters hold the base) at three minimum
impulse bits. Prints one table, writes runs/thrusters-<time>/thrusters.json and the figure
docs/img/thrusters.png (thrust per thruster, propellant burnt, the wheels' stored momentum and
the base's rotation, at the scene's bit); docs/thrusters.md quotes both.

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
from freefloat.space.thrusters import G0, thruster_summary

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
    thrust = np.array([thrusters.thrust(t) for t in tel.t])
    spans = np.diff(tel.t, append=tel.t[-1])
    burnt = np.concatenate(([0.0], np.cumsum(thrust.sum(axis=1) * spans)[:-1])) / (thrusters.specific_impulse * G0)
    numbers = {
        "min_impulse_bit": bit, "wall_s": wall, "base_rotation_max": float(rotation.max()),
        "wheel_momentum_final": wheels.momenta(tel.v[-1]).tolist(),
        "momentum_balance_max": summarize(tel, setup.plant, (), scene.simulation.control_period,
                                          setup.environment)["momentum_balance_max"],
        **thruster_summary(thrusters, setup.plant, tel),
    }
    return {"numbers": numbers, "isp": thrusters.specific_impulse, "t": tel.t, "thrust": thrust, "burnt": burnt, "rotation": rotation,
            "stored": wheels.momenta(tel.v)}


def figure(run: dict) -> None:
    """docs/img/thrusters.png: thrust per thruster, propellant, wheels' momentum, base rotation."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = run["t"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    for i, column in enumerate(run["thrust"].T):
        if column.any():
            axes[0, 0].plot(t, column, lw=0.8, label=f"thruster {i}")
    axes[0, 0].set(ylabel="thrust held over the period (N)", title="Thrusters (pulses averaged per period)")
    axes[0, 0].legend(fontsize=7)
    axes[0, 1].plot(t, 1e3 * run["burnt"])
    axes[0, 1].set(ylabel="propellant burnt (g)", title=f"Propellant (I_sp {run['isp']:g} s)")
    for name, column in zip(("wheel_x", "wheel_y", "wheel_z"), run["stored"].T):
        axes[1, 0].plot(t, column, label=name)
    axes[1, 0].set(xlabel="t (s)", ylabel="stored momentum I Omega (N m s)", title="Reaction wheels dumped")
    axes[1, 0].legend(fontsize=7)
    axes[1, 1].plot(t, 1e3 * run["rotation"])
    axes[1, 1].set(xlabel="t (s)", ylabel="base rotation (mrad)", title="Base attitude held")
    fig.tight_layout()
    fig.savefig(Path(__file__).resolve().parents[1] / "docs" / "img" / "thrusters.png", dpi=100)


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
