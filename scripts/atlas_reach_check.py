"""Issue 21's check of a workspace map: 20 grid points (seeded draw) of `freefloat atlas workspace
ROBOT` each reached by a simulated motion (computed torque, exact plant, the one loop), and how far
the end-effector arrives from the mapped point. Prints one line per point and the worst error.

    python3 scripts/atlas_reach_check.py four_arm_planar [--points 20] [--grid 7] [--seed 0]
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from freefloat.app.atlas import workspace
from freefloat.app.atlas.arm_maps import evaluate
from freefloat.app.atlas.kinds import Options
from freefloat.app.atlas.reach_check import drive_to


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robot", help="a robot's name or URDF file")
    parser.add_argument("--points", type=int, default=20, help="grid points checked (default 20)")
    parser.add_argument("--grid", type=int, default=7, help="points per axis of the map (default 7)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the draw (default 0)")
    args = parser.parse_args()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        context = workspace.prepare(args.robot, Options())
    grid = workspace.grid(context, Options(grid=args.grid))
    chosen = np.random.default_rng(args.seed).choice(grid.size, size=min(args.points, grid.size), replace=False)
    mapped = evaluate(context, grid.points()[chosen])["ee_from_com"]
    errors = []
    for k, index in enumerate(chosen):
        arrival = drive_to(context, grid.points(index, index + 1)[0])
        errors.append(float(np.linalg.norm(arrival.ee_from_com - mapped[k])))
        print(f"point {index}: mapped {np.round(mapped[k], 4)} m, arrived {errors[-1]:.2e} m from it, "
              f"CoM moved {arrival.com_drift:.1e} m")
    print(f"{args.robot}, {context.end_effector}: {len(errors)} points, worst {max(errors):.2e} m, "
          f"median {np.median(errors):.2e} m")


if __name__ == "__main__":
    main()
