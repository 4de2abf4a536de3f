"""``freefloat reproduce chattering``: sliding mode on the 5R with the control period as the axis.

Eq 187's printed gains on the 15 % plant (``TRUE_PARAMETERS``), lambda = 40, the circle of eq 189
from (0.07, 0.17) at rest, for sign(s) and tanh(100 s). The plant is integrated by RK4 at a fixed
step (10 us; 20 us with ``--quick``) in the one loop (compiled), Baumgarte lambda 100; the law is
held over each control period (zero-order hold) or evaluated at every RK4 stage ("continuous"). After 0.2 s: sign
changes of s per second (s sampled at every step), max tracking error x / y, max |s|, and the
median effort jump between control updates. Writes ``report.json``, ``report.md``,
``chattering.csv`` and ``chattering.png``.
"""

from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np

from ...app.outputs import write_report
from ...parallel.closed_loop import steps_per_period, track
from ...parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from ...parallel.sliding_mode import SWITCHES, PlatformControl, chattering, circle_reference
from .five_bar_report import eq_187_gains
from .interrupts import finished
from .printed import START

#: Control periods, s; None: the law at every RK4 stage.
PERIODS = (1e-5, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, None)
QUICK_PERIODS = (1e-4, 1e-3, None)
#: Start of the window the measures are taken over, s.
AFTER = 0.2


def run_period(saturation: str, period: float | None, step: float, duration: float) -> dict:
    """One closed loop; its row: the measures of :func:`~freefloat.parallel.sliding_mode.chattering`
    and the max error after :data:`AFTER` s, mm."""
    plant = five_bar(TRUE_PARAMETERS)
    point = np.array(START)
    q0 = plant.assemble(point, elbow_guess(TRUE_PARAMETERS, point))
    control = PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0, eq_187_gains(), saturation)
    result = finished(track(plant, control, q0, duration, step, period))
    tel = result.telemetry
    e, s = control.sliding_variables(tel.t, tel.q, tel.v)
    every = 1 if period is None else steps_per_period(period, step)
    updates = slice(0, len(tel.t) - 1, every)  # the rows the law was evaluated at (the last starts no step)
    late = tel.t > AFTER
    return {"saturation": saturation, "period": period, "completed": result.status == "completed",
            "error_after_0.2s_mm": (np.abs(e[late]).max(axis=0) * 1e3).tolist(),
            **chattering(tel.t, tel.efforts[updates], s, AFTER, tel.t[updates])}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Every (switch, period) closed loop; the report, table and figure in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    step, duration, periods = (2e-5, 0.25, QUICK_PERIODS) if quick else (1e-5, 0.3, PERIODS)
    rows = [run_period(saturation, period, step, duration) for saturation in SWITCHES for period in periods]
    report = {"settings": {"quick": quick, "step": step, "duration": duration, "after": AFTER, "lambda": 40.0,
                           "baumgarte": 100.0, "gains": "eq 187 (printed)", "plant": "TRUE_PARAMETERS (15 %)",
                           "start": list(START)}, "rows": rows}
    write_report(out, report, markdown, start)
    write_csv(rows, out / "chattering.csv")
    figure(rows, out / "chattering.png")
    return report


def _period(row: dict) -> str:
    """A row's control period in us, or "continuous"."""
    return "continuous" if row["period"] is None else f"{row['period'] * 1e6:g} us"


def markdown(report: dict) -> str:
    """The table, one row per (switch, control period)."""
    st = report["settings"]
    lines = ["# Chattering against the control period: sign(s) and tanh(100 s), eq 187's gains, the 15 % plant", "",
             (f"RK4 at {st['step'] * 1e6:g} us throughout; the law held over the control period, or evaluated at "
              f"every RK4 stage (continuous). Measured after {st['after']} s of {st['duration']} s on the circle of "
              f"eq 189; wall time {report['wall_time_s']:.0f} s."), "",
             "| switch | control period | sign changes of s per s | max error x / y (mm) | max abs(s) | median effort jump (N m) |",
             "|---|---|---|---|---|---|"]
    for r in report["rows"]:
        lines.append(f"| {r['saturation']} | {_period(r)} | " + ", ".join(f"{x:.0f}" for x in r["s_sign_changes_per_s"])
                     + " | " + " / ".join(f"{x:.4f}" for x in r["error_after_0.2s_mm"]) + " | "
                     + ", ".join(f"{x:.2g}" for x in r["s_max"]) + " | "
                     + ", ".join(f"{x:.3g}" for x in r["effort_jump_median"]) + (" |" if r["completed"] else " (stopped early) |"))
    return "\n".join(lines) + "\n"


def write_csv(rows: list[dict], path: Path) -> Path:
    """One line per (switch, period): period in s (empty: continuous), each measure per axis."""
    keys = ("error_after_0.2s_mm", "s_sign_changes_per_s", "s_max", "effort_jump_median", "effort_variation_per_s")
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["switch", "period_s", "completed"] + [f"{k}_{i}" for k in keys for i in range(2)])
        for r in rows:
            writer.writerow([r["saturation"], "" if r["period"] is None else r["period"], r["completed"]]
                            + [x for k in keys for x in r[k]])
    return path


def figure(rows: list[dict], path: Path) -> Path:
    """Four panels against the control period (log): sign changes per s, max error, max |s|,
    median effort jump; one curve per switch and axis, the continuous law as a dotted line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = (("s_sign_changes_per_s", "sign changes of s per s"), ("error_after_0.2s_mm", "max error (mm)"),
              ("s_max", "max |s|"), ("effort_jump_median", "median effort jump (N m)"))
    fig, axes = plt.subplots(1, 4, figsize=(17, 4))
    for ax, (key, label) in zip(axes, panels):
        for saturation, style in zip(SWITCHES, ("-", "--")):
            held = [r for r in rows if r["saturation"] == saturation and r["period"] is not None]
            continuous = [r for r in rows if r["saturation"] == saturation and r["period"] is None]
            for i, axis in enumerate("xy"):
                line, = ax.plot([r["period"] for r in held], [max(r[key][i], 1e-9) for r in held], "o" + style,
                                label=f"{saturation}, {axis}")
                for r in continuous:
                    ax.axhline(max(r[key][i], 1e-9), ls=":", color=line.get_color())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("control period (s); dotted: continuous")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
