"""Issue 21 item 3's comparison: each planned capture scene run through the one loop with each
approach method (null_space, min_norm, optimised) on the same target, the base attitude change
during the approach (planned and simulated), the grasp mismatch at contact and the peaks, written
as JSON and printed as a table.

    python3 scripts/approach_comparison.py [--scenes capture_planned_planar,...] [--methods ...]
                                           [--match position|pose] [--out approach_comparison.json]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
import warnings

from freefloat.app.runner import simulate
from freefloat.app.scenes import find_scene

SCENES = ("capture_planned_planar", "capture_planned_satellite", "capture_planned_two_hands_planar",
          "capture_planned_two_hands_satellite")
METHODS = ("null_space", "min_norm", "optimised")
KEYS = ("approach_plan_attitude_change", "approach_base_attitude_change", "grasp_position_mismatch",
        "grasp_velocity_mismatch", "grasp_angular_velocity_mismatch", "grasp_impulse", "approach_plan_peak_joint_rate", "approach_plan_peak_torque",
        "target_angular_velocity_final")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(SCENES), help="comma-separated planned capture scenes")
    parser.add_argument("--methods", default=",".join(METHODS), help="comma-separated approach methods")
    parser.add_argument("--match", default=None, choices=("position", "pose"),
                        help="what the hands match (default: each scene's approach.match)")
    parser.add_argument("--out", default="approach_comparison.json", help="JSON file written")
    args = parser.parse_args()
    rows = []
    for name in args.scenes.split(","):
        scene = find_scene(name)
        for method in args.methods.split(","):
            match = args.match or scene.approach.match
            variant = dataclasses.replace(scene, approach=dataclasses.replace(scene.approach, method=method,
                                                                              compare=False, match=match))
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                summary = simulate(variant).summary
            rows.append({"scene": name, "method": method, "match": match, "wall_time_s": time.perf_counter() - start,
                         **{key: summary.get(key) for key in KEYS}})
            print(" ".join(f"{k}={v:.3g}" if isinstance(v, float) else f"{k}={v}" for k, v in rows[-1].items()),
                  flush=True)
    with open(args.out, "w") as out:
        json.dump(rows, out, indent=1)


if __name__ == "__main__":
    main()
