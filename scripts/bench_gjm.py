"""Benchmark: the GJM quantities, compiled and numpy, against the Pinocchio floor, in one run.

Writes ``bench_gjm.json`` and ``bench_gjm.png`` to an output folder (default ``runs/bench-gjm-<time>``)
with versions and settings. Robots: the four-arm planar robot, the UR5 dual-arm satellite, and
2, 4, 8, 16 spatial 4-link arms (``bench_common.multi_arm_robot``), all with a free-flyer base.
Every time is per call, best of 7 repeats in which the compiled rows and their floors take turns
(the numpy rows: best of 5 or 3), in this process; every figure is also given as a ratio to its
Pinocchio floor:

- ``compiled``: :func:`freefloat.gjm.compute` (H0, H0m, Hm, H*, J0, Jm, J0E, J*, momenta, body
  kinematics), the compiled core; ``numpy``: the same with ``backend="numpy"`` (the reference, and
  what ``gjm.compute`` was before the core); ``numpy_blas_default``: numpy with the default BLAS
  threads (every other row runs with one BLAS thread).
- ``pinocchio_calls`` (the floor of ``compute``): CRBA + centroidal momentum + joint Jacobians +
  frame placements + one frame Jacobian per end-effector, no post-processing;
  ``pinocchio_same_outputs``: :func:`freefloat.dynamics.reference.reference`, the same quantities
  from those calls mapped to the GJM convention in numpy.
- ``compiled_derivatives`` / ``numpy_derivatives``: :func:`freefloat.gjm.derivatives` (every
  dH/dq_k and the time derivatives); their floor is one ``crba``.

Usage: ``python3 scripts/bench_gjm.py [--out DIR] [--calls N]``. Quote the ratios.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
from bench_common import (
    ARM_COUNTS,
    growth_axes,
    multi_arm_robot,
    parser,
    per_call,
    save_chart,
    side_by_side,
    write_json,
)
from threadpoolctl import threadpool_limits

from freefloat import gjm, load_robot
from freefloat.dynamics.reference import reference
from freefloat.dynamics.verify import random_configuration
from freefloat.paths import URDF_DIR
from freefloat.robot.joints import JointCoordinates

ROWS = ("compiled", "numpy", "numpy_blas_default", "pinocchio_calls", "pinocchio_same_outputs",
        "compiled_derivatives", "numpy_derivatives", "crba")


def bench_robot(name: str, robot, calls: int) -> dict:
    rng = np.random.default_rng(0)
    q = random_configuration(robot, rng, JointCoordinates(robot), joint_range=1.0)
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

    slow = max(1, calls // 10)
    gjm.compute(robot, q, v)  # build and cache the structure outside the timing
    times = {"numpy_blas_default": per_call(lambda: gjm.compute(robot, q, v, "numpy"), slow)}
    with threadpool_limits(limits=1, user_api="blas"):
        times["numpy"] = per_call(lambda: gjm.compute(robot, q, v, "numpy"), slow)
        times["numpy_derivatives"] = per_call(lambda: gjm.derivatives(robot, q, v, "numpy"), max(1, calls // 50), repeats=3)
        times.update(side_by_side({
            "compiled": (lambda: gjm.compute(robot, q, v), calls),
            "pinocchio_calls": (pinocchio_calls, calls),
            "pinocchio_same_outputs": (lambda: reference(robot, q, v, data), calls),
            "compiled_derivatives": (lambda: gjm.derivatives(robot, q, v), calls),
            "crba": (lambda: pin.crba(model, data, q), calls),
        }))
    floor, crba = times["pinocchio_calls"], times["crba"]
    return {
        "robot": name, "n_joints": robot.n_joints, "end_effectors": len(ee), "seconds_per_call": times,
        "ratios": {
            "compiled_over_pinocchio_calls": times["compiled"] / floor,
            "numpy_over_pinocchio_calls": times["numpy"] / floor,
            "pinocchio_same_outputs_over_pinocchio_calls": times["pinocchio_same_outputs"] / floor,
            "numpy_blas_default_over_one_thread": times["numpy_blas_default"] / times["numpy"],
            "compiled_derivatives_over_crba": times["compiled_derivatives"] / crba,
            "numpy_derivatives_over_crba": times["numpy_derivatives"] / crba,
        },
    }


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    growth = [r for r in rows if r["robot"].startswith("arms")]
    joints = [r["n_joints"] for r in growth]
    for key, style in (("compiled", "o-"), ("numpy", "s--"), ("pinocchio_calls", "k^-"), ("compiled_derivatives", "o-"),
                       ("numpy_derivatives", "s--"), ("crba", "kv:")):
        left.plot(joints, [r["seconds_per_call"][key] * 1e6 for r in growth], style, label=key)
    left.set_yscale("log")
    growth_axes(left, "time per call [us]")
    for i, key in enumerate(("compiled_over_pinocchio_calls", "numpy_over_pinocchio_calls", "compiled_derivatives_over_crba",
                             "numpy_derivatives_over_crba")):
        right.bar(np.arange(len(rows)) + 0.2 * i, [r["ratios"][key] for r in rows], 0.2, label=key)
    right.set_xticks(np.arange(len(rows)) + 0.3, [f"{r['robot']}\nn={r['n_joints']}" for r in rows], fontsize=7)
    right.set_yscale("log")
    right.set_ylabel("ratio to the Pinocchio floor")
    right.legend(fontsize=8)
    save_chart(fig, path)


def robots(folder: Path):
    """(name, robot) of every benchmarked robot."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in ("four_arm_planar.urdf", "dual_arm_satellite.urdf"):
            yield name, load_robot(URDF_DIR / name, visuals=False)
    for arms in ARM_COUNTS:
        yield f"arms{arms}", multi_arm_robot(arms, folder)


def main() -> None:
    cli = parser(__doc__, "gjm")
    cli.add_argument("--calls", type=int, default=500)
    args = cli.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        rows = [bench_robot(name, robot, args.calls) for name, robot in robots(Path(folder))]
    write_json(args.out, "gjm", {"robots": rows, "settings": {"calls": args.calls, "repeats": 7}})
    chart(rows, args.out / "bench_gjm.png")
    for row in rows:
        t, r = row["seconds_per_call"], row["ratios"]
        print(f"{row['robot']} (n = {row['n_joints']}): compute compiled {t['compiled'] * 1e6:.1f} us, numpy "
              f"{t['numpy'] * 1e6:.0f} us, Pinocchio calls {t['pinocchio_calls'] * 1e6:.1f} us (ratios "
              f"{r['compiled_over_pinocchio_calls']:.2f} / {r['numpy_over_pinocchio_calls']:.0f}); derivatives compiled "
              f"{t['compiled_derivatives'] * 1e6:.1f} us, numpy {t['numpy_derivatives'] * 1e6:.0f} us, crba "
              f"{t['crba'] * 1e6:.1f} us (ratios {r['compiled_derivatives_over_crba']:.1f} / "
              f"{r['numpy_derivatives_over_crba']:.0f}); numpy with default BLAS threads "
              f"{r['numpy_blas_default_over_one_thread']:.1f}x one thread")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
