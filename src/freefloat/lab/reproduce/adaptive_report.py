"""``freefloat reproduce adaptive``: adaptive sliding mode (the thesis proposal's planned chapter
5.3) against fixed-gain sliding mode and computed torque on the 5R, plants 15 % and 50 % off.

The runs are the ``laws`` bench suite's (:func:`freefloat.lab.bench.suites.laws.tracking`): sec
5.6's circle from rest at (0.07, 0.17) m, lambda = 40, tanh(100 s), every law on the nominal model
held over 0.1 ms, RK4 at 0.1 ms; sliding mode's gains from the cond < 6 grid (1 cm; ``--quick``:
3 cm); 1.5 s (``--quick``: 0.45 s). The steady error is the largest over the last turn of the
circle. The issue's aim: adaptive sliding mode's steady error on the 50 % plant at most
:data:`~freefloat.lab.bench.suites.laws.AIM` of the fixed-gain law's. The estimates' convergence:
when they enter and stay within 5 % and 1 % of the plant's base parameters. Writes
``report.json``, ``report.md`` and ``adaptive.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...parallel.closed_chain import load_closed_chain
from ...parallel.five_bar import FiveBarParameters
from ...parallel.sliding_mode import design_gains, workspace_grid
from ...paths import URDF_DIR
from ..bench.suites.laws import AIM, LABELS, PLANTS, settings, tracking

#: The laws compared (the ``laws`` suite's names).
LAWS = ("computed_torque", "sliding_mode", "adaptive_sliding_mode")
#: Relative distances of the estimates to the true values whose entry times are reported.
WITHIN = (0.05, 0.01)


def settled_from(t: list[float], ratios: list[list[float]], within: float) -> float | None:
    """The first time (s) from which every estimate stays within ``within`` of its true value
    (``ratios``: estimate / true per time), None if never."""
    far = np.abs(np.asarray(ratios) - 1.0).max(axis=1) > within
    if far[-1]:
        return None
    last = np.flatnonzero(far)
    return float(t[last[-1] + 1]) if len(last) else float(t[0])


def reproduce(out: Path, quick: bool = False) -> dict:
    """The design, the six closed loops and the aim; report and figure in ``out``."""
    start = time.perf_counter()
    st = settings(quick, None)
    points = workspace_grid(FiveBarParameters(), st["grid_spacing_m"], st["max_condition"])
    gains = design_gains(FiveBarParameters(), points)
    chain = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    runs = {plant: {law: tracking(chain, gains, st, law, params) for law in LAWS} for plant, params in PLANTS.items()}
    for plant in PLANTS:
        adaptive = runs[plant]["adaptive_sliding_mode"]
        adaptive["settled_from_s"] = {str(w): settled_from(adaptive["estimate_t"], adaptive["estimate_over_true"], w)
                                      for w in WITHIN}
    steady = {plant: {law: max(runs[plant][law]["steady_error_max_m"]) for law in LAWS} for plant in PLANTS}
    share = steady["50"]["adaptive_sliding_mode"] / steady["50"]["sliding_mode"]
    report = {"settings": {**st, "quick": quick, "design_points": len(points)},
              "gains": {"n": gains.n.tolist(), "T": gains.T.tolist()}, "runs": runs, "steady_m": steady,
              "aim": {"share_50": share, "share_15": steady["15"]["adaptive_sliding_mode"] / steady["15"]["sliding_mode"],
                      "limit": AIM, "holds": bool(share <= AIM)}}
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "adaptive.png", dpi=110)
    return report


def _shown(value: float | None) -> str:
    return "-" if value is None else f"{value:.3g}"


def markdown(report: dict) -> str:
    """One row per (plant, law), the estimates' convergence and the aim."""
    s = report["settings"]
    lines = ["# Adaptive sliding mode against fixed-gain sliding mode and computed torque (the 5R)", "",
             f"{s['duration_s']} s at {s['step_s'] * 1e3:g} ms, {s['design_points']} design points; wall time "
             f"{report['wall_time_s']:.0f} s.", "",
             "| plant | law | max error after 0.2 s, x / y (m) | steady (last turn), x / y (m) | peak efforts (N m) |",
             "|---|---|---|---|---|"]
    for plant, runs in report["runs"].items():
        for law, r in runs.items():
            lines.append(f"| {plant} % | {LABELS[law]} | {' / '.join(f'{x:.3g}' for x in r['error_max_after_0.2s_m'])} | "
                         f"{' / '.join(f'{x:.3g}' for x in r['steady_error_max_m'])} | "
                         f"{', '.join(f'{x:.3g}' for x in r['peak_effort_Nm'])} |")
    lines += ["", "| plant | final estimate / true | within 5 % from (s) | within 1 % from (s) | excitation condition |",
              "|---|---|---|---|---|"]
    for plant, runs in report["runs"].items():
        a = runs["adaptive_sliding_mode"]
        lines.append(f"| {plant} % | {', '.join(f'{x:.4f}' for x in a['final_over_true'])} | "
                     f"{_shown(a['settled_from_s']['0.05'])} | {_shown(a['settled_from_s']['0.01'])} | "
                     f"{a['excitation_condition']:.3g} |")
    a = report["aim"]
    lines += ["", f"Aim (adaptive's steady error at most {a['limit']:g} of fixed-gain's on the 50 % plant): "
                  f"{a['share_50']:.3g} ({a['share_15']:.3g} on the 15 % plant): {'holds' if a['holds'] else 'fails'}."]
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """Left: the error (larger axis) over time per law, 50 % plant; right: the adaptive law's
    estimates over the true values on both plants."""
    fig = Figure(figsize=(12, 4.2))
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    for i, law in enumerate(LAWS):
        for plant, style in zip(PLANTS, (":", "-")):
            r = report["runs"][plant][law]
            a1.semilogy(r["t"], np.abs(np.array(r["error_m"])).max(axis=1), style, color=f"C{i}", lw=0.8,
                        label=f"{LABELS[law]}, {plant} %")
    a1.set(xlabel="t (s)", ylabel="|e| (larger axis), m", title="Tracking error (solid: 50 % plant, dotted: 15 %)")
    a1.legend(fontsize=7)
    for plant, style in zip(PLANTS, (":", "-")):
        a = report["runs"][plant]["adaptive_sliding_mode"]
        ratios = np.array(a["estimate_over_true"])
        for k, name in enumerate(a["names"]):
            a2.plot(a["estimate_t"], ratios[:, k], style, color=f"C{k}", label=name if plant == "50" else None)
    a2.axhline(1.0, color="k", lw=0.5)
    a2.set(xlabel="t (s)", ylabel="estimate / true", title="Adaptive law's base parameters (solid 50 %, dotted 15 %)",
           ylim=(0.3, 1.7))
    a2.legend(fontsize=7)
    fig.tight_layout()
    return fig
