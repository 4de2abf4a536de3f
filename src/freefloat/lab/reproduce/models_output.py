"""Markdown tables and figures of the model-accuracy report."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .models_cases import GRID_MODELS, REGIMES
from .printed import TABLE_1


def _fmt(x) -> str:
    return "-" if x is None else f"{x:.2e}"


def markdown(report: dict) -> str:
    """The report as Markdown: one table per part, numbers as measured."""
    acc = report["accuracy"]
    lines = ["# Dynamics models against the exact dynamics (Pinocchio ABA)", "",
             f"freefloat {report['versions'].get('freefloat')}, pin {report['versions'].get('pin')}; "
             f"settings: {report['settings']}; total wall time {report['wall_time_s']:.0f} s.", "",
             f"## 1. Accelerations at random states (four-arm robot, free base, {acc['samples']} states per regime)", "",
             "Max relative error `max|a - a_exact| / max|a_exact|`, and cost per call.", "",
             "| model | " + " | ".join(REGIMES) + " | us per call |", "|---|" + "---|" * (len(REGIMES) + 1)]
    for name in acc["seconds_per_evaluation"]:
        errs = [acc["errors"][r][name] for r in REGIMES]
        lines.append(f"| {name} | " + " | ".join(_fmt(e) for e in errs) + f" | {acc['seconds_per_evaluation'][name] * 1e6:.0f} |")
    lines += ["", "## 2. Chapter 5.1: plant x controller model (nested RMS tracking error, eq 140, rad)", "",
              "| plant (integrator) | controller | overall | per arm | CoM drift (m) | momentum drift | wall (s) |",
              "|---|---|---|---|---|---|---|"]
    for c in report["grid"]:
        per_arm = ", ".join(_fmt(x) for x in c["tracking_rms_per_arm"])
        lines.append(f"| {c['plant']} ({c['integrator']}) | {c['controller']} | {_fmt(c['tracking_rms_overall'])} | "
                     f"{per_arm} | {_fmt(c['com_drift_max'])} | {_fmt(c['momentum_drift_max'])} | {c['wall_time_s']:.1f} |")
    lines += ["", "Dissertation, Table 1 (plant FM-NIC-A): controller FM-NIC-A " + ", ".join(_fmt(x) for x in TABLE_1["nidc"])
              + "; controller FM-ST-A " + ", ".join(_fmt(x) for x in TABLE_1["standard"]) + " (arms 1-4, overall).", "",
              "## 3. Torque-free tumbling (RKMK4, 1 ms): state error against exact", "",
              "| model | case | final state error | momentum drift (model) | momentum drift (exact) |", "|---|---|---|---|---|"]
    for t in report["tumbling"]:
        lines.append(f"| {t['model']} | {t['case']} | {_fmt(t['final_state_error'])} | {_fmt(t['momentum_drift_max'])} | "
                     f"{_fmt(t['exact_momentum_drift_max'])} |")
    att = report["attitude"]
    lines += ["", "## 4. Base attitude: Euler angles (eqs 9-11) vs the Lie group, constant spin, RK4 at 1 ms, 3 s", "",
              "| spin (rad/s) | closest min abs(cos theta) | Euler-angle max error (rad) | Lie-group max error (rad) |", "|---|---|---|---|"]
    for row in att["spins"]:
        lines.append(f"| {row['spin']} | {row['min_abs_cos_theta']:.1e} | {_fmt(row['euler_max_error_rad'])} | {_fmt(row['lie_max_error_rad'])} |")
    lines += ["", f"Eq 11 as printed vs the rotation derivative: max relative error {att['eq11_printed_max_relative_error']:.2f} "
              "over 100 random angles and rates.", ""]
    return "\n".join(lines)


def _save(fig, path: Path) -> Path:
    """Lay out, write at 120 dpi and close a figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def figures(report: dict, out: Path) -> list[Path]:
    """accuracy.png (errors per regime), grid.png (tracking error heat map), attitude.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    acc = report["accuracy"]
    names = list(acc["seconds_per_evaluation"])
    fig, ax = plt.subplots(figsize=(11, 4.5))
    width = 0.8 / len(REGIMES)
    for i, regime in enumerate(REGIMES):
        ax.bar(np.arange(len(names)) + i * width, [max(acc["errors"][regime][n], 1e-17) for n in names], width, label=regime)
    ax.set_yscale("log")
    ax.set_xticks(np.arange(len(names)) + width, names, rotation=30, ha="right")
    ax.set_ylabel("max relative acceleration error vs exact")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    written.append(_save(fig, out / "accuracy.png"))

    cells = [c for c in report["grid"] if c["integrator"] == "euler"]
    table = np.full((len(GRID_MODELS), len(GRID_MODELS)), np.nan)
    for c in cells:
        table[GRID_MODELS.index(c["plant"]), GRID_MODELS.index(c["controller"])] = c["tracking_rms_overall"] or np.nan
    fig, ax = plt.subplots(figsize=(6.5, 5))
    image = ax.imshow(np.log10(table), cmap="viridis")
    for i in range(len(GRID_MODELS)):
        for j in range(len(GRID_MODELS)):
            ax.text(j, i, f"{table[i, j]:.1e}", ha="center", va="center", color="w", fontsize=8)
    ax.set_xticks(range(len(GRID_MODELS)), GRID_MODELS, rotation=30, ha="right")
    ax.set_yticks(range(len(GRID_MODELS)), GRID_MODELS)
    ax.set_xlabel("controller model")
    ax.set_ylabel("plant (semi-implicit Euler, 1 ms)")
    fig.colorbar(image, label="log10 nested RMS tracking error (rad)")
    written.append(_save(fig, out / "grid.png"))

    rows = report["attitude"]["spins"]
    fig, ax = plt.subplots(figsize=(6, 4))
    closest = [r["min_abs_cos_theta"] for r in rows]
    ax.loglog(closest, [r["euler_max_error_rad"] for r in rows], "o-", label="Euler angles (eqs 9-11), RK4")
    ax.loglog(closest, [max(r["lie_max_error_rad"], 1e-17) for r in rows], "s-", label="Lie group (RKMK4)")
    ax.set_xlabel("closest approach: min |cos theta|")
    ax.set_ylabel("max orientation error (rad)")
    ax.legend()
    written.append(_save(fig, out / "attitude.png"))
    return written
