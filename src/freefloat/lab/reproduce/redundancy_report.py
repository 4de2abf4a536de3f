"""``freefloat reproduce redundancy``: redundant actuation (thesis proposal objective 2; eq 137
assumes none): the 5R with chain 1's elbow actuated too, its efforts shared among three actuators
(:mod:`freefloat.parallel.redundancy`), against the square 5R.

Sec 5.6's closed loop: sliding mode with the gains designed over (0.07, 0.17) and (0, 0.22)
(eta = 20; they carry over unchanged, the design does not see the actuation), lambda = 40,
tanh(100 s), the plant 15 % off, the law held over 0.2 ms, RK4 at 0.2 ms in the Python loop,
0.3 s (``--quick``: 0.22 s). Per sharing (square, minimum norm, weights 1:1:4, limits +-3 N m,
limits +-2.5 N m): the largest error after 0.2 s, peak and RMS efforts, and the internal forces
(the efforts' projection on the null space of ``Z^T = C^T U`` along the run); a sharing the limits
cannot give is reported with the reason. Writes ``report.json``, ``report.md`` and ``efforts.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...errors import InfeasiblePlan
from ...parallel.closed_loop import track
from ...parallel.five_bar import (
    TRUE_PARAMETERS,
    FiveBarParameters,
    elbow_guess,
    five_bar,
    redundant_five_bar,
)
from ...parallel.redundancy import EffortDistribution, null_space
from ...parallel.sliding_mode import PlatformControl, circle_reference, design_gains
from .interrupts import finished
from .printed import START

#: The sharings compared: label -> distribution (None with ``square``: the square 5R).
SHARINGS = {"square (base joints)": None, "redundant, minimum norm": EffortDistribution(),
            "redundant, weights 1:1:4": EffortDistribution(weights=np.array([1.0, 1.0, 4.0])),
            "redundant, limits +-3 N m": EffortDistribution(lower=np.full(3, -3.0), upper=np.full(3, 3.0)),
            "redundant, limits +-2.5 N m": EffortDistribution(lower=np.full(3, -2.5), upper=np.full(3, 2.5))}
#: Design points (m), control period and step (s), window start (s).
POINTS, PERIOD, AFTER = np.array([[0.07, 0.17], [0.0, 0.22]]), 2e-4, 0.2


def internal_forces(mech, q: np.ndarray, qd: np.ndarray, efforts: np.ndarray) -> np.ndarray:
    """The internal part of each effort row (N, k): its projection on the null space of the
    actuation map ``Z^T`` (p, k) at the row's state (zeros for square actuation)."""
    p = mech.p
    out = np.zeros_like(efforts)
    for i, (qi, vi, tau) in enumerate(zip(q, qd, efforts)):
        ZT = mech.required_force(qi, vi[:p], np.zeros(p))[1]
        N = null_space(ZT)
        out[i] = N @ (N.T @ tau)
    return out


def run_sharing(label: str, distribution: EffortDistribution | None, gains, duration: float) -> dict:
    """One closed loop; its errors (m), efforts (N m), internal forces (N m), or why it stopped."""
    square = label.startswith("square")
    plant = five_bar(TRUE_PARAMETERS) if square else redundant_five_bar(TRUE_PARAMETERS)
    model = five_bar(FiveBarParameters()) if square else redundant_five_bar(FiveBarParameters(), distribution)
    q0 = plant.assemble(np.array(START), elbow_guess(TRUE_PARAMETERS, np.array(START)))
    control = PlatformControl(model, circle_reference, 40.0, gains)
    try:
        tel = finished(track(plant, control, q0, duration, PERIOD, PERIOD, backend="python")).telemetry
    except InfeasiblePlan as exc:
        return {"refused": str(exc)}
    e = control.sliding_variables(tel.t, tel.q, tel.v)[0]
    late = tel.t > AFTER
    evaluated = slice(0, len(tel.t) - 1)  # the rows the law was evaluated at (the last starts no step)
    internal = internal_forces(plant, tel.q[evaluated], tel.v[evaluated], tel.efforts[evaluated])
    every = max(1, len(tel.t) // 300)
    return {"error_max_m": np.abs(e[late]).max(axis=0).tolist(), "effort_peak": np.abs(tel.efforts).max(axis=0).tolist(),
            "effort_rms": np.sqrt((tel.efforts ** 2).mean(axis=0)).tolist(),
            "internal_max": float(np.linalg.norm(internal, axis=1).max()),
            "t": tel.t[::every].tolist(), "efforts": tel.efforts[::every].tolist(),
            "internal_norm": np.linalg.norm(internal[::every], axis=1).tolist(), "internal_t": tel.t[:-1:every].tolist()}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Every sharing's closed loop; report and figure in ``out``."""
    start = time.perf_counter()
    duration = 0.22 if quick else 0.3
    gains = design_gains(FiveBarParameters(), POINTS, eta=20.0)
    report = {"settings": {"quick": quick, "duration_s": duration, "period_s": PERIOD, "after_s": AFTER, "lambda": 40.0,
                           "eta": 20.0, "design_points": POINTS.tolist(), "plant": "TRUE_PARAMETERS (15 %)"},
              "gains": {"n": gains.n.tolist(), "T": gains.T.tolist()},
              "runs": {label: run_sharing(label, d, gains, duration) for label, d in SHARINGS.items()}}
    square, shared = report["runs"]["square (base joints)"], report["runs"]["redundant, minimum norm"]
    report["peak_relief"] = 1.0 - max(shared["effort_peak"]) / max(square["effort_peak"])
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "efforts.png", dpi=110)
    return report


def markdown(report: dict) -> str:
    """One row per sharing."""
    s = report["settings"]
    lines = ["# Redundant actuation: the 5R with chain 1's elbow actuated", "",
             f"Sliding mode, 15 % plant, law held over {s['period_s'] * 1e3:g} ms, {s['duration_s']} s; errors after "
             f"{s['after_s']} s; wall time {report['wall_time_s']:.0f} s.", "",
             "| sharing | max error x / y (m) | peak efforts (N m) | RMS efforts (N m) | largest internal part (N m) |",
             "|---|---|---|---|---|"]
    for label, r in report["runs"].items():
        if "refused" in r:
            lines.append(f"| {label} | refused: {r['refused']} | | | |")
            continue
        lines.append(f"| {label} | {' / '.join(f'{x:.4g}' for x in r['error_max_m'])} | "
                     f"{', '.join(f'{x:.3g}' for x in r['effort_peak'])} | {', '.join(f'{x:.3g}' for x in r['effort_rms'])} | "
                     f"{r['internal_max']:.3g} |")
    lines += ["", f"The elbow actuator takes {100 * report['peak_relief']:.0f} % off the square 5R's peak effort "
                  "(minimum norm)."]
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """Left: each actuator's effort under the square 5R and the shared sharings; right: the norm of
    the internal forces over time."""
    fig = Figure(figsize=(12, 4.2))
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    for k, (label, r) in enumerate(report["runs"].items()):
        if "refused" in r:
            continue
        efforts = np.array(r["efforts"])
        for j in range(efforts.shape[1]):
            a1.plot(r["t"], efforts[:, j], color=f"C{k}", lw=0.8, ls=("-", "--", ":")[j],
                    label=label if j == 0 else None)
        a2.plot(r["internal_t"], r["internal_norm"], color=f"C{k}", lw=0.9, label=label)
    a1.set(xlabel="t (s)", ylabel="effort (N m); solid tau_11, dashed tau_21, dotted tau_12",
           title="Efforts, sliding mode on the 15 % plant")
    a2.set(xlabel="t (s)", ylabel="|internal part| (N m)", title="Internal forces (null space of C^T U)")
    a1.legend(fontsize=7)
    a2.legend(fontsize=7)
    fig.tight_layout()
    return fig
