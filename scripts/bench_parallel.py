"""Benchmark the parallel-mechanism code against Pinocchio's constrained dynamics, in one run.

Writes ``bench_parallel.json`` and ``bench_parallel.png`` (default ``runs/bench-parallel-<time>``)
with versions and settings. On the 5R (the 2RSU+PPaP is not built yet):

- inverse dynamics along the circle of sec 5.6 (assembly by Newton from the previous point,
  then eqs 130-140): points per second;
- one forward-dynamics evaluation (eq 129) by Orsino's model and by Pinocchio's
  ``constraintDynamics`` on the same mechanism loaded from ``urdf/five_bar.closure.toml``.

The thesis's C++ code did more than 10 000 inverse-dynamics points per second on a 6-DOF chain;
the issue asks for 50 000. Quote the ratios measured here.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from bench_common import parser, per_call, write_json
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.sliding_mode import circle_reference
from freefloat.paths import URDF_DIR


def inverse_dynamics_rate(points: int) -> float:
    """Inverse-dynamics points per second along the circle."""
    p = FiveBarParameters()
    mech = five_bar(p)
    q = mech.assemble(np.array([0.07, 0.17]), elbow_guess(p, np.array([0.07, 0.17])))
    times = np.linspace(0.0, 0.22, points)
    start = time.perf_counter()
    for t in times:
        x, xd, xdd = circle_reference(t)
        q = mech.assemble(x, q[2:])
        mech.inverse(q, xd, xdd)
    return points / (time.perf_counter() - start)


def forward_costs(calls: int) -> dict:
    """Seconds per forward-dynamics call: Orsino vs Pinocchio constraintDynamics."""
    cc = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    mech, model = cc.mechanism, cc.model
    p = FiveBarParameters()
    q = mech.assemble(np.array([0.07, 0.17]), elbow_guess(p, np.array([0.07, 0.17])))
    _, _, C, *_ = mech.terms(q, np.zeros(6))
    qd, tau = C @ np.array([0.3, -0.2]), np.array([0.02, -0.01])
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
    cli.add_argument("--points", type=int, default=500)
    cli.add_argument("--calls", type=int, default=300)
    args = cli.parse_args()
    report = {"inverse_dynamics_points_per_s": inverse_dynamics_rate(args.points), "forward": forward_costs(args.calls),
              "targets": {"thesis_cpp_points_per_s": 10000, "issue_points_per_s": 50000},
              "settings": {"points": args.points, "calls": args.calls}}
    write_json(args.out, "parallel", report)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.bar(["freefloat (numpy)", "thesis C++", "issue aim"], [report["inverse_dynamics_points_per_s"], 1e4, 5e4])
    a1.set_yscale("log")
    a1.set_ylabel("5R inverse-dynamics points per second")
    f = report["forward"]
    a2.bar(["Orsino (numpy)", "Pinocchio constraintDynamics"], [f["orsino_s"] * 1e6, f["pinocchio_s"] * 1e6])
    a2.set_yscale("log")
    a2.set_ylabel("forward dynamics, us per call")
    fig.tight_layout()
    fig.savefig(args.out / "bench_parallel.png", dpi=120)
    plt.close(fig)
    print(f"inverse dynamics: {report['inverse_dynamics_points_per_s']:.0f} points/s; forward: Orsino "
          f"{f['orsino_s'] * 1e6:.0f} us, Pinocchio {f['pinocchio_s'] * 1e6:.1f} us (ratio {f['ratio']:.0f}); wrote {args.out}")


if __name__ == "__main__":
    main()
