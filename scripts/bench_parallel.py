"""Benchmark the parallel-mechanism code against Pinocchio's constrained dynamics, in one run.

Writes ``bench_parallel.json`` and ``bench_parallel.png`` (default ``runs/bench-parallel-<time>``)
with versions and settings. For the 5R (circle of sec 5.6) and the 2RSU+PPaP (its reference
path), side by side in one process, with the compiled core (default) and the numpy reference
(``ParallelMechanism.reference()``, what the code did before the core):

- one forward-dynamics evaluation (eq 129) by Orsino's model and by Pinocchio's
  ``constraintDynamics`` on the same mechanism loaded from its closure file (the floor);
- inverse dynamics along the path, points per second: point by point from Python (Newton from the
  previous pose, then eqs 130-140) and ``inverse_trajectory`` (compiled: the same continuation in
  C++, the per-point floor; numpy: the path assembled in blocks, eqs 130-140 for all points at once);
  compiled: best of 7 runs, the two taking turns; numpy: one run;
- coarse paths: eq 189's circle wound 1, 2, 4, 8 times in 4000 points, ``inverse_trajectory``'s
  rate and, for the numpy blocks, how many points Newton assembled per point asked.

Quote the ratios measured here.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from bench_common import parser, per_call, save_chart, side_by_side, write_json
from threadpoolctl import threadpool_limits

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


def inverse_rates(mech, path, guess, repeats: int) -> dict:
    """Inverse-dynamics points per second, point by point from Python and by inverse_trajectory
    (best of ``repeats``, the two taking turns)."""
    x, xd, xdd = path

    def loop():
        q, out = np.concatenate((x[0], guess)), []
        for i in range(len(x)):
            q = mech.assemble(x[i], q[mech.p:])
            out.append(mech.inverse(q, xd[i], xdd[i])[0])
        return np.array(out)

    looped, batched = loop(), mech.inverse_trajectory(x, xd, xdd, guess)[0]
    best = side_by_side({"loop": (loop, 1), "trajectory": (lambda: mech.inverse_trajectory(x, xd, xdd, guess), 1)}, repeats)
    return {"points": len(x), "loop_points_per_s": len(x) / best["loop"],
            "trajectory_points_per_s": len(x) / best["trajectory"],
            "max_effort_difference": float(np.abs(looped - batched).max())}


def forward_costs(cc, path, guess, calls: int) -> dict:
    """Seconds per forward-dynamics call at the path's first pose: Orsino (compiled, numpy) vs Pinocchio."""
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
    reference = mech.reference()
    out = side_by_side({
        "compiled_s": (lambda: mech.forward(q, qd, tau, 100.0), calls),
        "pinocchio_s": (lambda: pin.constraintDynamics(model, data, q_pin, v_pin, tau_pin, cc.constraints, cds, settings), calls)})
    out["numpy_s"] = per_call(lambda: reference.forward(q, qd, tau, 100.0), max(1, calls // 10), repeats=3)
    out["compiled_over_pinocchio"] = out["compiled_s"] / out["pinocchio_s"]
    out["numpy_over_pinocchio"] = out["numpy_s"] / out["pinocchio_s"]
    return out


def coarse_paths(points: int = 4000) -> list[dict]:
    """inverse_trajectory on eq 189's circle wound 1, 2, 4, 8 times in ``points`` points."""
    from freefloat.parallel.mechanism import ParallelMechanism

    cc = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    rows, assemble = [], ParallelMechanism.assemble
    for turns in (1, 2, 4, 8):
        x, xd, xdd = (np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, turns * 2 * np.pi / 28.57, points))))
        guess = elbow_guess(FiveBarParameters(), x[0])
        row = {"turns": turns, "points": points}
        for name, mech in (("compiled", cc.mechanism), ("numpy", cc.mechanism.reference())):
            assembled = [0]

            def counting(self, q_sharp, g, *args, **kwargs):
                assembled[0] += len(np.atleast_2d(q_sharp))
                return assemble(self, q_sharp, g, *args, **kwargs)

            ParallelMechanism.assemble = counting
            try:
                seconds = side_by_side({name: (lambda: mech.inverse_trajectory(x, xd, xdd, guess), 1)},
                                       5 if name == "compiled" else 1)[name]
                row[f"{name}_points_per_s"] = points / seconds
            finally:
                ParallelMechanism.assemble = assemble
            if name == "numpy":  # one run
                row["numpy_assembled_per_point"] = assembled[0] / points
        rows.append(row)
    return rows


def main() -> None:
    cli = parser(__doc__, "parallel")
    cli.add_argument("--points", type=int, default=2000, help="points on each path (default 2000)")
    cli.add_argument("--calls", type=int, default=300, help="forward calls per timing (default 300)")
    args = cli.parse_args()
    report = {"targets": {"forward_over_constraintDynamics": 3, "five_bar_points_per_s": 200000,
                          "rsu_ppap_points_per_s": 50000},
              "settings": {"points": args.points, "calls": args.calls}}
    names = ["five_bar", "rsu_ppap"]
    with threadpool_limits(limits=1, user_api="blas"):
        for name, case in zip(names, (five_bar_case, rsu_ppap_case)):
            cc, path, guess = case(args.points)
            report[name] = {"forward": forward_costs(cc, path, guess, args.calls),
                            "inverse_compiled": inverse_rates(cc.mechanism, path, guess, 7),
                            "inverse_numpy": inverse_rates(cc.mechanism.reference(), path, guess, 1)}
            inv = report[name]["inverse_compiled"]
            inv["loop_over_trajectory"] = inv["trajectory_points_per_s"] / inv["loop_points_per_s"]
        report["coarse_paths"] = coarse_paths()
    write_json(args.out, "parallel", report)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(15, 4))
    bars = (("inverse_numpy", "loop_points_per_s", "numpy, point by point"), ("inverse_numpy", "trajectory_points_per_s", "numpy, blocks"),
            ("inverse_compiled", "loop_points_per_s", "compiled, point by point"),
            ("inverse_compiled", "trajectory_points_per_s", "compiled, inverse_trajectory"))
    for i, (row, key, label) in enumerate(bars):
        a1.bar(np.arange(2) + 0.2 * i - 0.3, [report[n][row][key] for n in names], width=0.2, label=label)
    a1.axhline(5e4, color="k", ls=":", label="aim 2RSU+PPaP")
    a1.axhline(2e5, color="grey", ls="--", label="aim 5R")
    a1.set_xticks(range(2), ["5R", "2RSU+PPaP"])
    a1.set_yscale("log")
    a1.set_ylabel("inverse-dynamics points per second")
    a1.legend(fontsize=7)
    for i, (key, label) in enumerate((("numpy_s", "Orsino (numpy)"), ("compiled_s", "Orsino (compiled)"),
                                      ("pinocchio_s", "Pinocchio constraintDynamics"))):
        a2.bar(np.arange(2) + 0.25 * i - 0.25, [report[n]["forward"][key] * 1e6 for n in names], width=0.25, label=label)
    a2.set_xticks(range(2), ["5R", "2RSU+PPaP"])
    a2.set_yscale("log")
    a2.set_ylabel("forward dynamics, us per call")
    a2.legend(fontsize=7)
    turns = [r["turns"] for r in report["coarse_paths"]]
    for key in ("compiled_points_per_s", "numpy_points_per_s"):
        a3.plot(turns, [r[key] for r in report["coarse_paths"]], "o-", label=key.replace("_points_per_s", ""))
    a3.set_xscale("log", base=2)
    a3.set_yscale("log")
    a3.set_xlabel("turns of eq 189's circle in 4000 points")
    a3.set_ylabel("inverse_trajectory points per second (5R)")
    a3.legend(fontsize=7)
    save_chart(fig, args.out / "bench_parallel.png")
    for n in names:
        f, c, r = report[n]["forward"], report[n]["inverse_compiled"], report[n]["inverse_numpy"]
        print(f"{n}: forward compiled {f['compiled_s'] * 1e6:.1f} us, numpy {f['numpy_s'] * 1e6:.0f} us, Pinocchio "
              f"{f['pinocchio_s'] * 1e6:.1f} us (ratios {f['compiled_over_pinocchio']:.2f} / {f['numpy_over_pinocchio']:.0f}); "
              f"inverse points/s compiled {c['loop_points_per_s']:.0f} point by point, {c['trajectory_points_per_s']:.0f} "
              f"trajectory; numpy {r['loop_points_per_s']:.0f} / {r['trajectory_points_per_s']:.0f}")
    for row in report["coarse_paths"]:
        print(f"coarse 5R, {row['turns']} turns: compiled {row['compiled_points_per_s']:.0f} points/s, numpy blocks "
              f"{row['numpy_points_per_s']:.0f} ({row['numpy_assembled_per_point']:.2f} assembled per point)")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
