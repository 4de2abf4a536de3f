"""``integrators`` suite: the Lie-group integrators of :data:`freefloat.dynamics.integrators.INTEGRATORS`,
measured side by side in one run (quote the ratios, not the absolute times).

On the bench's two tumbling scenes (:mod:`..scenes.tumbling`: the four-arm robot and the UR5 dual-arm
satellite, free base, torque-free from a seeded state with non-zero momentum), in freefloat's
Python loop on Pinocchio's ABA:

1. Work against precision over 1 s: every fixed-step integrator at halving steps (observed order
   ``log2(e(h) / e(h/2))``; the 6th- and 8th-order ones from coarser steps, as they reach the
   floor sooner), every adaptive one over tolerances; the bench's one sweep (:func:`..race.sweep.sweep`:
   median wall time of ``repeats`` runs, errors against dopri5 at rtol 1e-13), and per accuracy
   band each integrator's least time to reach it (:func:`..race.summary.times_to_reach`).
2. Cost per step: wall time of one 1 ms step of each fixed-step integrator and of one accepted
   dopri5 step (rtol 1e-9), and their dynamics evaluations, taking turns in one process, as ratios
   to rkmk4.
3. Long run: 20 s with euler (1 ms) and rkmk4 (5 ms), with and without momentum projection: the
   conserved momentum's and the kinetic energy's largest change from the start.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ....dynamics.integrators import INTEGRATORS, make_integrator
from ....dynamics.models import make_model
from ....dynamics.simulation import run
from ..race.chart import draw_curves
from ..race.scene import Method
from ..race.summary import BANDS, curves, times_to_reach
from ..race.sweep import Point, sweep, timed_reference
from ..scenes.free_floating import NOTES, FreeFloatingBench
from ..scenes.methods import REFERENCE_ATOL, REFERENCE_RTOL, torque_free
from ..scenes.tumbling import TumblingScene, tumbling_scene
from .drawing import save, subplots
from .timing import side_by_side

#: The tumbling bench scenes swept.
ROBOTS = ("four_arm", "dual_arm")
#: Steps per second of the fixed-step integrators (halving h), of those of order 6 and more, and
#: the dopri5 tolerances (atol = rtol / 100); full and quick.
STEPS, QUICK_STEPS = (25, 50, 100, 200, 400, 800), (25, 50, 100)
HIGH_ORDER_STEPS, QUICK_HIGH_ORDER_STEPS = (5, 10, 20, 40, 80, 160, 320), (5, 10, 20)
RTOLS, QUICK_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12), (1e-5, 1e-8, 1e-11)
#: Order from which a fixed-step integrator sweeps :data:`HIGH_ORDER_STEPS`.
HIGH_ORDER = 6
#: (integrator, step in s) of the long run.
LONG_RUN = (("euler", 1e-3), ("rkmk4", 5e-3))


def settings(quick: bool, repeats: int | None) -> dict:
    """The scenes, the sweep's steps and tolerances, repeats (median of; default 3, 1 quick), the
    cost-per-step repeats (best of) and the long run's simulated time (20 s; 2 s quick)."""
    return {"robots": ROBOTS, "duration_s": 1.0, "seed": 0, "steps_per_s": QUICK_STEPS if quick else STEPS,
            "high_order_steps_per_s": QUICK_HIGH_ORDER_STEPS if quick else HIGH_ORDER_STEPS,
            "rtols": QUICK_RTOLS if quick else RTOLS, "repeats": repeats or (1 if quick else 3),
            "cost_repeats": 3 if quick else 7, "long_run_s": 2.0 if quick else 20.0,
            "reference": {"integrator": "dopri5", "rtol": REFERENCE_RTOL, "atol": REFERENCE_ATOL}}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """Per robot, parts ``<robot> work precision``, ``<robot> cost per step`` and ``<robot> long run``."""
    for name in settings["robots"]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the notes on inertias that MuJoCo refuses: no MuJoCo here
            scene = tumbling_scene(name, settings["duration_s"], settings["seed"])
        yield f"{name} work precision", work_precision(scene, settings)
        yield f"{name} cost per step", cost_per_step(scene, settings["cost_repeats"])
        yield f"{name} long run", long_run(scene, settings["long_run_s"])


def methods(settings: dict) -> list[Method]:
    """Every fixed-step integrator at its steps (h = 1 s / steps), every adaptive one at each rtol;
    freefloat's Python loop."""
    out = []
    for name, spec in INTEGRATORS.items():
        if spec.adaptive:
            out += [Method("freefloat", name, rtol) for rtol in settings["rtols"]]
        else:
            steps = settings["high_order_steps_per_s" if spec.order >= HIGH_ORDER else "steps_per_s"]
            out += [Method("freefloat", name, settings["duration_s"] / n) for n in steps]
    return out


def work_precision(scene: TumblingScene, settings: dict) -> dict:
    """The sweep's points (records of :class:`..race.sweep.Point`), each fixed-step integrator's
    observed orders (from consecutive halvings) and, per band of :data:`..race.summary.BANDS`, each
    integrator's least time to reach it (s), the fastest and its lead over the next."""
    bench = FreeFloatingBench(scene, NOTES[scene.name], tuple(methods(settings)), settings)
    ref, _ = timed_reference(bench)
    points = list(sweep(bench, ref, settings["repeats"]))
    orders = {}
    for label, curve in curves(points).items():
        if not INTEGRATORS[curve[0].method.integrator].adaptive:
            errors = np.array([p.state_error for p in sorted(curve, key=lambda p: -p.method.setting)])
            with np.errstate(divide="ignore", invalid="ignore"):  # a diverged or exact point: inf or nan
                orders[label] = np.log2(errors[:-1] / errors[1:]).tolist()
    bands = {}
    for band in BANDS:
        times = times_to_reach(points, band)
        ranked = list(times)
        bands[f"{band:.0e}"] = {"seconds": times, "fastest": ranked[0] if ranked else None,
                                "lead": times[ranked[1]] / times[ranked[0]] if len(ranked) > 1 else None}
    return {"points": [p.record(scene.name) for p in points], "observed_orders": orders, "bands": bands}


def cost_per_step(scene: TumblingScene, repeats: int) -> dict:
    """Best wall time (s) of one 1 ms step of each fixed-step integrator (20 calls of 10 steps)
    and of one accepted step of dopri5 (1 s at rtol 1e-9), taking turns; dynamics evaluations per
    step; the times over rkmk4's."""
    f, model = torque_free(scene.model), scene.model
    fixed = {name: make_integrator(name, model, substeps=10) for name, spec in INTEGRATORS.items() if not spec.adaptive}
    fns = {name: ((lambda i=i: i.advance(f, scene.q0, scene.v0, 0.01)), 20) for name, i in fixed.items()}
    fns["dopri5"] = (lambda: make_integrator("dopri5", model, rtol=1e-9, atol=1e-11).advance(f, scene.q0, scene.v0, 1.0), 1)
    probe = make_integrator("dopri5", model, rtol=1e-9, atol=1e-11)
    probe.advance(f, scene.q0, scene.v0, 1.0)
    best = side_by_side(fns, repeats)
    per_step = {name: best[name] / 10 for name in fixed} | {"dopri5": best["dopri5"] / probe.accepted}
    return {"seconds_per_step": per_step,
            "evaluations_per_step": {name: INTEGRATORS[name].stages for name in fixed}
            | {"dopri5": probe.evaluations() / probe.accepted},
            "dopri5": {"accepted": probe.accepted, "rejected": probe.rejected},
            "time_ratio_to_rkmk4": {name: t / per_step["rkmk4"] for name, t in per_step.items()}}


def long_run(scene: TumblingScene, duration: float) -> dict:
    """Per :data:`LONG_RUN` integrator, with and without momentum projection, a run of the one
    loop (:func:`freefloat.dynamics.simulation.run`, exact plant) over ``duration`` s: the largest
    change from the start of the momentum ``[P; L]`` about the origin (kg m/s, kg m^2/s) and of
    the kinetic energy (J; no gravity), its wall time (s), its loop, and every 20th sample of both
    changes."""
    plant, out = make_model("exact", scene.robot), {}
    for name, h in LONG_RUN:
        for projected in (False, True):
            integrator = make_integrator(name, scene.model, project_momentum=projected)
            result = run(scene.robot, scene.q0, scene.v0, duration, h, integrator, plant)
            tel = result.telemetry
            dp = np.abs(tel.momentum - tel.momentum[0]).max(axis=1)
            de = np.abs(tel.energy - tel.energy[0])
            out[f"{name}{'_projected' if projected else ''}"] = {
                "h": h, "status": result.status, "backend": result.backend, "momentum_drift_max": float(dp.max()),
                "energy_drift_max": float(de.max()), "energy_drift_final": float(de[-1]), "wall_s": result.wall_time_s,
                "t": tel.t[::20].tolist(), "momentum_drift": dp[::20].tolist(), "energy_drift": de[::20].tolist(),
            }
    return out


def chart(report: dict, path: Path) -> None:
    """Per robot: work against precision (:func:`..race.chart.draw_curves`), and the long run's drifts."""
    robots = report["settings"]["robots"]
    fig, axes = subplots(len(robots), 3, (16, 4.5 * len(robots)), squeeze=False)
    for row, name in zip(axes, robots):
        draw_curves(row[0], [Point.from_record(r) for r in report[f"{name} work precision"]["points"]], "state_error")
        row[0].set(xlabel="final-state error", ylabel="wall time per run, ms (median)",
                   title=f"{name}: work against precision (tumbling, free base)")
        for key, series in report[f"{name} long run"].items():
            row[1].semilogy(series["t"], np.maximum(series["momentum_drift"], 1e-17), label=f"{key} (h={series['h']})")
            row[2].semilogy(series["t"], np.maximum(series["energy_drift"], 1e-17), label=f"{key} (h={series['h']})")
        row[1].set(xlabel="t [s]", ylabel="max |[P; L] - [P0; L0]|", title=f"{name}: momentum drift")
        row[2].set(xlabel="t [s]", ylabel="|T - T0| [J]", title=f"{name}: kinetic energy drift")
        for ax in row:
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    save(fig, path)
