"""The 2RSU+PPaP's modes at home and its conditioning on a grid about home, from the mechanism maps.

Usage: ``python3 scripts/rsu_ppap_workspace.py [--half 0.05] [--spacing 0.01]``. Prints, for the
assumed geometry (``urdf/rsu_ppap.data.toml``): the working modes (inverse kinematics, one sign
per leg) and assembly modes (direct kinematics) at the home pose, naming the one the scenes use,
and every distinct solution of the direct kinematics there;
over the grid points that assemble in the scenes' mode, the condition numbers of the inverse
block (type I), the direct block (type II) and the actuation map C^T U; the efforts that hold
home at rest against gravity. The whole workspace and its singularity loci are
``freefloat atlas mechanism rsu_ppap [--axes x,y,z]``. docs/parallel.md quotes its output.
"""

from __future__ import annotations

import argparse

import numpy as np

from freefloat import FreefloatError
from freefloat.parallel.maps.jacobians import closure, partition, singularity
from freefloat.parallel.maps.modes import (
    assembly_label,
    assembly_modes,
    direct_solutions,
    working_label,
    working_modes,
)
from freefloat.parallel.rsu_ppap import assembly_guess, load_data, load_rsu_ppap

#: Where the direct kinematics' starts put the platform, m (x, y, z: lower, upper).
BOX = np.array([[-0.33, 0.12], [-0.25, 0.25], [0.05, 0.65]])


def main() -> None:
    cli = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    cli.add_argument("--half", type=float, default=0.05, help="half-width of the cubic grid, m (default 0.05)")
    cli.add_argument("--spacing", type=float, default=0.01, help="grid spacing, m (default 0.01)")
    args = cli.parse_args()
    data, mech = load_data(), load_rsu_ppap().mechanism
    home = np.array(data["home"])
    q_home = mech.assemble(home, assembly_guess(data, home))
    working = working_modes(mech, home[None], count=64)
    assembly = assembly_modes(mech, q_home[None, mech.actuated], BOX, count=64)
    print(f"home {home.tolist()} m: working modes {[m for m, f in zip(working.labels, working.found[0]) if f]} "
          f"(the scenes': {working_label(mech, q_home)}); assembly modes "
          f"{[m for m, f in zip(assembly.labels, assembly.found[0]) if f]} (the scenes': {assembly_label(mech, q_home)})")
    for label, q in zip(working.labels, working.q[0]):
        print(f"  working mode {label}: cranks {q[mech.actuated[0]]:+.3f}, {q[mech.actuated[1]]:+.3f} rad; "
              f"parallelogram bar {q[-3]:+.3f} rad")
    solutions = direct_solutions(mech, q_home[mech.actuated], BOX)
    print(f"direct kinematics at home's actuated joints: {len(solutions)} distinct solutions")
    for q in solutions:
        print(f"  platform {np.round(q[:3], 4).tolist()} m, bar {q[-3]:+.3f} rad, assembly mode "
              f"{assembly_label(mech, q)}, working mode {working_label(mech, q)}")
    axis = np.arange(-args.half, args.half + 1e-12, args.spacing)
    points = home + np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    poses = []
    for x in points:
        try:
            poses.append(mech.assemble(x, assembly_guess(data, x)))
        except FreefloatError:
            continue
    q = np.array(poses)
    s = singularity(partition(mech), closure(mech, q)[1])
    cond_b = np.linalg.cond(mech.velocity_map(q).swapaxes(-1, -2) @ mech.selection())
    hold = mech.inverse(q_home, np.zeros(3), np.zeros(3))[0]
    print(f"{len(q)} of {len(points)} grid points assemble (+-{args.half} m, {args.spacing} m spacing)")
    print(f"cond of the inverse block (type I) {1 / s.inverse_ratio.max():.1f} to {1 / s.inverse_ratio.min():.1f}; "
          f"direct block (type II) {1 / s.direct_ratio.max():.1f} to {1 / s.direct_ratio.min():.1f}; "
          f"C^T U {cond_b.min():.1f} to {cond_b.max():.1f}")
    print(f"holding the home pose: cranks {hold[0]:.3f}, {hold[1]:.3f} N m; rail {hold[2]:.3f} N")


if __name__ == "__main__":
    main()
