"""Benchmark: every dynamics model of freefloat.models against Pinocchio's ABA, in one run.

Writes ``bench_models.json`` and ``bench_models.png`` (default ``runs/bench-models-<time>``) with
versions and settings. For the four-arm planar robot, the UR5 dual-arm satellite and 2, 4, 8, 16
spatial 4-link arms (``bench_common.multi_arm_robot``), free-flyer base, zero gravity, one random
state and random joint torques: the time of one ``acceleration(q, v, tau)`` of each model with the
compiled core (the default) and with ``backend="numpy"`` (the reference, and what every model cost
before the core), each as a ratio to ``pin.aba`` measured side by side in this process (best of 7 repeats in which
``pin.aba`` and the compiled models take turns; the numpy rows best of 3; one BLAS thread).

Usage: ``python3 scripts/bench_models.py [--out DIR] [--calls N]``. Quote the ratios.
"""

from __future__ import annotations

import functools
import tempfile
import warnings
from pathlib import Path

import numpy as np
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

from freefloat import load_robot
from freefloat.dynamics.models import MODELS, make_model
from freefloat.dynamics.verify import random_configuration
from freefloat.paths import URDF_DIR
from freefloat.robot.joints import JointCoordinates

GJM_MODELS = [name for name in MODELS if name != "exact"]


def bench_robot(name: str, robot, calls: int, numpy_models: list[str]) -> dict:
    robot.model.gravity.linear[:] = 0.0
    rng = np.random.default_rng(0)
    q = random_configuration(robot, rng, JointCoordinates(robot), joint_range=1.0)
    v = rng.normal(size=robot.model.nv)
    tau = np.concatenate((np.zeros(robot.n_base), rng.normal(size=robot.n_joints)))
    models = {name: make_model(name, robot) for name in ("exact", *GJM_MODELS)}
    compiled = side_by_side({name: (functools.partial(m.acceleration, q, v, tau), calls) for name, m in models.items()})
    floor, numpy = compiled.pop("exact"), {}
    for model_name in GJM_MODELS:
        if model_name in numpy_models:
            reference = make_model(model_name, robot, backend="numpy")
            numpy[model_name] = per_call(lambda: reference.acceleration(q, v, tau), max(1, calls // 100), repeats=3)
    return {
        "robot": name, "n_joints": robot.n_joints, "aba_s": floor, "compiled_s": compiled, "numpy_s": numpy,
        "compiled_over_aba": {k: t / floor for k, t in compiled.items()},
        "numpy_over_aba": {k: t / floor for k, t in numpy.items()},
    }


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 4.5))
    first = rows[0]
    x = np.arange(len(GJM_MODELS))
    left.bar(x - 0.2, [first["compiled_over_aba"][m] for m in GJM_MODELS], 0.4, label="compiled")
    left.bar(x + 0.2, [first["numpy_over_aba"].get(m, np.nan) for m in GJM_MODELS], 0.4, label="numpy (before)")
    left.axhline(5, color="k", ls=":", label="aim: 5x aba")
    left.set_xticks(x, GJM_MODELS, rotation=45, ha="right", fontsize=8)
    left.set_yscale("log")
    left.set_ylabel("time per acceleration / pin.aba")
    left.set_title(f"{first['robot']} (n = {first['n_joints']})")
    left.legend(fontsize=8)
    growth = [r for r in rows if r["robot"].startswith("arms")]
    joints = [r["n_joints"] for r in growth]
    for model_name in ("standard", "standard_corrected", "nidc", "momentum_routh"):
        right.plot(joints, [r["compiled_over_aba"][model_name] for r in growth], "o-", label=model_name)
    growth_axes(right, "compiled time / pin.aba")
    save_chart(fig, path)


def main() -> None:
    cli = parser(__doc__, "models")
    cli.add_argument("--calls", type=int, default=500)
    args = cli.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as folder, threadpool_limits(limits=1, user_api="blas"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            named = [(n, load_robot(URDF_DIR / n, visuals=False)) for n in ("four_arm_planar.urdf", "dual_arm_satellite.urdf")]
        for name, robot in named:
            rows.append(bench_robot(name, robot, args.calls, GJM_MODELS))
        for arms in ARM_COUNTS:  # the numpy reference only where it takes seconds, not minutes
            rows.append(bench_robot(f"arms{arms}", multi_arm_robot(arms, Path(folder)), args.calls,
                                    ["standard", "momentum_routh"] if arms <= 8 else []))
    write_json(args.out, "models", {"robots": rows, "settings": {"calls": args.calls, "repeats": 7, "blas_threads": 1}})
    chart(rows, args.out / "bench_models.png")
    for row in rows:
        ratios = row["compiled_over_aba"]
        worst = max(ratios, key=ratios.get)
        numpy = row["numpy_over_aba"]
        before = f", numpy {min(numpy.values()):.0f}-{max(numpy.values()):.0f}x" if numpy else ""
        print(f"{row['robot']} (n = {row['n_joints']}): aba {row['aba_s'] * 1e6:.1f} us; compiled "
              f"{min(ratios.values()):.1f}-{ratios[worst]:.1f}x aba (worst {worst}){before}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
