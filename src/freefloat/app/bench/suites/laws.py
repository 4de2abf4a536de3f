"""``laws`` suite: the 5R's platform laws compared like for like: cost per call, tracking and
robustness on plants 15 % and 50 % off (thesis proposal objective 2 and planned chapter 5.3).

The laws, all on the nominal model (sec 5.6: lambda = 40, ``tanh(100 s)``, the circle of eq 189):
computed torque (eq 190), sliding mode (eq 153 with eq 167's worst-case gains over the cond < 6
workspace grid), adaptive sliding mode (:func:`freefloat.parallel.adaptive_sliding_mode.five_bar_law`,
its documented gains) and computed torque with feedforward (:mod:`freefloat.parallel.feedforward`, the
reference's inverse dynamics tabulated at the control instants) with eq 190's PD feedback or
eq 153's sliding feedback (same gains).

- ``cost``: seconds per call of each law's ``torque`` from Python, the laws taking turns within
  each repeat (best of ``repeats``, this process's CPU time), at states along the circle 1 mm and
  1 cm/s off it; the compiled closed-chain loop's computed torque and sliding mode called from
  Python (``PlatformControl.compiled_torque``) beside them. The ratios to computed torque in
  Python are what carries over to another machine.
- ``tracking``: each law on the 15 % and 50 % plants (``TRUE_PARAMETERS``, ``TRUE_PARAMETERS_50``)
  from rest at (0.07, 0.17) m, RK4, the law held over each step (:func:`~freefloat.parallel.
  closed_loop.track_five_bar`): the largest and RMS error after 0.2 s, the largest over the last
  turn of the circle (the steady error), the peak effort, the error over time and, for the
  adaptive law, its estimates over time against the plant's base parameters, its Lyapunov
  function over time and the persistent excitation of the circle (condition number of the
  scaled regressor over one turn).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from ....parallel.adaptive_sliding_mode import five_bar_law
from ....parallel.closed_chain import load_closed_chain
from ....parallel.closed_loop import track_five_bar
from ....parallel.feedforward import FeedforwardControl, FeedforwardTable
from ....parallel.five_bar import (
    TRUE_PARAMETERS,
    TRUE_PARAMETERS_50,
    FiveBarParameters,
    elbow_guess,
    five_bar,
)
from ....parallel.platform_regressor import five_bar_theta
from ....parallel.sliding_mode import (
    PlatformControl,
    circle_reference,
    design_gains,
    workspace_grid,
)
from ....paths import URDF_DIR
from .drawing import save, subplots
from .timing import side_by_side

LAWS = ("computed_torque", "sliding_mode", "adaptive_sliding_mode", "feedforward_pd", "feedforward_sliding")
LABELS = {"computed_torque": "computed torque (eq 190)", "sliding_mode": "sliding mode (eq 153)",
          "adaptive_sliding_mode": "adaptive sliding mode", "feedforward_pd": "feedforward + PD (CTCp)",
          "feedforward_sliding": "feedforward + sliding term"}
PLANTS = {"15": TRUE_PARAMETERS, "50": TRUE_PARAMETERS_50}
#: One turn of eq 189's circle, s.
TURN = 2.0 * np.pi / 28.57
#: The issue's aim: adaptive sliding mode's steady error at most this share of sliding mode's (50 % plant).
AIM = 0.5


def settings(quick: bool, repeats: int | None) -> dict:
    """The run (1.5 s at 0.1 ms, sec 5.6's step; quick: 0.45 s, the last turn of the circle after
    0.2 s either way), the design grid's spacing, the timed states, the repeats (best of; default
    7, 2 quick)."""
    return {"duration_s": 0.45 if quick else 1.5, "step_s": 1e-4, "grid_spacing_m": 0.03 if quick else 0.01, "max_condition": 6.0, "lambda": 40.0, "states": 50,
            "repeats": repeats or (2 if quick else 7), "aim": AIM, "blas_threads": 1}


def measure(settings: dict) -> Iterator[tuple[str, object]]:
    """Parts ``design`` (the gains), ``cost``, then ``tracking_15`` and ``tracking_50``."""
    with threadpool_limits(limits=1, user_api="blas"):
        began = time.perf_counter()
        points = workspace_grid(FiveBarParameters(), settings["grid_spacing_m"], settings["max_condition"])
        gains = design_gains(FiveBarParameters(), points)
        yield "design", {"points": len(points), "n": gains.n.tolist(), "T": gains.T.tolist(),
                         "seconds": time.perf_counter() - began}
        chain = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
        yield "cost", cost(chain, gains, settings)
        for name, plant in PLANTS.items():
            yield f"tracking_{name}", {law: tracking(chain, gains, settings, law, plant) for law in LAWS}


def build(chain, gains, settings: dict, law: str, table: FeedforwardTable | None = None):
    """The controller called ``law`` on the nominal 5R (``table``: the feedforward laws' table, else
    built for the run's duration and step)."""
    nominal, lam, step = five_bar(FiveBarParameters()), settings["lambda"], settings["step_s"]
    if law in ("computed_torque", "sliding_mode"):
        return PlatformControl(nominal, circle_reference, lam, gains if law == "sliding_mode" else None)
    if law == "adaptive_sliding_mode":
        return five_bar_law(chain, circle_reference, step, lam)
    twin = PlatformControl(nominal, circle_reference, lam, gains if law == "feedforward_sliding" else None)
    if table is None:
        return FeedforwardControl.along(twin, elbow_guess(FiveBarParameters(), circle_reference(0.0)[0]),
                                        settings["duration_s"], step)
    return FeedforwardControl(twin, table)


def cost(chain, gains, settings: dict) -> dict:
    """Seconds per call of every law and of the compiled computed torque and sliding mode, at
    ``settings["states"]`` states 1 mm and 1 cm/s off the circle, one every control period."""
    mech, step, count = chain.mechanism, settings["step_s"], settings["states"]
    times = step * np.arange(count)
    table = FeedforwardTable.along(five_bar(FiveBarParameters()), circle_reference,
                                   elbow_guess(FiveBarParameters(), circle_reference(0.0)[0]), times[-1], step)
    states, q = [], None
    for t in times:
        x, xd, _ = circle_reference(t)
        q = mech.assemble(x + 1e-3, elbow_guess(FiveBarParameters(), x) if q is None else q[2:])
        states.append((t, q, mech.velocity_map(q) @ (xd + 1e-2)))
    laws = {law: build(chain, gains, settings, law, table) for law in LAWS}
    compiled = {f"{law}_compiled": laws[law].compiled_torque() for law in ("computed_torque", "sliding_mode")}

    def calls(torque, reset=None):
        def run():
            if reset is not None:
                reset()
            for t, q, qd in states:
                torque(t, q, qd)
        return run, 1

    timed = {law: calls(c.torque, getattr(c, "reset", None)) for law, c in laws.items()}
    timed |= {name: calls(fn) for name, fn in compiled.items()}
    best = side_by_side(timed, settings["repeats"], time.process_time)
    out = {name: seconds / count for name, seconds in best.items()}
    return {"seconds_per_call": out, "over_computed_torque": {k: v / out["computed_torque"] for k, v in out.items()},
            "table_seconds_per_row": table_cost(settings)}


def table_cost(settings: dict) -> float:
    """Seconds per row to build the feedforward table (once, before the run) over one turn."""
    began = time.process_time()
    table = FeedforwardTable.along(five_bar(FiveBarParameters()), circle_reference,
                                   elbow_guess(FiveBarParameters(), circle_reference(0.0)[0]), TURN, settings["step_s"])
    return (time.process_time() - began) / len(table.efforts)


def tracking(chain, gains, settings: dict, law: str, plant: FiveBarParameters) -> dict:
    """One closed loop of ``law`` on ``plant``: errors (m), peak effort (N m), the error every
    5 ms and, for the adaptive law, its estimates every 5 ms over the plant's base parameters."""
    control = build(chain, gains, settings, law)
    duration, step = settings["duration_s"], settings["step_s"]
    began = time.perf_counter()
    tel = track_five_bar(plant, control, duration, step).telemetry
    wall = time.perf_counter() - began
    e = np.array([circle_reference(t)[0] for t in tel.t]) - tel.q[:, :2]
    after, last = tel.t > 0.2, tel.t > tel.t[-1] - TURN
    every = max(1, round(5e-3 / step))
    out = {"error_max_after_0.2s_m": np.abs(e[after]).max(axis=0).tolist(),
           "error_rms_after_0.2s_m": np.sqrt((e[after] ** 2).mean(axis=0)).tolist(),
           "steady_error_max_m": np.abs(e[last]).max(axis=0).tolist(),
           "peak_effort_Nm": np.abs(tel.efforts).max(axis=0).tolist(), "loop_wall_s": wall,
           "t": tel.t[::every].tolist(), "error_m": e[::every].tolist()}
    if law == "adaptive_sliding_mode":
        t, estimates = control.estimates()
        truth = five_bar_theta(plant)
        pick = np.arange(0, len(t), every)
        lyapunov = [lyapunov_function(control, tel, t[k], estimates[k], truth) for k in pick]
        out |= {"names": list(control.regressor.names), "true": truth.tolist(), "estimate_t": t[pick].tolist(),
                "estimate_over_true": (estimates[pick] / truth).tolist(),
                "final_over_true": (estimates[-1] / truth).tolist(), "excitation_condition": excitation(control, truth),
                "lyapunov": lyapunov, "lyapunov_largest_rise": float(np.diff(lyapunov).max())}
    return out


def lyapunov_function(control, tel, t: float, estimate: np.ndarray, truth: np.ndarray) -> float:
    """``V = s^T H s / 2 + (theta^ - theta)^T Gamma^-1 (theta^ - theta) / 2`` at the recorded row
    of time ``t``, H the plant's (its base parameters ``truth`` in the regressor)."""
    row = int(np.argmin(np.abs(tel.t - t)))
    q, qd, p = tel.q[row], tel.v[row], control.regressor.p
    x_d, xd_d, _ = circle_reference(tel.t[row])
    s = qd[:p] - xd_d - control.lam * (x_d - q[:p])
    zero = np.zeros(p)
    static = control.regressor.platform(q, zero, zero) @ truth
    H = np.stack([control.regressor.platform(q, zero, unit) @ truth - static for unit in np.eye(p)], axis=1)
    error = estimate - truth
    return float(0.5 * s @ H @ s + 0.5 * error @ (error / control.gamma))


def excitation(control, truth: np.ndarray) -> float:
    """Condition number of the platform regressor along one turn of the circle (200 points),
    its columns scaled by the plant's base parameters: finite when the turn excites every one."""
    mech, rows, q = control.regressor.chain.mechanism, [], None
    for t in np.linspace(0.0, TURN, 200, endpoint=False):
        x, xd, xdd = circle_reference(t)
        q = mech.assemble(x, elbow_guess(FiveBarParameters(), x) if q is None else q[2:])
        rows.append(control.regressor.platform(q, xd, xdd) * truth)
    return float(np.linalg.cond(np.vstack(rows)))


def steady(report: dict, plant: str, law: str) -> float:
    """The larger axis of a law's steady error on a plant, m."""
    return max(report[f"tracking_{plant}"][law]["steady_error_max_m"])


def summary(report: dict) -> list[str]:
    """Cost ratios and steady errors, one line per law; the aim's ratio."""
    ratio = report["cost"]["over_computed_torque"]
    lines = [f"laws: {law}: {ratio[law]:.2f} x computed torque's cost, steady error "
             + ", ".join(f"{steady(report, p, law):.2e} m ({p} %)" for p in PLANTS) for law in LAWS]
    share = steady(report, "50", "adaptive_sliding_mode") / steady(report, "50", "sliding_mode")
    return [*lines, f"laws: adaptive / fixed-gain sliding mode, steady error on the 50 % plant: {share:.3f} (aim <= {AIM})"]


def chart(report: dict, path: Path) -> None:
    """Cost per call; steady error against cost per plant; the 50 % plant's errors over time; the
    adaptive law's estimates over the true values."""
    from matplotlib.ticker import NullFormatter

    fig, ((a1, a2), (a3, a4)) = subplots(2, 2, (13, 9))
    cost_us = {k: v * 1e6 for k, v in report["cost"]["seconds_per_call"].items()}
    names = [*LAWS, "computed_torque_compiled", "sliding_mode_compiled"]
    a1.barh(range(len(names)), [cost_us[n] for n in names], color=["C0"] * len(LAWS) + ["grey"] * 2)
    a1.set_yticks(range(len(names)), [LABELS.get(n, n.replace("_compiled", " (compiled C++)").replace("_", " "))
                                      for n in names], fontsize=8)
    a1.set_xscale("log")
    a1.set_xlabel("CPU time per call, us (Python unless marked)")
    for marker, plant in zip("os", PLANTS):
        for i, law in enumerate(LAWS):
            a2.loglog(cost_us[law], steady(report, plant, law), marker, color=f"C{i}",
                      label=f"{LABELS[law]}, {plant} %" if plant == "50" else None)
    a2.xaxis.set_minor_formatter(NullFormatter())
    a2.set_xlabel("CPU time per call, us (Python)")
    a2.set_ylabel("steady error (last turn, larger axis), m")
    a2.set_title("circles: 15 % plant, squares: 50 % plant", fontsize=9)
    a2.legend(fontsize=7)
    for i, law in enumerate(LAWS):
        run = report["tracking_50"][law]
        a3.semilogy(run["t"], np.abs(np.array(run["error_m"])).max(axis=1), color=f"C{i}", label=LABELS[law], lw=0.8)
    a3.set_xlabel("t (s)")
    a3.set_ylabel("|e| (larger axis), m, 50 % plant")
    a3.legend(fontsize=7)
    for plant, style in zip(PLANTS, (":", "-")):
        run = report[f"tracking_{plant}"]["adaptive_sliding_mode"]
        ratios = np.array(run["estimate_over_true"])
        for k, name in enumerate(run["names"]):
            a4.plot(run["estimate_t"], ratios[:, k], style, color=f"C{k}", label=f"{name}" if plant == "50" else None)
    a4.axhline(1.0, color="k", lw=0.5)
    a4.set_xlabel("t (s)")
    a4.set_ylabel("estimate / true (solid 50 %, dotted 15 % plant)")
    a4.legend(fontsize=7)
    save(fig, path)
