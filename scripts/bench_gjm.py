"""Benchmark: hand-built GJM quantities vs the Pinocchio path, per call, in one run.

Writes ``bench_gjm.json`` and ``bench_gjm.png`` to an output folder (default ``runs/bench-gjm-<time>``)
with versions and settings. Robots: the four-arm planar robot and the UR5 dual-arm satellite,
both with a free-flyer base. Rows:

- ``hand_built``: :func:`freefloat.gjm.compute` (H0, H0m, Hm, H*, J0, Jm, J0E, J*, momenta).
- ``pinocchio_calls``: CRBA + centroidal momentum + joint Jacobians + one frame Jacobian per
  end-effector, no post-processing (the floor).
- ``pinocchio_same_outputs``: :func:`freefloat.dynamics.reference.reference`, the same quantities from
  Pinocchio mapped to the GJM convention.
- ``hand_built_derivatives``: :func:`freefloat.gjm.derivatives` (all dH/dq_k and time derivatives);
  ``pinocchio_fd_derivatives``: central differences of the reference (2 n reference calls).

Usage: ``python3 scripts/bench_gjm.py [--out DIR] [--calls N]``. Quote the ratios.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
from bench_common import parser, per_call, write_json

from freefloat import gjm, load_robot
from freefloat.dynamics.reference import reference
from freefloat.dynamics.verify import random_configuration
from freefloat.paths import URDF_DIR
from freefloat.robot.joints import JointCoordinates


def bench_robot(path: Path, calls: int) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(path, visuals=False)
    rng = np.random.default_rng(0)
    coords = JointCoordinates(robot)
    q = random_configuration(robot, rng, coords, joint_range=1.0)
    v = rng.normal(size=robot.model.nv)
    model, data = robot.model, robot.model.createData()
    ee = robot.end_effector_frame_ids

    def pinocchio_calls():
        pin.crba(model, data, q)
        pin.computeCentroidalMomentum(model, data, q, v)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for fid in ee:
            pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)

    def fd_derivatives():
        theta = coords.get(q)
        for k in range(robot.n_joints):
            for sign in (1.0, -1.0):
                qk = q.copy()
                coords.set(qk, theta + sign * 1e-6 * np.eye(robot.n_joints)[k])
                reference(robot, qk, v, data)

    gjm.compute(robot, q, v)  # build and cache the structure outside the timing
    times = {
        "hand_built": per_call(lambda: gjm.compute(robot, q, v), calls),
        "pinocchio_calls": per_call(pinocchio_calls, calls),
        "pinocchio_same_outputs": per_call(lambda: reference(robot, q, v, data), calls),
        "hand_built_derivatives": per_call(lambda: gjm.derivatives(robot, q, v), max(1, calls // 10)),
        "pinocchio_fd_derivatives": per_call(fd_derivatives, max(1, calls // 100)),
    }
    return {
        "robot": path.name, "n_joints": robot.n_joints, "end_effectors": len(ee),
        "seconds_per_call": times,
        "ratio_hand_built_over_pinocchio_calls": times["hand_built"] / times["pinocchio_calls"],
        "ratio_hand_built_over_pinocchio_same_outputs": times["hand_built"] / times["pinocchio_same_outputs"],
        "ratio_fd_over_analytic_derivatives": times["pinocchio_fd_derivatives"] / times["hand_built_derivatives"],
    }


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = ["hand_built", "pinocchio_calls", "pinocchio_same_outputs", "hand_built_derivatives", "pinocchio_fd_derivatives"]
    fig, ax = plt.subplots(figsize=(10, 4.5))
    width = 0.8 / len(rows)
    for i, row in enumerate(rows):
        values = [row["seconds_per_call"][k] * 1e6 for k in labels]
        ax.bar(np.arange(len(labels)) + i * width, values, width, label=f"{row['robot']} (n = {row['n_joints']})")
    ax.set_xticks(np.arange(len(labels)) + width * (len(rows) - 1) / 2, [l.replace("_", "\n") for l in labels])
    ax.set_yscale("log")
    ax.set_ylabel("time per call [us]")
    ax.set_title("GJM quantities: hand-built vs Pinocchio")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    cli = parser(__doc__, "gjm")
    cli.add_argument("--calls", type=int, default=500)
    args = cli.parse_args()
    rows = [bench_robot(URDF_DIR / name, args.calls) for name in ("four_arm_planar.urdf", "dual_arm_satellite.urdf")]
    write_json(args.out, "gjm", {"robots": rows, "settings": {"calls": args.calls, "repeats": 5}})
    chart(rows, args.out / "bench_gjm.png")
    for row in rows:
        t = row["seconds_per_call"]
        print(f"{row['robot']}: hand-built {t['hand_built'] * 1e6:.0f} us, Pinocchio calls {t['pinocchio_calls'] * 1e6:.1f} us "
              f"(ratio {row['ratio_hand_built_over_pinocchio_calls']:.1f}), same outputs {t['pinocchio_same_outputs'] * 1e6:.0f} us "
              f"(ratio {row['ratio_hand_built_over_pinocchio_same_outputs']:.2f}); derivatives analytic "
              f"{t['hand_built_derivatives'] * 1e6:.0f} us vs FD {t['pinocchio_fd_derivatives'] * 1e6:.0f} us")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
