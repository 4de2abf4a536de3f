"""The 2RSU+PPaP's conditioning and holding efforts on a grid about its home pose.

Usage: ``python3 scripts/rsu_ppap_workspace.py [--half 0.05] [--spacing 0.01]``. Prints, for the
assumed geometry (``urdf/rsu_ppap.data.toml``), the range of cond(A°) and cond(C^T U) over the
grid points that assemble, and the efforts that hold the home pose at rest against gravity.
docs/parallel.md quotes its output.
"""

from __future__ import annotations

import argparse

import numpy as np

from freefloat import FreefloatError
from freefloat.parallel.rsu_ppap import assembly_guess, load_data, load_rsu_ppap


def main() -> None:
    cli = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    cli.add_argument("--half", type=float, default=0.05, help="half-width of the cubic grid, m (default 0.05)")
    cli.add_argument("--spacing", type=float, default=0.01, help="grid spacing, m (default 0.01)")
    args = cli.parse_args()
    data, mech = load_data(), load_rsu_ppap().mechanism
    home = np.array(data["home"])
    axis = np.arange(-args.half, args.half + 1e-12, args.spacing)
    points = home + np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    poses = []
    for x in points:
        try:
            poses.append(mech.assemble(x, assembly_guess(data, x)))
        except FreefloatError:
            continue
    q = np.array(poses)
    A = mech.terms(q, np.zeros_like(q))[0]
    C = mech.velocity_map(q)
    cond_a = np.linalg.cond(A[:, :, mech.p:])
    cond_b = np.linalg.cond(C.swapaxes(-1, -2) @ mech.selection())
    hold = mech.inverse(mech.assemble(home, assembly_guess(data, home)), np.zeros(3), np.zeros(3))[0]
    print(f"{len(q)} of {len(points)} grid points assemble (+-{args.half} m, {args.spacing} m spacing)")
    print(f"cond(A°) {cond_a.min():.1f} to {cond_a.max():.1f}; cond(C^T U) {cond_b.min():.1f} to {cond_b.max():.1f}")
    print(f"holding the home pose: cranks {hold[0]:.3f}, {hold[1]:.3f} N m; rail {hold[2]:.3f} N")


if __name__ == "__main__":
    main()
