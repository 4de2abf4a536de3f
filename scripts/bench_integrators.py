"""Benchmark the Lie-group integrators: measured orders, cost per step, momentum projection.

Writes ``bench_integrators.json`` and ``bench_integrators.png`` to an output folder (default
``runs/bench-integrators-<time>``). Everything compared is measured side by side in one run: quote
the ratios, not the absolute times (shared 2-core machines are noisy).

On two torque-free tumbling robots (four-arm and dual-arm satellite, free base, seeded states):

1. Work-precision over 1 s: rkmk4, rkmk6 and rkmk8 (5 to 320 steps) at halving steps (observed order
   ``log2(e(h) / e(h/2))``), dopri5 over tolerances; final-state error against dopri5 at rtol 1e-13.
2. Cost per step: evaluations and wall time of one step of euler, rkmk4, rkmk6, rkmk8 (h = 1 ms) and of
   one accepted dopri5 step (rtol 1e-9), taking turns in one process, as ratios to rkmk4; at equal
   accuracy (1e-5 ... 1e-11), each method's time as its evaluations times its time per evaluation.
3. Long run: 20 s with euler (1 ms) and rkmk4 (5 ms), with and without momentum projection:
   the conserved momentum's and the kinetic energy's largest change from the start.

Usage: ``python3 scripts/bench_integrators.py [--out DIR] [--quick]``
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pinocchio as pin
from bench_common import parser, side_by_side, write_json

from freefloat import load_robot
from freefloat.dynamics.integrators import DormandPrince45, make_integrator
from freefloat.dynamics.models import ExactModel
from freefloat.paths import URDF_DIR
from freefloat.robot.conventions import momentum_about_origin

ROBOTS = {"four-arm": "four_arm_planar.urdf", "dual-arm": "dual_arm_satellite.urdf"}


def tumbling(urdf: str):
    """Torque-free robot on a free base, tumbling from a seeded state: robot, f, q0, v0."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(URDF_DIR / urdf, visuals=False)
    model, tau = ExactModel(robot), np.zeros(robot.model.nv)
    rng = np.random.default_rng(7)
    q0 = robot.neutral()
    q0[7:] = rng.uniform(-0.5, 0.5, robot.n_joints)
    v0 = rng.uniform(-0.3, 0.3, robot.model.nv)
    v0[3:6] = [0.4, -0.3, 1.0]
    return robot, lambda q, v: model.acceleration(q, v, tau), q0, v0


def state_error(model: pin.Model, q, v, q_ref, v_ref) -> float:
    return float(np.linalg.norm(np.concatenate((pin.difference(model, q_ref, q), v - v_ref))))


def work_precision(robot, f, q0, v0, quick: bool) -> dict:
    """Final-state error after 1 s vs steps (fixed-step) and tolerance (dopri5)."""
    q_ref, v_ref = DormandPrince45(robot.model, rtol=1e-13, atol=1e-14).advance(f, q0, v0, 1.0)
    rows = []
    steps = [25, 50, 100, 200] if quick else [25, 50, 100, 200, 400, 800]
    steps8 = [5, 10, 20, 40] if quick else [5, 10, 20, 40, 80, 160, 320]  # rkmk8 reaches the floor sooner
    for name in ("rkmk4", "rkmk6", "rkmk8"):
        for n in steps8 if name == "rkmk8" else steps:
            integrator = make_integrator(name, robot.model, substeps=n)
            start = time.perf_counter()
            q, v = integrator.advance(f, q0, v0, 1.0)
            rows.append({"integrator": name, "steps": n, "error": state_error(robot.model, q, v, q_ref, v_ref),
                         "evaluations": integrator.evaluations(), "wall_s": time.perf_counter() - start})
    for rtol in ([1e-5, 1e-8, 1e-11] if quick else [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]):
        integrator = DormandPrince45(robot.model, rtol=rtol, atol=rtol * 1e-2)
        start = time.perf_counter()
        q, v = integrator.advance(f, q0, v0, 1.0)
        rows.append({"integrator": "dopri5", "rtol": rtol, "steps": integrator.accepted + integrator.rejected,
                     "error": state_error(robot.model, q, v, q_ref, v_ref),
                     "evaluations": integrator.evaluations(), "wall_s": time.perf_counter() - start})
    orders = {}
    for name in ("rkmk4", "rkmk6", "rkmk8"):
        e = [r["error"] for r in rows if r["integrator"] == name]
        orders[name] = np.log2(np.array(e[:-1]) / np.array(e[1:])).tolist()
    return {"rows": rows, "observed_orders": orders}


def cost_per_step(robot, f, q0, v0, repeats: int) -> dict:
    """Evaluations and best wall time per step, side by side; dopri5 per accepted step at rtol 1e-9."""
    fixed = {name: make_integrator(name, robot.model, substeps=10) for name in ("euler", "rkmk4", "rkmk6", "rkmk8")}
    probe = DormandPrince45(robot.model, rtol=1e-9, atol=1e-11)
    probe.advance(f, q0, v0, 1.0)
    dopri_steps = probe.accepted + probe.rejected
    fns = {name: ((lambda i=i: i.advance(f, q0, v0, 0.01)), 20) for name, i in fixed.items()}
    fns["dopri5"] = (lambda: DormandPrince45(robot.model, rtol=1e-9, atol=1e-11).advance(f, q0, v0, 1.0), 1)
    best = side_by_side(fns, repeats)
    per_step = {name: best[name] / 10 for name in fixed} | {"dopri5": best["dopri5"] / probe.accepted}
    evals = {"euler": 1, "rkmk4": 4, "rkmk6": 7, "rkmk8": 11, "dopri5": probe.evaluations() / probe.accepted}
    return {
        "seconds_per_step": per_step,
        "evaluations_per_step": evals,
        "time_ratio_to_rkmk4": {k: t / per_step["rkmk4"] for k, t in per_step.items()},
        "dopri5": {"accepted": probe.accepted, "rejected": probe.rejected, "attempts": dopri_steps},
    }


def equal_accuracy(work: dict, cost: dict, targets=(1e-5, 1e-7, 1e-9, 1e-11, 1e-12)) -> dict:
    """Per target error: each method's cheapest point reaching it, its time as evaluations times the
    side-by-side time per evaluation, and the fastest method's lead over the runner-up."""
    per_eval = {k: cost["seconds_per_step"][k] / cost["evaluations_per_step"][k] for k in ("rkmk4", "rkmk6", "rkmk8", "dopri5")}
    out = {}
    for target in targets:
        times = {}
        for name, seconds in per_eval.items():
            ok = [r["evaluations"] for r in work["rows"] if r["integrator"] == name and r["error"] <= target]
            if ok:
                times[name] = min(ok) * seconds
        ranked = sorted(times, key=times.get)
        out[f"{target:.0e}"] = {"seconds_for_1s": times, "fastest": ranked[0] if ranked else None,
                                "lead": times[ranked[1]] / times[ranked[0]] if len(ranked) > 1 else None}
    return out


def long_run(robot, f, q0, v0, duration: float) -> dict:
    """Largest change of the momentum [P; L] and of the kinetic energy over ``duration``."""
    data = robot.model.createData()
    p0 = momentum_about_origin(robot.model, data, q0, v0)
    e0 = pin.computeKineticEnergy(robot.model, data, q0, v0)
    out = {}
    for name, h in (("euler", 1e-3), ("rkmk4", 5e-3)):
        for projected in (False, True):
            integrator = make_integrator(name, robot.model, project_momentum=projected)
            q, v = q0, v0
            t, dp, de = [], [], []
            start = time.perf_counter()
            for k in range(round(duration / h)):
                q, v = integrator.advance(f, q, v, h)
                t.append((k + 1) * h)
                dp.append(float(np.abs(momentum_about_origin(robot.model, data, q, v) - p0).max()))
                de.append(abs(pin.computeKineticEnergy(robot.model, data, q, v) - e0))
            out[f"{name}{'_projected' if projected else ''}"] = {
                "h": h, "momentum_drift_max": max(dp), "energy_drift_max": max(de), "energy_drift_final": de[-1],
                "wall_s": time.perf_counter() - start, "t": t[::20], "momentum_drift": dp[::20], "energy_drift": de[::20],
            }
    return out


def chart(report: dict, path) -> None:
    """Per robot: work-precision (error vs evaluations), and drift over the long run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(ROBOTS), 3, figsize=(16, 4.5 * len(ROBOTS)))
    for row, label in zip(axes, ROBOTS):
        r = report[label]
        for name in ("rkmk4", "rkmk6", "rkmk8", "dopri5"):
            pts = [p for p in r["work_precision"]["rows"] if p["integrator"] == name]
            row[0].loglog([p["evaluations"] for p in pts], [max(p["error"], 1e-16) for p in pts], "o-", label=name)
        row[0].set(xlabel="acceleration evaluations for 1 s", ylabel="final-state error",
                   title=f"{label}: work-precision (tumbling, free base)")
        for key, series in r["long_run"].items():
            row[1].semilogy(series["t"], np.maximum(series["momentum_drift"], 1e-17), label=f"{key} (h={series['h']})")
            row[2].semilogy(series["t"], np.maximum(series["energy_drift"], 1e-17), label=f"{key} (h={series['h']})")
        row[1].set(xlabel="t [s]", ylabel="max |[P; L] - [P0; L0]|", title=f"{label}: momentum drift")
        row[2].set(xlabel="t [s]", ylabel="|T - T0| [J]", title=f"{label}: kinetic energy drift")
        for ax in row:
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    cli = parser(__doc__, "integrators")
    cli.add_argument("--repeats", type=int, default=7)
    cli.add_argument("--quick", action="store_true", help="fewer points and a 2 s long run (smoke run)")
    args = cli.parse_args()
    report: dict = {"settings": {"repeats": args.repeats, "quick": args.quick}}
    for label, urdf in ROBOTS.items():
        robot, f, q0, v0 = tumbling(urdf)
        wp = work_precision(robot, f, q0, v0, args.quick)
        cost = cost_per_step(robot, f, q0, v0, 3 if args.quick else args.repeats)
        report[label] = {"work_precision": wp, "cost_per_step": cost, "equal_accuracy": equal_accuracy(wp, cost),
                         "long_run": long_run(robot, f, q0, v0, 2.0 if args.quick else 20.0)}
        print(label, "observed orders", {k: [round(x, 2) for x in v] for k, v in wp["observed_orders"].items()})
        print(label, "time per step / rkmk4", {k: round(x, 2) for k, x in cost["time_ratio_to_rkmk4"].items()},
              "evaluations per step", {k: round(x, 2) for k, x in cost["evaluations_per_step"].items()})
        for target, e in report[label]["equal_accuracy"].items():
            lead = f"{e['lead']:.2f}x" if e["lead"] else "alone"
            print(label, f"error <= {target}: fastest {e['fastest']} ({lead} ahead of the next)")
        for key, s in report[label]["long_run"].items():
            print(label, key, f"momentum drift {s['momentum_drift_max']:.2e}, energy drift {s['energy_drift_max']:.2e}")
    write_json(args.out, "integrators", report)
    chart(report, args.out / "bench_integrators.png")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
