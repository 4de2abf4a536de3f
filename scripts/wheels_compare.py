"""The reaction-wheel scenes three ways: the wheels holding the base attitude, the same wheels free
(no torque), and no wheels at all, on the same arm motion; prints one table and writes
runs/wheels-compare-<time>/wheels_compare.json (docs/wheels.md quotes it).

    python3 scripts/wheels_compare.py [SCENE ...]   # default: satellite_wheels detumble_impulse_wheel
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

from freefloat.app.runner import simulate
from freefloat.app.scenes import find_scene
from freefloat.app.scenes.schema import AttitudeSection
from freefloat.dynamics.metrics import rotation_angle

SCENES = ("satellite_wheels", "detumble_impulse_wheel")
KEYS = ("base_rotation_max", "tracking_rms_overall", "wheel_momentum_max", "wheel_momentum_final",
        "wheel_stored_momentum_change", "arm_reaction_momentum", "wheel_momentum_balance_max", "momentum_drift_max",
        "momentum_balance_max", "external_impulse", "wheel_saturated", "detumbled_rows_speed_final", "sim_wall_time_s")


#: A start tumbling as satellite_dual_arm's, for the scenes that start at rest (deg/s).
TUMBLE = (1.0, -0.5, 2.0)


def variants(name: str) -> dict:
    """The scene held, with free wheels, and without wheels (no figures or page); a scene that
    starts at rest also held from a tumble at :data:`TUMBLE`, which the wheels stop and store."""
    scene = find_scene(name)
    scene = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False, html=False))
    runs = {"held": scene,
            "free wheels": dataclasses.replace(scene, attitude=AttitudeSection(kind="none")),
            "no wheels": dataclasses.replace(scene, wheels=(), attitude=None)}
    if not any(scene.initial.base_angular_velocity) and scene.angle_unit == "deg":
        tumbling = dataclasses.replace(scene.initial, base_angular_velocity=TUMBLE)
        runs["held, tumbling at start"] = dataclasses.replace(scene, initial=tumbling)
    return runs


def main(names: list[str]) -> None:
    out = Path("runs") / f"wheels-compare-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    report = {}
    for name in names or SCENES:
        for label, scene in variants(name).items():
            outcome = simulate(scene)
            tel = outcome.telemetry
            row = {k: outcome.summary[k] for k in KEYS if k in outcome.summary}
            row["base_rotation_final"] = float(rotation_angle(tel.base_quaternion[-1:], tel.base_quaternion[0])[0])
            row["base_angular_velocity_start_final"] = [float(np.linalg.norm(tel.base_twist[i, 3:])) for i in (0, -1)]
            row["angular_momentum_start"] = tel.momentum[0, 3:].tolist()
            report[f"{name} / {label}"] = row
            print(f"{name:24s} {label:12s} base rotation max {row['base_rotation_max']:.3g} rad, "
                  f"final {row['base_rotation_final']:.3g} rad; "
                  + ", ".join(f"{k} {np.round(row[k], 9) if isinstance(row[k], float) else row[k]}"
                              for k in ("wheel_momentum_final", "wheel_momentum_balance_max") if k in row))
    (out / "wheels_compare.json").write_text(json.dumps(report, indent=1))
    print(f"-> {out / 'wheels_compare.json'}")


if __name__ == "__main__":
    main(sys.argv[1:])
