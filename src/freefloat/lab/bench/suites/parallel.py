"""``parallel`` suite: the parallel-mechanism code against Pinocchio's constrained dynamics.

For the 5R (the circle of sec 5.6) and the 2RSU+PPaP (its reference path), side by side in one
process, one BLAS thread, with the compiled core (default) and the numpy reference
(``ParallelMechanism.reference()``):

- one forward-dynamics evaluation (eq 129) by Orsino's model and by Pinocchio's
  ``constraintDynamics`` on the same mechanism loaded from its closure file (the floor);
- inverse dynamics along the path, points per second: point by point from Python (Newton from the
  previous pose, then eqs 130-140) and ``inverse_trajectory`` (compiled: the same continuation in
  C++; numpy: the path assembled in blocks, eqs 130-140 for all points at once); compiled: best of
  ``repeats`` runs, the two taking turns; numpy: one run;
- coarse paths: eq 189's circle wound 1, 2, 4, 8 times, ``inverse_trajectory``'s rate and, for
  the numpy blocks, how many points Newton assembled per point asked.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin
from threadpoolctl import threadpool_limits

from ....parallel import rsu_ppap
from ....parallel.closed_chain import load_closed_chain
from ....parallel.five_bar import FiveBarParameters, elbow_guess
from ....parallel.mechanism import ParallelMechanism
from ....parallel.sliding_mode import circle_reference
from ....paths import URDF_DIR
from .drawing import save, subplots
from .timing import per_call, side_by_side

#: The aims the chart marks: forward dynamics within 3x Pinocchio's, inverse dynamics rates.
TARGETS = {"forward_over_constraintDynamics": 3, "five_bar_points_per_s": 200000, "rsu_ppap_points_per_s": 50000}
#: Turns of eq 189's circle on the coarse paths.
TURNS = (1, 2, 4, 8)


def settings(quick: bool, repeats: int | None) -> dict:
    """Points per path, forward calls per timing, points of the coarse paths, repeats (best of;
    default 7, 2 quick)."""
    return {"points": 200 if quick else 2000, "calls": 30 if quick else 300, "coarse_points": 400 if quick else 4000,
            "repeats": repeats or (2 if quick else 7), "targets": TARGETS, "blas_threads": 1}


def measure(settings: dict) -> Iterator[tuple[str, object]]:
    """Parts ``five_bar`` and ``rsu_ppap`` (forward costs, inverse rates compiled and numpy), then
    ``coarse_paths``."""
    with threadpool_limits(limits=1, user_api="blas"):
        for name, case in (("five_bar", five_bar_case), ("rsu_ppap", rsu_ppap_case)):
            cc, path, guess = case(settings["points"])
            compiled = inverse_rates(cc.mechanism, path, guess, settings["repeats"])
            yield name, {"forward": forward_costs(cc, path, guess, settings["calls"], settings["repeats"]),
                         "inverse_compiled": compiled | {
                             "trajectory_over_loop": compiled["trajectory_points_per_s"] / compiled["loop_points_per_s"]},
                         "inverse_numpy": inverse_rates(cc.mechanism.reference(), path, guess, 1)}
        yield "coarse_paths", coarse_paths(settings["coarse_points"], settings["repeats"])


def five_bar_case(points: int):
    """The 5R from its closure file, the sec 5.6 circle (0.22 s) in ``points`` points and the first
    pose's guess."""
    cc = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    path = [np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, 0.22, points)))]
    return cc, path, elbow_guess(FiveBarParameters(), path[0][0])


def rsu_ppap_case(points: int):
    """The 2RSU+PPaP, its reference path (1 s) in ``points`` points and the first pose's guess."""
    data = rsu_ppap.load_data()
    path = rsu_ppap.reference_path(np.linspace(0.0, 1.0, points), data)
    return rsu_ppap.load_rsu_ppap(), path, rsu_ppap.assembly_guess(data, path[0][0])


def inverse_rates(mech, path, guess, repeats: int) -> dict:
    """Inverse-dynamics points per second, point by point from Python and by inverse_trajectory
    (best of ``repeats``, the two taking turns), and the largest difference of their efforts."""
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


def forward_costs(cc, path, guess, calls: int, repeats: int) -> dict:
    """Seconds per forward-dynamics call at the path's first pose: Orsino (compiled, numpy) against
    Pinocchio's ``constraintDynamics``, and the ratios."""
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
        "pinocchio_s": (lambda: pin.constraintDynamics(model, data, q_pin, v_pin, tau_pin, cc.constraints, cds, settings),
                        calls)}, repeats)
    out["numpy_s"] = per_call(lambda: reference.forward(q, qd, tau, 100.0), max(1, calls // 10), 3)
    out["compiled_over_pinocchio"] = out["compiled_s"] / out["pinocchio_s"]
    out["numpy_over_pinocchio"] = out["numpy_s"] / out["pinocchio_s"]
    return out


def coarse_paths(points: int, repeats: int) -> list[dict]:
    """inverse_trajectory on eq 189's circle wound :data:`TURNS` times in ``points`` points: points
    per second, compiled (best of ``repeats``) and numpy (one run, counting the points Newton
    assembled)."""
    cc = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    rows, assemble = [], ParallelMechanism.assemble
    for turns in TURNS:
        x, xd, xdd = (np.array(v) for v in zip(*(circle_reference(t) for t in np.linspace(0.0, turns * 2 * np.pi / 28.57, points))))
        guess = elbow_guess(FiveBarParameters(), x[0])
        row = {"turns": turns, "points": points}
        for name, mech, runs in (("compiled", cc.mechanism, repeats), ("numpy", cc.mechanism.reference(), 1)):
            assembled = [0]

            def counting(self, q_sharp, g, *args, **kwargs):
                assembled[0] += len(np.atleast_2d(q_sharp))
                return assemble(self, q_sharp, g, *args, **kwargs)

            ParallelMechanism.assemble = counting
            try:
                row[f"{name}_points_per_s"] = points / per_call(lambda: mech.inverse_trajectory(x, xd, xdd, guess), 1, runs)
            finally:
                ParallelMechanism.assemble = assemble
        row["numpy_assembled_per_point"] = assembled[0] / points  # the numpy run's, the last one
        rows.append(row)
    return rows


def chart(report: dict, path: Path) -> None:
    """Inverse-dynamics rates and forward-dynamics costs per mechanism; the coarse paths' rates."""
    names = ["five_bar", "rsu_ppap"]
    fig, (a1, a2, a3) = subplots(1, 3, (15, 4))
    bars = (("inverse_numpy", "loop_points_per_s", "numpy, point by point"),
            ("inverse_numpy", "trajectory_points_per_s", "numpy, blocks"),
            ("inverse_compiled", "loop_points_per_s", "compiled, point by point"),
            ("inverse_compiled", "trajectory_points_per_s", "compiled, inverse_trajectory"))
    for i, (row, key, label) in enumerate(bars):
        a1.bar(np.arange(2) + 0.2 * i - 0.3, [report[n][row][key] for n in names], width=0.2, label=label)
    a1.axhline(TARGETS["rsu_ppap_points_per_s"], color="k", ls=":", label="aim 2RSU+PPaP")
    a1.axhline(TARGETS["five_bar_points_per_s"], color="grey", ls="--", label="aim 5R")
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
    coarse = report["coarse_paths"]
    for key in ("compiled_points_per_s", "numpy_points_per_s"):
        a3.plot([r["turns"] for r in coarse], [r[key] for r in coarse], "o-", label=key.replace("_points_per_s", ""))
    a3.set_xscale("log", base=2)
    a3.set_yscale("log")
    a3.set_xlabel(f"turns of eq 189's circle in {coarse[0]['points']} points")
    a3.set_ylabel("inverse_trajectory points per second (5R)")
    a3.legend(fontsize=7)
    save(fig, path)
