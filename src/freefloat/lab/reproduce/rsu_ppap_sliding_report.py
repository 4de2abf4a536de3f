"""``freefloat reproduce rsu_ppap_sliding``: the 2RSU+PPaP under sliding mode against computed
torque, as the thesis proposal's sec 5.6 does for the 5R (issue 21 item 6).

1. Worst-case gains (eqs 155-170, eta = 20) over the scene's design box (home +- 4 cm on a 2 cm
   grid, 125 points; ``--quick``: 4 cm, 27 points) and the 2^7 extreme sets of the seven uncertain
   masses (+-15 %, ``urdf/rsu_ppap.data.toml``), beside the gains the scene prints.
2. The scene ``rsu_ppap_sliding_mode`` through the one loop with those gains and, on the same
   plant, computed torque (eq 190, lambda = 40): plants nominal, 15 % and 50 % off (every mass;
   :data:`~freefloat.parallel.rsu_ppap_masses.PLANT_SIGNS`). Max and RMS error after the
   reaching phase, reaching time of each sliding variable (|s| < 0.02), peak efforts.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...app.outputs import write_report
from ...app.scenes import MechanismScene, builtin_scenes, load_scene
from ...parallel.gain_design import SlidingModeGains, box_grid, design_gains
from ...parallel.rsu_ppap import load_data, load_rsu_ppap
from ...parallel.rsu_ppap_masses import PLANT_ERRORS, RsuPpapModel
from .five_bar_report import reaching_times
from .interrupts import finished

SCENE = "rsu_ppap_sliding_mode"
#: The design box: half-width and grid spacing (m) about the home pose; the quick run's spacing.
HALF_WIDTH, SPACING, QUICK_SPACING = 0.04, 0.02, 0.04


def design(spacing: float = SPACING, eta: float = 20.0) -> SlidingModeGains:
    """The scene's worst-case gains over the cube home +- :data:`HALF_WIDTH` at ``spacing`` (m)."""
    data = load_data()
    model = RsuPpapModel(load_rsu_ppap().mechanism, data)
    return design_gains(model, box_grid(np.array(data["home"]), HALF_WIDTH, spacing), eta)


def variant(scene: MechanismScene, plant: str, gains: SlidingModeGains | None,
            duration: float | None = None) -> MechanismScene:
    """``scene`` on the named plant under sliding mode with ``gains`` or, for None, computed
    torque with the same lambda; ``duration`` (s) shortens the run."""
    ctrl = scene.controller
    if gains is None:
        ctrl = ctrl.with_settings("computed_torque", n=None, T=None, n_ij={})
    else:
        ctrl = ctrl.with_settings("sliding_mode", n=tuple(gains.n), T=tuple(map(tuple, gains.T)),
                       n_ij={f"{i},{j}": tuple(v) for (i, j), v in gains.n_ij.items()})
    sim = scene.simulation if duration is None else replace(scene.simulation, duration=duration)
    return replace(scene, mechanism=replace(scene.mechanism, plant=plant), controller=ctrl, simulation=sim)


def run_case(scene: MechanismScene) -> dict:
    """One run through the one loop (:func:`freefloat.app.runner.simulate`): the summary's
    errors (mm) and peak efforts, the reaching times, the error every 5 ms for the figure."""
    from ...app.runner import simulate

    outcome = finished(simulate(scene))
    tel, summary = outcome.telemetry, outcome.summary
    e = tel.platform_reference - tel.platform
    return {"status": outcome.status, "loop": summary["loop"],
            "error_max_mm": (np.array(summary["tracking_error_max"]) * 1e3).tolist(),
            "error_rms_mm": (np.array(summary["tracking_error_rms"]) * 1e3).tolist(),
            "reaching_time_s": reaching_times(tel.t, tel.sliding), "peak_efforts": summary["peak_efforts"],
            "t": tel.t[::10].tolist(), "e_mm": (e[::10] * 1e3).tolist()}


def reproduce(out: Path, quick: bool = False) -> dict:
    """The design and the six closed loops; report.json, report.md and errors.png in ``out``."""
    start = time.perf_counter()
    scene = load_scene(builtin_scenes()[SCENE])
    spacing = QUICK_SPACING if quick else SPACING
    gains = design(spacing)
    duration = 0.5 if quick else None
    cases = {f"{law}, {plant}": variant(scene, plant, g, duration)
             for plant in PLANT_ERRORS for law, g in (("sliding mode", gains), ("computed torque", None))}
    ctrl = scene.controller
    report = {
        "settings": {"quick": quick, "scene": SCENE, "design_points": len(gains.points), "spacing": spacing, "half_width": HALF_WIDTH, "eta": gains.eta, "lambda": ctrl.lam,
                     "step": scene.simulation.step, "duration": duration or scene.simulation.duration,
                     "reaching_phase": scene.metrics.reaching_phase, "plant_errors": PLANT_ERRORS},
        "gains": {"n": gains.n.tolist(), "T": gains.T.tolist(),
                  "n_ij": {f"{i},{j}": gains.n_ij[i, j].tolist() for i, j in sorted(gains.n_ij)},
                  "Delta_max": gains.Delta_max.tolist(), "delta0_max": gains.delta0_max.tolist()},
        "scene_gains": {"n": list(ctrl.n), "T": [list(r) for r in ctrl.T], "n_ij": {k: list(v) for k, v in ctrl.n_ij.items()}},
        "cases": {name: run_case(case) for name, case in cases.items()},
    }
    write_report(out, report, markdown, start)
    figure(report, out / "errors.png")
    return report


def markdown(report: dict) -> str:
    """The report as Markdown: gains, then one row per case."""
    g, s = report["gains"], report["settings"]
    lines = ["# The 2RSU+PPaP: sliding mode against computed torque", "",
             f"Settings {s}; wall time {report['wall_time_s']:.1f} s.", "",
             "## Gains (eq 167) from the design", "",
             f"n = {np.round(g['n'], 4).tolist()}, T = {np.round(g['T'], 4).tolist()}, |Delta|_max's spectral radius "
             f"{max(abs(np.linalg.eigvals(np.array(g['Delta_max'])))):.3f}", ""]
    lines += [f"n_{key} = {np.round(v, 4).tolist()}" for key, v in g["n_ij"].items()]
    lines += ["", f"## Closed loop (error after {s['reaching_phase']} s)", "",
              ("| case | max error x / y / z (mm) | RMS error x / y / z (mm) | reaching time of s (s) "
               "| peak efforts (cranks N m, rail N) |"),
              "|---|---|---|---|---|"]
    for name, c in report["cases"].items():
        reach = ", ".join("-" if r is None else f"{r:.4f}" for r in c["reaching_time_s"])
        lines.append(f"| {name} | {' / '.join(f'{x:.3g}' for x in c['error_max_mm'])} | "
                     f"{' / '.join(f'{x:.3g}' for x in c['error_rms_mm'])} | {reach} | "
                     f"{', '.join(f'{x:.2f}' for x in c['peak_efforts'])} |")
    return "\n".join(lines) + "\n"


def figure(report: dict, path: Path) -> None:
    """One panel per plant: the platform error's norm |e| (mm, log) under each law."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plants = list(report["settings"]["plant_errors"])
    fig, axes = plt.subplots(1, len(plants), figsize=(4.5 * len(plants), 4), sharex=True, sharey=True)
    for ax, plant in zip(axes, plants):
        for name, c in report["cases"].items():
            if name.endswith(f", {plant}"):
                ax.semilogy(c["t"], np.linalg.norm(c["e_mm"], axis=1), label=name.split(",")[0])
        ax.set_title(f"plant {plant}", fontsize=9)
        ax.set_xlabel("t (s)")
    axes[0].set_ylabel("|q#_d - q#| (mm)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
