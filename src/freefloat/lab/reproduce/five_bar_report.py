"""``freefloat reproduce five_bar``: the thesis proposal's sec 5.6 with freefloat's 5R.

1. Worst-case sliding-mode gains (eqs 155-170, eta = 20) over the 1 cm grid of the 5R's
   non-singular workspace (condition numbers of A° and C^T U below 6: the document draws its
   region without a threshold) and the 64 extreme parameter sets, beside eq 187.
2. The circle of eq 189 from (0.07, 0.17) at rest, lambda = 40, tanh(100 s), with the true
   parameters 15 % and 50 % off the estimates: sliding mode and computed torque (eq 190).
   Reaching time (|s| < 0.02), tracking error after 0.2 s, peak actuator torques; the error,
   sliding-variable and torque series (every 10th step) for the report's figures.
3. Fig 8's workspace as numbers: the conditioning map of :func:`conditioning_map`, and the exact
   boundary and singularity loci of :func:`singularity_map`.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from ...app.outputs import write_report
from ...errors import FreefloatError
from ...parallel.closed_loop import track, track_five_bar
from ...parallel.five_bar import TRUE_PARAMETERS, TRUE_PARAMETERS_50, FiveBarParameters, elbow_guess, five_bar
from ...parallel.sliding_mode import PlatformControl, circle_reference, design_gains, printed_gains, workspace_grid
from .interrupts import finished
from .printed import EQ_187, START
from .study_journal import entries


def eq_187_gains():
    """Eq 187's printed sliding-mode gains."""
    return printed_gains(EQ_187["n"], EQ_187["T"],
                         {(0, 0): EQ_187["xdot2"], (1, 0): EQ_187["xdot_ydot"], (1, 1): EQ_187["ydot2"]})


#: Integrators of the closure-stability map: every fixed-step one of the registry, and the explicit
#: Euler the thesis's analysis contrasts with the semi-implicit one.
STABILITY_INTEGRATORS = ("euler", "explicit_euler", "rkmk4", "rkmk6", "rkmk8")

#: The closed loop animated in meshcat, and its page.
ANIMATED, ANIMATION = "sliding mode, 15 %", "trajectory_sliding_mode_15.html"


#: The threshold on the condition numbers of A° and C^T U that bounds the non-singular workspace
#: (the thesis draws its region without stating one; freefloat's stated choice).
MAX_CONDITION = 6.0


def conditioning_map(p: FiveBarParameters, spacing: float) -> dict:
    """Thesis fig 8 as numbers: on the ``spacing`` grid of :func:`workspace_grid` (x in
    [-reach, reach], y in (0, reach], m), the larger of the condition numbers of A° and C^T U where
    the 5R assembles with outward elbows, None where it does not (out of reach)."""
    mech = five_bar(p)
    reach = p.l1 + p.l2 + p.l0
    xs, ys = np.arange(-reach, reach + 1e-9, spacing), np.arange(spacing, reach + 1e-9, spacing)
    condition = np.full((len(ys), len(xs)), np.nan)
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            try:
                q = mech.assemble(np.array([x, y]), elbow_guess(p, np.array([x, y])))
            except FreefloatError:
                continue
            A, _, C, *_ = mech.terms(q, np.zeros(6))
            condition[i, j] = max(np.linalg.cond(A[:, 2:]), np.linalg.cond(C.T @ mech.selection()))
    return {"x": xs.tolist(), "y": ys.tolist(), "condition": [[None if np.isnan(c) else float(c) for c in row]
                                                              for row in condition]}


def singularity_map(p: FiveBarParameters, spacing: float) -> dict:
    """Thesis fig 8's exact counterpart (:mod:`freefloat.parallel.maps`): the workspace's boundary in
    closed form (arcs where a leg is stretched or folded, points (n, 2) in m), its area (m^2), and
    the type I and type II singularity loci of the working mode the circle of eq 189 runs in (the
    outward elbows at (0.07, 0.17)), bisected from a ``spacing`` grid over the reach."""
    from ...parallel.maps import five_bar_exact, grids, loci
    from ...parallel.maps.modes import working_label

    mech = five_bar(p)
    start = np.array(START)
    mode = str(working_label(mech, mech.assemble(start, elbow_guess(p, start))[None])[0])
    reach = p.l1 + p.l2 + p.l0
    axes = [np.arange(-reach, reach + 1e-9, spacing)] * 2
    found = loci.loci(mech, grids.task_map(mech, grids.axes_grid(axes)), (len(axes[0]), len(axes[1])), "task")
    return {"mode": mode, "area_m2": five_bar_exact.area(p),
            "boundary": [{"leg": arc.leg, "stretched": arc.stretched, "points": arc.points.tolist()}
                         for arc in five_bar_exact.boundary(p, samples=400)],
            "loci": {locus.kind: locus.coordinates[locus.mode == mode].tolist() for locus in found}}


def reaching_times(t: np.ndarray, s: np.ndarray, bound: float = 0.02) -> list[float | None]:
    """First time (s) each sliding variable's |s| is below ``bound``, or None: ``t`` (N,), ``s`` (N, p)."""
    reached = np.abs(s) < bound
    return [float(t[np.argmax(reached[:, i])]) if reached[:, i].any() else None for i in range(s.shape[1])]


def run_case(gains, plant: FiveBarParameters, duration: float, step: float, html: Path | None = None) -> dict:
    """One closed-loop run; summary numbers; optionally its meshcat animation."""
    control = PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0, gains)
    tel = finished(track_five_bar(plant, control, duration, step)).telemetry
    t_sim, qs = tel.t, tel.q
    if html is not None:
        animate(t_sim, qs, html)
    e, s = (x[:-1] for x in control.sliding_variables(tel.t, tel.q, tel.v))  # at every step started
    t, efforts = tel.t[:-1], tel.efforts[:-1]
    reach = reaching_times(t, s)
    late = t > 0.2
    magnitude = np.abs(efforts)
    reaching = t_sim[: len(magnitude)] <= max((r for r in reach if r is not None), default=t[-1])
    return {"reaching_time_s": reach, "error_after_0.2s_mm": (np.abs(e[late]).max(axis=0) * 1e3).tolist(),
            "peak_torque_Nm": magnitude.max(axis=0).tolist(),
            "peak_torque_time_s": t_sim[magnitude.argmax(axis=0)].tolist(),
            "peak_torque_reaching_Nm": magnitude[reaching].max(axis=0).tolist(),
            "t": t[::10].tolist(), "e_mm": (e[::10] * 1e3).tolist(), "s": s[::10].tolist(),
            "torque_Nm": efforts[::10].tolist()}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run the gain design and the four closed loops; write report.json, report.md, errors.png and
    the meshcat page of the sliding-mode run against the 15 % plant."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    nominal = FiveBarParameters()
    spacing = 0.03 if quick else 0.01
    points = workspace_grid(nominal, spacing=spacing, max_condition=MAX_CONDITION)
    gains = design_gains(nominal, points)
    duration, step = (0.25, 2e-4) if quick else (0.5, 1e-4)
    cases = {"sliding mode, 15 %": (gains, TRUE_PARAMETERS), "computed torque, 15 %": (None, TRUE_PARAMETERS),
             "sliding mode, eq 187's gains, 15 %": (eq_187_gains(), TRUE_PARAMETERS),
             "sliding mode, 50 %": (gains, TRUE_PARAMETERS_50), "computed torque, 50 %": (None, TRUE_PARAMETERS_50)}
    report = {
        "settings": {"quick": quick, "duration": duration, "step": step, "lambda": 40.0, "eta": 20.0,
                     "grid_points": len(points), "max_condition": MAX_CONDITION},
        "workspace": conditioning_map(nominal, spacing),
        "singularities": singularity_map(nominal, 0.03 if quick else 0.02),
        "gains": {"n": gains.n.tolist(), "T": gains.T.tolist(), "xdot2": gains.n_ij[(0, 0)].tolist(),
                  "xdot_ydot": gains.n_ij[(1, 0)].tolist(), "ydot2": gains.n_ij[(1, 1)].tolist()},
        "eq_187": EQ_187,
        "cases": {name: run_case(g, plant, duration, step, out / ANIMATION if name == ANIMATED else None)
                  for name, (g, plant) in cases.items()},
    }
    write_report(out, report, markdown, start)
    figure(report, out / "errors.png")
    return report


def animate(t: np.ndarray, qs: np.ndarray, path: Path) -> Path:
    """Self-contained meshcat page of a 5R run: the spanning-tree URDF with its base held still,
    the chains' joints from Orsino's coordinates ``[x, y, q11, q12, q21, q22]``."""
    import warnings

    from ...app.viz import write_trajectory_html
    from ...paths import URDF_DIR
    from ...robot.loading import load_robot

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(URDF_DIR / "five_bar.urdf")
    q = np.tile(robot.neutral(), (len(t), 1))
    q[:, 7:] = qs[:, 2:]
    return write_trajectory_html(robot, t, q, path, fps=200.0)


def markdown(report: dict) -> str:
    g, d = report["gains"], report["eq_187"]
    lines = ["# Sec 5.6: the 5R tracking a circle, sliding mode vs computed torque", "",
             f"Settings {report['settings']}; wall time {report['wall_time_s']:.0f} s.", "",
             "## Gains (eq 167): freefloat / eq 187", "", "| term | x | y |", "|---|---|---|"]
    for key, label in (("n", "constant"), ("xdot2", "xdot^2"), ("xdot_ydot", "|xdot ydot|"), ("ydot2", "ydot^2")):
        lines.append(f"| {label} | {g[key][0]:.1f} / {d[key][0]} | {g[key][1]:.1f} / {d[key][1]} |")
    lines.append(f"| T | {np.round(g['T'], 2).tolist()} / {d['T']} | |")
    lines += ["", "## Closed loop (circle of eq 189, lambda = 40)", "",
              ("| case | reaching time x, y (s) | max error after 0.2 s, x / y (mm) | peak torques until reached (N m) "
               "| peak torques (N m) at t (s) |"), "|---|---|---|---|---|"]
    for name, c in report["cases"].items():
        reach = ", ".join("-" if r is None else f"{r:.4f}" for r in c["reaching_time_s"])
        err = " / ".join(f"{x:.4f}" for x in c["error_after_0.2s_mm"])
        early = ", ".join(f"{x:.2f}" for x in c["peak_torque_reaching_Nm"])
        peaks = ", ".join(f"{x:.2f} at {w:.4f}" for x, w in zip(c["peak_torque_Nm"], c["peak_torque_time_s"]))
        lines.append(f"| {name} | {reach} | {err} | {early} | {peaks} |")
    lines += ["", "Document (sec 5.6): reaching time of s_y about 0.008 s; sliding-mode errors in the hundredths of a "
              "millimetre, also with 50 % errors; computed torque oscillates with peaks of 12 mm (x) and 27 mm (y).", ""]
    return "\n".join(lines)


def figure(report: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharex=True)
    for name, c in report["cases"].items():
        e = np.array(c["e_mm"])
        for i, ax in enumerate(axes):
            ax.plot(c["t"], e[:, i], label=name)
    for i, ax in enumerate(axes):
        ax.set_xlabel("t (s)")
        ax.set_ylabel(f"error {'xy'[i]} (mm)")
        ax.set_yscale("symlog", linthresh=1e-3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def stability_map(duration: float = 0.5, steps=(1e-4, 2e-4, 5e-4, 1e-3, 2e-3),
                  lambdas=(0.0, 10.0, 100.0, "1/h", 1000.0), methods=STABILITY_INTEGRATORS) -> list[dict]:
    """Loop-closure drift of the free-falling 5R over (integrator, h, Baumgarte lambda)."""
    p = FiveBarParameters()
    mech = five_bar(p)
    q0 = mech.assemble(np.array(START), elbow_guess(p, np.array(START)))
    rows = []
    for method in methods:
        for h in steps:
            for lam in lambdas:
                value = 1.0 / h if lam == "1/h" else lam
                result = finished(track(mech, None, q0, duration, h, h, value, method))
                rows.append({"method": method, "h": h, "lambda": value, "lambda_label": str(lam),
                             "diverged": result.status != "completed",
                             "max_drift_m": float(np.nanmax(result.telemetry.drift))})
    return rows


def reproduce_stability(out: Path, quick: bool = False) -> dict:
    """``freefloat reproduce closure_stability``: the (method, h, lambda) map as JSON and Markdown."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    steps = (2e-4, 1e-3, 2e-3) if quick else (1e-4, 2e-4, 5e-4, 1e-3, 2e-3)
    lambdas = (0.0, 100.0, "1/h") if quick else (0.0, 10.0, 100.0, "1/h", 1000.0)
    rows = stability_map(duration=0.2 if quick else 0.5, steps=steps, lambdas=lambdas)
    report = {"rows": rows,
              "settings": {"quick": quick, "mechanism": f"5R falling freely from {START} at rest, zero torques"}}
    lines = ["# Loop-closure drift of the 5R over step and Baumgarte lambda", "",
             f"{report['settings']['mechanism']}; max |qbar| (m) over the run; 'diverged' when it exceeds 1 m.", "",
             "| method | h (s) | " + " | ".join(f"lambda = {lam}" for lam in lambdas) + " |",
             "|---|---|" + "---|" * len(lambdas)]
    for method in STABILITY_INTEGRATORS:
        for h in steps:
            cells = [r for r in rows if r["method"] == method and r["h"] == h]
            lines.append(f"| {method} | {h:g} | " + " | ".join("diverged" if r["diverged"] else f"{r['max_drift_m']:.1e}" for r in cells) + " |")
    return write_report(out, report, lambda _: "\n".join(lines) + "\n", start)


def _resumable(journal: Path, settings: dict) -> dict[int, dict]:
    """Samples of an earlier run into the same folder with the same settings, by index.

    Raises:
        RunFolderError: naming the journal's line that is not a sample of these settings
            (:func:`~.study_journal.entries`).
    """
    return {record["sample"]: record for record in entries(journal, settings, lambda r: _not_a_sample(r, settings))}


def _not_a_sample(record: dict, settings: dict) -> str | None:
    """What is wrong with a journaled sample of a run of ``settings`` (None: nothing)."""
    sample = record.get("sample")
    if isinstance(sample, bool) or not isinstance(sample, int) or not 0 <= sample < settings["runs"]:
        return f"names sample {sample!r}, which a run of {settings['runs']} samples does not have"
    if record.get("status") not in ("ok", "failed"):
        return f"gives sample {sample} the status {record.get('status')!r} (ok or failed)"
    errors = record.get("error_mm")
    if record["status"] == "ok" and not (isinstance(errors, list) and len(errors) == 2
                                         and all(isinstance(x, (int, float)) and math.isfinite(x) for x in errors)):
        return f"gives sample {sample} an error_mm of {errors!r} (two finite numbers)"
    return None


def reproduce_robustness(out: Path, quick: bool = False, runs: int | None = None, relative_error: float = 0.5,
                         scheduler: str | None = None, journal: Path | None = None) -> dict:
    """``freefloat reproduce robustness``: gains designed across Dask workers over the grid, then
    ``runs`` closed loops (default 20, 2 when ``quick``) on plants drawn within ``relative_error``
    of the nominal parameters.

    Each finished sample is appended to ``journal`` (default ``samples.jsonl`` in ``out``) as it
    comes in; rerun with the same journal and settings, the study resumes from them. Failed
    samples are kept as failures with their reason; the statistics are over the samples that ran.

    Raises:
        FreefloatError: for ``runs`` or ``relative_error`` that
            :func:`~freefloat.parallel.sweeps.check_monte_carlo` refuses, a scheduler that does
            not answer, or a gain design that fails.
    """
    from ...parallel.sweeps import check_monte_carlo, client, design_gains_distributed, monte_carlo

    runs = (2 if quick else 20) if runs is None else runs
    check_monte_carlo(runs, relative_error)  # before the cluster starts
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    nominal = FiveBarParameters()
    points = workspace_grid(nominal, spacing=0.03 if quick else 0.01, max_condition=6.0)
    duration = 0.25 if quick else 0.3
    settings = {"quick": quick, "runs": runs, "relative_error": relative_error, "duration": duration,
                "grid_points": len(points), "seed": 0}
    journal = out / "samples.jsonl" if journal is None else journal
    done = _resumable(journal, settings)
    with client(scheduler) as dask_client:
        gains = design_gains_distributed(dask_client, nominal, points, quiet=False)
        with journal.open("a") as log:
            def keep(i: int, result: dict) -> None:
                log.write(json.dumps({"settings": settings, **result}) + "\n")
                log.flush()

            results = monte_carlo(dask_client, gains, runs=runs, relative_error=relative_error, duration=duration,
                                  quiet=False, done=done, on_result=keep)
    ran = [r for r in results if r["status"] == "ok"]
    if not ran:
        # base class: every sample's failure, of any kind
        raise FreefloatError(f"robustness: every one of the {runs} samples failed, e.g. {results[0]['reason']}")
    errors = np.array([r["error_mm"] for r in ran])
    report = {"settings": {**settings, "scheduler": scheduler or "local cluster", "resumed": len(done)},
              "gains": {"n": gains.n.tolist(), "T": gains.T.tolist()},
              "runs": results, "failed": len(results) - len(ran), "error_after_0.2s_mm_max": errors.max(axis=0).tolist(),
              "error_after_0.2s_mm_median": np.median(errors, axis=0).tolist()}
    return write_report(out, report, lambda r: (
        f"# Monte-Carlo robustness of the 5R sliding-mode controller\n\n{len(results)} plants with the six uncertain "
        f"parameters drawn uniformly within {relative_error:.0%} of nominal (seed 0); gains over {len(points)} grid points; "
        f"circle of eq 189 for {duration} s.\n\nTracking error after 0.2 s, x / y (mm): median "
        f"{r['error_after_0.2s_mm_median'][0]:.4f} / {r['error_after_0.2s_mm_median'][1]:.4f}, worst "
        f"{r['error_after_0.2s_mm_max'][0]:.4f} / {r['error_after_0.2s_mm_max'][1]:.4f}; "
        f"{r['failed']} failed samples.\n"), start)
