"""Benchmark the parallel-mechanism code against Pinocchio's constrained dynamics, in one run.

Writes ``bench_parallel.json`` and ``bench_parallel.png`` (default ``runs/bench-parallel-<time>``)
with versions and settings. For the 5R (circle of sec 5.6) and the 2RSU+PPaP (its reference
path), side by side in one process:

- inverse dynamics along the path, points per second: point by point (Newton from the previous
  pose, then eqs 130-140) and batched (``ParallelMechanism.inverse_trajectory``: the path
  assembled in blocks, eqs 130-140 for all points at once);
- one forward-dynamics evaluation (eq 129) by Orsino's model and by Pinocchio's
  ``constraintDynamics`` on the same mechanism loaded from its closure file.

The thesis's C++ code did more than 10 000 inverse-dynamics points per second on a 6-DOF chain;
the issue asks for 50 000. Quote the ratios measured here.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin
from bench_common import parser, per_call, write_json

from freefloat.parallel import rsu_ppap
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess
from freefloat.parallel.sliding_mode import circle_reference
from freefloat.paths import URDF_DIR


def five_bar_case(points: int):
    """The 5R from its closure file, the sec 5.6 circle (0.22 s) and the first pose's guess."""
    cc = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    path = [np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, 0.22, points)))]
    return cc, path, elbow_guess(FiveBarParameters(), path[0][0])


def rsu_ppap_case(points: int):
    """The 2RSU+PPaP, its reference path (1 s) and the first pose's guess."""
    data = rsu_ppap.load_data()
    path = rsu_ppap.reference_path(np.linspace(0.0, 1.0, points), data)
    return rsu_ppap.load_rsu_ppap(), path, rsu_ppap.assembly_guess(data, path[0][0])


def inverse_rates(cc, path, guess) -> dict:
    """Inverse-dynamics points per second, point by point and batched, and their largest difference."""
    mech, (x, xd, xdd) = cc.mechanism, path
    start = time.perf_counter()
    q, looped = np.concatenate((x[0], guess)), []
    for i in range(len(x)):
        q = mech.assemble(x[i], q[mech.p:])
        looped.append(mech.inverse(q, xd[i], xdd[i])[0])
    loop_s = time.perf_counter() - start
    start = time.perf_counter()
    batched, _ = mech.inverse_trajectory(x, xd, xdd, guess)
    batch_s = time.perf_counter() - start
    return {"points": len(x), "loop_points_per_s": len(x) / loop_s, "batched_points_per_s": len(x) / batch_s,
            "speedup": loop_s / batch_s, "max_effort_difference": float(np.abs(np.array(looped) - batched).max())}


def forward_costs(cc, path, guess, calls: int) -> dict:
    """Seconds per forward-dynamics call at the path's first pose: Orsino vs Pinocchio."""
    mech, model = cc.mechanism, cc.model
    q = mech.assemble(path[0][0], guess)
    qd, tau = mech.velocity_map(q) @ path[1][0], np.full(len(mech.actuated), 0.01)
    data, cds = model.createData(), [c.createData() for c in cc.constraints]
    pin.initConstraintDynamics(model, data, cc.constraints, cds)
    settings = pin.ProximalSettings(1e-12, 1e-12, 20)
    q_pin, v_pin = cc.pinocchio_q(q), cc.pinocchio_q(qd)
    tau_pin = np.zeros(model.nv)
    for j, t in zip(cc.actuated, tau):
        tau_pin[model.idx_vs[j]] = t
    orsino = per_call(lambda: mech.forward(q, qd, tau, 100.0), calls, repeats=3)
    pinocchio = per_call(lambda: pin.constraintDynamics(model, data, q_pin, v_pin, tau_pin, cc.constraints, cds, settings),
                         calls, repeats=3)
    return {"orsino_s": orsino, "pinocchio_s": pinocchio, "ratio": orsino / pinocchio}


def main() -> None:
    cli = parser(__doc__, "parallel")
    cli.add_argument("--points", type=int, default=2000, help="points on each path (default 2000)")
    cli.add_argument("--calls", type=int, default=300, help="forward calls per timing (default 300)")
    args = cli.parse_args()
    report = {"targets": {"thesis_cpp_points_per_s": 10000, "issue_points_per_s": 50000},
              "settings": {"points": args.points, "calls": args.calls}}
    for name, case in (("five_bar", five_bar_case), ("rsu_ppap", rsu_ppap_case)):
        cc, path, guess = case(args.points)
        report[name] = {"inverse": inverse_rates(cc, path, guess), "forward": forward_costs(cc, path, guess, args.calls)}
    write_json(args.out, "parallel", report)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    names = ["five_bar", "rsu_ppap"]
    for offset, key, label in ((-0.2, "loop_points_per_s", "point by point"), (0.2, "batched_points_per_s", "batched")):
        a1.bar(np.arange(2) + offset, [report[n]["inverse"][key] for n in names], width=0.4, label=label)
    a1.axhline(1e4, color="grey", ls="--", label="thesis C++")
    a1.axhline(5e4, color="k", ls=":", label="issue aim")
    a1.set_xticks(range(2), ["5R", "2RSU+PPaP"])
    a1.set_yscale("log")
    a1.set_ylabel("inverse-dynamics points per second")
    a1.legend()
    for offset, key, label in ((-0.2, "orsino_s", "Orsino (numpy)"), (0.2, "pinocchio_s", "Pinocchio constraintDynamics")):
        a2.bar(np.arange(2) + offset, [report[n]["forward"][key] * 1e6 for n in names], width=0.4, label=label)
    a2.set_xticks(range(2), ["5R", "2RSU+PPaP"])
    a2.set_yscale("log")
    a2.set_ylabel("forward dynamics, us per call")
    a2.legend()
    fig.tight_layout()
    fig.savefig(args.out / "bench_parallel.png", dpi=120)
    plt.close(fig)
    for n in names:
        i, f = report[n]["inverse"], report[n]["forward"]
        print(f"{n}: inverse dynamics {i['loop_points_per_s']:.0f} points/s point by point, {i['batched_points_per_s']:.0f} "
              f"batched ({i['speedup']:.1f}x); forward: Orsino {f['orsino_s'] * 1e6:.0f} us, Pinocchio "
              f"{f['pinocchio_s'] * 1e6:.1f} us (ratio {f['ratio']:.0f})")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
