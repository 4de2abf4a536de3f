"""Mechanism map points reached by a simulated motion, 20 per mechanism (issue 21's check).

Usage: ``python3 scripts/mechanism_reach_check.py [--count 20] [--seed 0]``. For the 5R and the
2RSU+PPaP: seeded map points in the scenes' working mode, reachable from the scenes' start along
a line without a type II crossing (:func:`freefloat.app.atlas.mechanism_reach.targets`), each
driven to by computed torque on the simulated plant; prints the largest platform error at the
end, whether every run ended in the scenes' mode, and the largest difference of the actuated
joints from the map's (angles modulo 2 pi). docs/parallel.md quotes its output.
"""

from __future__ import annotations

import argparse

import numpy as np

from freefloat.app.atlas.mechanism_reach import drive_to, targets
from freefloat.app.atlas.mechanism_targets import setup_of
from freefloat.parallel.maps.solve import wrap


def main() -> None:
    cli = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    cli.add_argument("--count", type=int, default=20, help="points per mechanism (default 20)")
    cli.add_argument("--seed", type=int, default=0, help="seed of the points (default 0)")
    args = cli.parse_args()
    for name in ("five_bar", "rsu_ppap"):
        mech = setup_of(name).nominal
        points, expected = targets(name, args.count, args.seed)
        arrivals = [drive_to(name, x) for x in points]
        error = max(np.abs(a.q[: mech.p] - x).max() for a, x in zip(arrivals, points))
        joints = max(np.abs(wrap(mech, a.q - q)[mech.actuated]).max() for a, q in zip(arrivals, expected))
        modes = {a.mode for a in arrivals}
        spread = np.ptp(points, axis=0)
        print(f"{name}: {len(points)} points (spread {np.round(spread, 3).tolist()} m), all runs "
              f"{'completed' if all(a.status == 'completed' for a in arrivals) else 'NOT completed'}; "
              f"platform error at the end {error:.2e} m; modes at the end {sorted(modes)}; "
              f"actuated joints off the map's by {joints:.2e}")


if __name__ == "__main__":
    main()
