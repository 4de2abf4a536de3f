"""The thesis proposal's remaining programme in the report (its sec 9 schedule, items 4-11, the
planned chapter 5.3 and objective 2; issue 38): one entry per capability, drawn from its study.

The proposal plans these and prints no result for them, so the "printed" column carries what it
states or the aim issue 38 sets, and freefloat's column what its study measured. Each figure is
the study's own (its module's ``draw``), redrawn from the study's ``report.json``.
"""

from __future__ import annotations

import importlib

from .entry import THESIS, Entry, Row, row
from .results import Results


def _draw(study: str, module: str):
    """The figure of ``module``'s ``draw`` from study ``study``'s report."""
    def draw(r: Results):
        return importlib.import_module(f"..{module}", __package__).draw(r.report(study))
    return draw


def _mm(xs) -> str:
    return " / ".join(f"{1e3 * x:.3g}" for x in xs)


def _voltage_rows(r: Results) -> list[Row]:
    report, rows = r.report("voltage_sliding"), []
    for name, part in report["mechanisms"].items():
        runs, aim = part["runs"], report["aim"][name]
        after = part["after"]
        rows += [row(f"{name}: {label}, max |e| after {after} s (mm)", None, 1e3 * run["error_norm_max"])
                 for label, run in runs.items()]
        voltage = runs["sliding mode, voltage"]
        rows += [row(f"{name}: voltage-input sliding mode, peak voltage (V) / current (A)", None,
                     f"{' / '.join(f'{x:.3g}' for x in voltage['voltage_peak'])}; "
                     f"{' / '.join(f'{x:.3g}' for x in voltage['current_peak'])}"),
                 row(f"{name}: sign changes of s per s, voltage / torque input", None,
                     f"{' / '.join(f'{x:.0f}' for x in voltage['chattering']['s_sign_changes_per_s'])}; "
                     + " / ".join(f"{x:.0f}" for x in runs["sliding mode, torque"]["chattering"]["s_sign_changes_per_s"])),
                 row(f"{name}: voltage over torque input's max |e| (issue 38's aim)", f"<= {report['settings']['aim']:g}",
                     f"{aim['norm_ratio']:.3g} (per axis {' / '.join(f'{x:.3g}' for x in aim['axis_ratios'])}): "
                     f"{'holds' if aim['holds'] else 'fails'}")]
    return rows


def _adaptive_rows(r: Results) -> list[Row]:
    report, rows = r.report("adaptive"), []
    for plant, runs in report["runs"].items():
        rows += [row(f"{plant} % plant: {law.replace('_', ' ')}, steady error x / y (mm)", None,
                     _mm(run["steady_error_max_m"])) for law, run in runs.items()]
        a = runs["adaptive_sliding_mode"]
        rows.append(row(f"{plant} % plant: final estimates / true base parameters", None,
                        ", ".join(f"{x:.4f}" for x in a["final_over_true"])))
        rows.append(row(f"{plant} % plant: estimates within 5 % / 1 % from (s)", None,
                        " / ".join("never" if v is None else f"{v:.3g}" for v in a["settled_from_s"].values())))
    aim = report["aim"]
    rows.append(row("adaptive over fixed-gain steady error, 50 % plant (issue 38's aim)", f"<= {aim['limit']:g}",
                    f"{aim['share_50']:.3g}: {'holds' if aim['holds'] else 'fails'}"))
    return rows


def _friction_rows(r: Results) -> list[Row]:
    report = r.report("friction")
    e = report["energy"]
    rows = [row(f"energy lost falling {e['duration_s']} s (J)", "= work of friction", f"{e['energy_lost_J']:.6g}"),
            row("work of friction (J)", None, f"{e['friction_work_J']:.6g}"),
            row("energy lost - work of friction (J)", 0.0, f"{e['difference_J']:.2g}")]
    rows += [row(f"{name}: max error after 0.2 s, x / y (mm)", None, _mm(run["error_max_m"]))
             for name, run in report["runs"].items()]
    return rows


def _identification_rows(r: Results) -> list[Row]:
    report = r.report("identification")
    robot, fb = report["robot"], report["five_bar"]
    rows = [row("UR5: base parameters", None, robot["base_parameters"]),
            row("UR5: coverage of the 95 % intervals (Monte-Carlo)", 0.95, robot["monte_carlo"]["coverage_95"]),
            row("5R: base parameters", None, fb["base_parameters"]),
            row("5R: true values inside their 95 % intervals", None, f"{fb['inside_95']} of {fb['base_parameters']}"),
            row("5R: coverage of the 95 % intervals (Monte-Carlo)", 0.95, fb["monte_carlo"]["coverage_95"])]
    rows += [row(f"5R {label}: true, estimate +- 95 %", None, f"{t:.5g}, {e:.5g} +- {h:.2g}")
             for label, t, e, h in zip(fb["labels"], fb["true"], fb["estimate"], fb["half_width_95"])]
    rows += [row(f"5R closed loop, {name.replace('_', ' ')}: max error x / y (mm)", None,
                 _mm(c["tracking_error_max_m"])) for name, c in fb["closed_loop"].items()]
    if "target" in report:
        for name, t in report["target"]["identification"].items():
            rows.append(row(f"captured target, {name}: mass / inertia error", None,
                            f"{t['mass_error']:.2g} / {t['inertia_error']:.2g}"))
    return rows


def _jerk_rows(r: Results) -> list[Row]:
    report, rows = r.report("jerk"), []
    steps = report["settings"]["steps_s"]
    for name, c in report["chains"].items():
        for key in ("com", "end_effector"):
            rows.append(row(f"{name}, {key.replace('_', '-')}: relative difference at h = "
                            + ", ".join(f"{h:g}" for h in steps) + " s", None,
                            ", ".join(f"{c[key][str(h)]:.2g}" for h in steps)))
        rows.append(row(f"{name}, link CoMs with eq 4 as printed", None, f"{c['printed_eq4_com']:.2g}"))
    return rows


def _redundancy_rows(r: Results) -> list[Row]:
    report = r.report("redundancy")
    rows = []
    for label, run in report["runs"].items():
        if "refused" in run:
            rows.append(row(label, None, f"refused: {run['refused']}"))
            continue
        rows.append(row(f"{label}: max error x / y (mm); peak efforts (N m); largest internal part (N m)", None,
                        f"{_mm(run['error_max_m'])}; {', '.join(f'{x:.3g}' for x in run['effort_peak'])}; "
                        f"{run['internal_max']:.3g}"))
    rows.append(row("peak effort taken off by the elbow actuator (minimum norm)", None,
                    f"{100 * report['peak_relief']:.0f} %"))
    return rows


def _three_rrr_rows(r: Results) -> list[Row]:
    report = r.report("three_rrr")
    rows = [row(f"forward dynamics, {report['settings']['states']} turned states: largest relative difference", None,
                f"{report['forward_relative_max']:.2g}")]
    rows += [row(f"free motion, RK4 at {float(step) * 1e3:g} ms: platform turned (rad); largest joint difference (rad)",
                 None, f"{m['turned_rad']:.3f}; {m['largest_rad']:.2g}") for step, m in report["free_motion"].items()]
    return rows


ENTRIES: tuple[Entry, ...] = (
    Entry(THESIS, "Sec 9, items 4-5", "Joint friction and the actuators' effective inertias in the modelling "
          "algorithm (schedule items 4 and 5; no result printed).", "friction", _draw("friction", "friction_report"),
          _friction_rows,
          "The 5R with maxon RE 40 class rotors (N^2 J_m = 2.0e-3 kg m^2) and drive-train friction (viscous and "
          "tanh-regularised Coulomb): Pinocchio's energy with the same armature falls by the work of friction; a law "
          "whose model leaves the terms out tracks worse than one that has them."),
    Entry(THESIS, "Sec 9, items 6-7", "Jerk by the composition of motion (eqs 4-5, 19-21) for the end-effectors "
          "and link centres of mass of serial chains.", "jerk", _draw("jerk", "jerk_report"), _jerk_rows,
          "Against 4th-order central differences of Pinocchio's classical accelerations: the difference falls as h^4 "
          "to round-off. Eq 4 as printed (alpha x (alpha x r)) misses the jerk (see docs/jerk.md)."),
    Entry(THESIS, "Sec 9, items 8, 10-11", "Electromechanical actuators and sliding mode with the voltage as the "
          "control input, on the 5R and the 2RSU+PPaP (no design or result printed).", "voltage_sliding",
          _draw("voltage_sliding", "voltage_sliding_report"), _voltage_rows,
          "15 % link and motor errors; each sliding-mode law has its own worst-case design (the voltage design covers "
          "the motors' uncertainty), the voltage through a PI current loop at 3500 1/s, RK4 at 0.1 ms. The printed "
          "column holds issue 38's aim."),
    Entry(THESIS, "Sec 9, item 9", "Identification of the dynamic parameters and their uncertainties (the "
          "prototypes are hardware; the method is simulated here).", "identification",
          _draw("identification", "identification_report"), _identification_rows,
          "1 % noise on every channel; least squares on the base parameters with 95 % intervals. The printed column "
          "holds the intervals' nominal coverage."),
    Entry(THESIS, "Ch 5.3 (planned)", "Adaptive sliding mode on the linear-in-parameters model, against fixed-gain "
          "sliding mode and computed torque, plants 15 % and 50 % off.", "adaptive", _draw("adaptive", "adaptive_report"),
          _adaptive_rows,
          "Sec 5.6's circle, every law held over 0.1 ms; the steady error is the largest over the last turn. The "
          "printed column holds issue 38's aim."),
    Entry(THESIS, "Objective 2, redundant actuation", "Redundant actuation (eq 137 assumes none): the 5R with chain "
          "1's elbow actuated, the effort distribution and its internal forces.", "redundancy",
          _draw("redundancy", "redundancy_report"), _redundancy_rows,
          "Sliding mode on the 15 % plant with the square 5R's gains (the design does not see the actuation); the "
          "internal part is the efforts' projection on the null space of C^T U."),
    Entry(THESIS, "Eqs 101-102, P != 0", "Angular constraints with platform rates: a 3-RRR whose platform turns, "
          "against Pinocchio's constraint dynamics.", "three_rrr", _draw("three_rrr", "three_rrr_report"),
          _three_rrr_rows,
          "Two 6-D welds in pin.constraintDynamics (6 rows redundant in the plane); the free-motion difference "
          "shrinks with the step: it is RK4's error on the two coordinate sets."),
)
