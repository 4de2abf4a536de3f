"""The entries of the report of ``freefloat reproduce all``: every table and figure of the
dissertation's chapters 4-5 and the thesis's sec 5.6, in the documents' order, and each erratum,
as one registry (:data:`ENTRIES`).

An entry names its document and number, describes the document's figure or table in our words,
says which study's output it is drawn from, and gives: a figure function (what freefloat drew), a
rows function (quantity, printed value, freefloat's value, difference) and a note (the difference's
reason). Every number comes from the studies' saved outputs or is computed here from the package.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from matplotlib.figure import Figure

from ..models_cases import TABLE_1
from ..series_report import DOCUMENT
from ..task_space_report import TABLE_2, TABLE_3, TABLE_5
from . import figures as rf
from .results import Results

DISSERTATION, THESIS = "Dissertation", "Thesis"


@dataclass(frozen=True)
class Row:
    """One compared number: what, the document's value, freefloat's, and their difference."""

    quantity: str
    printed: str
    ours: str
    difference: str


def row(quantity: str, printed: float | str | None, ours: float | str, fmt: str = ".3g") -> Row:
    """A :class:`Row`; for two numbers the difference is ours - printed and their ratio."""
    if isinstance(printed, (int, float)) and isinstance(ours, (int, float)):
        ratio = f", ratio {ours / printed:.3g}" if printed else ""
        return Row(quantity, format(printed, fmt), format(ours, fmt), f"{ours - printed:+{fmt}}{ratio}")
    shown = lambda x: "-" if x is None else (format(x, fmt) if isinstance(x, (int, float)) else str(x))  # noqa: E731
    return Row(quantity, shown(printed), shown(ours), "-")


@dataclass(frozen=True)
class Entry:
    """One table, figure or erratum of a document.

    Attributes:
        document: :data:`DISSERTATION` or :data:`THESIS`.
        number: as printed ("Fig 20", "Table 2", "Eq 140").
        caption: what the document shows there, in our words.
        study: the ``freefloat reproduce`` study its numbers come from ("" for none).
        draw: freefloat's figure from the results, or None (a table or erratum).
        rows: the compared numbers from the results, or None.
        note: the difference and its reason, or what to read in the figure.
        erratum: True for an error in the printed text.
    """

    document: str
    number: str
    caption: str
    study: str = ""
    draw: Callable[[Results], Figure] | None = None
    rows: Callable[[Results], list[Row]] | None = None
    note: str = ""
    erratum: bool = False


#: Registry, in the documents' order (dissertation, then thesis; errata after each document).
ENTRIES: list[Entry] = []


def entry(*args, **kwargs) -> Entry:
    """Add an :class:`Entry` to :data:`ENTRIES`."""
    made = Entry(*args, **kwargs)
    ENTRIES.append(made)
    return made


# ------------------------------------------------------------------ dissertation, chapter 4 / sec 5.1
SEC51 = {"FM-NIC-A": ("sec51_exact_nidc", "sec51_nidc_nidc"), "FM-ST-A": ("sec51_exact_standard", "sec51_nidc_standard")}
#: The dissertation's controller names -> freefloat's model names.
CONTROLLER_MODELS = {"FM-NIC-A": "nidc", "FM-ST-A": "standard"}
ARM_SIGNS = (1, -1, -1, 1)  # sec 4.2.2: arms 1 and 4 by +5 deg, arms 2 and 3 by -5 deg


def sec51(res: Results, controller: str) -> dict[str, dict]:
    """The sec-5.1 runs with ``controller``'s model: on the exact plant and on FM-NIC-A."""
    exact, printed = SEC51[controller]
    return {"exact plant (RKMK4)": res.arrays("series", exact),
            "FM-NIC-A plant (semi-implicit Euler)": res.arrays("series", printed)}


def _summary(res: Results, run: str) -> dict:
    return res.report("series")["runs"][run]


def _sec51_rms_rows(res: Results, controller: str) -> list[Row]:
    printed = TABLE_1[CONTROLLER_MODELS[controller]][-1]
    exact, document = SEC51[controller]
    return [row("nested RMS overall (rad), exact plant", printed, _summary(res, exact)["tracking_rms_overall"]),
            row("nested RMS overall (rad), FM-NIC-A plant", printed, _summary(res, document)["tracking_rms_overall"])]


def _com_rows(res: Results, controller: str) -> list[Row]:
    exact, document = SEC51[controller]
    return [row("max CoM drift (m), exact plant", 1e-7, _summary(res, exact)["com_drift_max"]),
            row("max CoM drift (m), FM-NIC-A plant", 1e-7, _summary(res, document)["com_drift_max"])]


def _base_rows(res: Results, controller: str) -> list[Row]:
    run = res.arrays("series", SEC51[controller][0])
    dx, dy, _ = run["base"][-1] - run["base"][0]
    return [row("base displacement x, y (m), exact plant", "along the (-x, -y) bisector", f"{dx:.4g}, {dy:.4g}"),
            row("largest |base yaw| (deg)", "~0", float(np.abs(run["base"][:, 2]).max()))]


SEC51_NOTE = ("In this scene the base does not turn and the momentum is zero, so the FM-NIC-A, FM-ST-A and exact "
              "models describe the same motion; the tracking error is set by the integrator (semi-implicit Euler "
              "against RKMK4) and by the zero-order hold of the torques, not by the controller's model. Table 1's "
              "236-fold gap between the two controllers is not reproduced (docs/models.md).")

entry(DISSERTATION, "Fig 6", "Start posture of the four-arm robot: arms stretched along +x, +y, -x, -y.", "series",
      lambda r: rf.configuration(r.arrays("series", "sec51_exact_nidc")["skeleton_start"], "Dissertation fig 6: start posture"),
      lambda r: [row(f"arm {k + 1} end-effector x, y (m)", p, ", ".join(f"{v:.4g}" for v in r.arrays("series", "sec51_exact_nidc")["ee"][0, k, :2]))
                 for k, p in enumerate(("7.75, 0", "0, 7.75", "-7.75, 0", "0, -7.75"))])
entry(DISSERTATION, "Fig 7", "Flowchart of the joint-space simulation loop (dynamic matrices, control law, model update).",
      note="A diagram, no data: freefloat's one loop (plant x integrator x controller) is described in "
           "docs/architecture.md; nothing to compare.")
entry(DISSERTATION, "Fig 8", "Joint reference trajectories: quintic polynomials, 5 deg in 5 s.", "series",
      lambda r: rf.per_arm({"reference": r.arrays("series", "sec51_exact_nidc")}, "joint_reference",
                           "Dissertation fig 8: joint references", "q_d (deg)", np.degrees(1.0)),
      lambda r: [row(f"arm {k + 1} reference displacement (deg)", 5.0 * s,
                     float(np.degrees(np.mean(np.diff(r.arrays("series", "sec51_exact_nidc")["joint_reference"][[0, -1], 4 * k:4 * k + 4], axis=0)))))
                 for k, s in enumerate(ARM_SIGNS)],
      "With --quick the run and the quintic last 0.5 s, so the displacement reached is the same 5 deg in a tenth of the time.")
for number, controller, what in (("9", "FM-NIC-A", "errors"), ("10", "FM-NIC-A", "torques"), ("11", "FM-NIC-A", "paths"),
                                 ("12", "FM-NIC-A", "base"), ("13", "FM-NIC-A", "final"), ("14", "FM-NIC-A", "com"),
                                 ("15", "FM-ST-A", "errors"), ("16", "FM-ST-A", "torques"), ("17", "FM-ST-A", "paths"),
                                 ("18", "FM-ST-A", "base"), ("19", "FM-ST-A", "com")):
    title = f"Dissertation fig {number}"
    spec = {
        "errors": (f"Joint tracking errors, controller {controller}.",
                   lambda r, c=controller, t=title: rf.joint_errors(sec51(r, c), f"{t}: joint tracking errors, controller {c}"),
                   lambda r, c=controller: _sec51_rms_rows(r, c), SEC51_NOTE),
        "torques": (f"Joint control torques, controller {controller}.",
                    lambda r, c=controller, t=title: rf.per_arm(sec51(r, c), "tau", f"{t}: joint torques, controller {c}", "tau (N m)"),
                    lambda r, c=controller: [row("peak joint torque (N m), exact plant", None, _summary(r, SEC51[c][0])["peak_joint_torque"])],
                    "The document prints no torque values; the curves are the computed torque of the quintic."),
        "paths": (f"End-effector trajectories, controller {controller}" + (" (printed 'ST-ST-A')." if number == "17" else "."),
                  lambda r, c=controller, t=title: rf.ee_paths(sec51(r, c), f"{t}: end-effector paths, controller {c}"),
                  lambda r, c=controller: [row(f"arm {k + 1} end-effector end x, y (m)", None,
                                               ", ".join(f"{v:.4g}" for v in r.arrays("series", SEC51[c][0])["ee"][-1, k, :2])) for k in range(4)],
                  "The document prints no end values for this run (Table 5 is sec 5.2's)."),
        "base": (f"Base trajectory, controller {controller}.",
                 lambda r, c=controller, t=title: rf.base_motion(sec51(r, c), f"{t}: base CoM and yaw, controller {c}"),
                 lambda r, c=controller: _base_rows(r, c), "Sec 4.2.2 expects the base to translate along the (-x, -y) "
                 "bisector with no rotation: both hold (x = y displacement, yaw at round-off)."),
        "final": ("Final posture of the four-arm robot.",
                  lambda r, t=title: rf.configuration(r.arrays("series", "sec51_exact_nidc")["skeleton_end"], f"{t}: final posture"),
                  None, "The arms turned by the quintic's 5 deg; the base moved along the bisector."),
        "com": (f"System CoM trajectory, controller {controller}.",
                lambda r, c=controller, t=title: rf.com_drift(sec51(r, c), f"{t}: CoM drift, controller {c}"),
                lambda r, c=controller: _com_rows(r, c),
                "The dissertation's ~1e-7 m drift 'by the sequential base/joint update' is integration error: it falls to "
                "round-off with RKMK4 on the exact plant."),
    }[what]
    entry(DISSERTATION, f"Fig {number}", spec[0], "series", spec[1], spec[2], spec[3])
    if number == "16":
        entry(DISSERTATION, "Table 1", "Nested RMS joint tracking error (eq 140) per arm and overall, plant FM-NIC-A, "
              "controllers FM-NIC-A and FM-ST-A.", "series", None,
              lambda r: [row(f"{c}, {'overall' if k == 4 else f'arm {k + 1}'}", printed[k],
                             (_summary(r, SEC51[c][1])["tracking_rms_overall"] if k == 4 else
                              list(_summary(r, SEC51[c][1])["tracking_rms_per_arm"].values())[k]))
                         for c, printed in ((c, TABLE_1[m]) for c, m in CONTROLLER_MODELS.items())
                         for k in range(5)] + _sec51_rms_rows(r, "FM-NIC-A")[:1],
              SEC51_NOTE)

# ------------------------------------------------------------------ sec 5.2: joint-space and task-space runs
TS = "task_space"


def jsc(r: Results) -> dict:
    return r.arrays(TS, "jsc")


def tsc(r: Results) -> dict:
    return r.arrays(TS, "tsc")


def _table5_rows(r: Results, run: str, arm: int, which: str) -> list[Row]:
    printed = TABLE_5[f"arm{arm + 1}"][0 if which == "start" else 1]
    ours = r.report(TS)["table5"][run][which][arm]
    return [row(f"{run} arm {arm + 1} {which} {c}", p, o) for c, p, o in zip(("x (m)", "y (m)", "z-rotation (deg)"), printed, ours)]


def _table_rows(r: Results, table: str, printed: dict, label: str) -> list[Row]:
    ours = r.report(TS)[table]
    return [row(f"{label} {key}, arm {k + 1}", printed[key][k], ours[key][k]) for key in ("x", "y", "z_deg", "overall")
            for k in range(4)]


TS_NOTE = ("Exact plant, RKMK4 at 0.1 ms. The dissertation simulated FM-NIC-A, which describes the same motion as "
           "the exact plant when the momentum is zero and the base does not turn (the models study: on sec 5.1's task every "
           "plant gives the same tracking error with the same integrator; here the base yaw "
           "stays below 3e-11 deg), so only the exact plant is run. The start is every joint 0.5 deg off the stretched "
           "posture along the motion (Table 4).")
for number, caption, draw in (
    ("20", "Joint trajectories, joint-space control (JSC).",
     lambda r: rf.per_arm({"JSC": jsc(r)}, "joints", "Dissertation fig 20: joints, JSC", "q (deg)", np.degrees(1.0))),
    ("21", "End-effector paths in the plane, JSC.", lambda r: rf.ee_paths({"JSC": jsc(r)}, "Dissertation fig 21: end-effector paths, JSC")),
    ("22", "End-effector x and y over time, JSC.",
     lambda r: rf.ee_components({"JSC": jsc(r)}, "Dissertation fig 22: end-effector x, y, JSC", (0, 1), ("x (m)", "y (m)"))),
    ("23", "End-effector z-rotation over time, JSC.",
     lambda r: rf.ee_components({"JSC": jsc(r)}, "Dissertation fig 23: end-effector z-rotation, JSC", (2,), ("z-rotation (deg)",))),
    ("24", "Base trajectory, JSC.", lambda r: rf.base_motion({"JSC": jsc(r)}, "Dissertation fig 24: base, JSC")),
    ("25", "Joint control torques, JSC.", lambda r: rf.per_arm({"JSC": jsc(r)}, "tau", "Dissertation fig 25: joint torques, JSC", "tau (N m)")),
    ("26", "End-effector paths in the plane, task-space control (TSC).",
     lambda r: rf.ee_paths({"TSC": tsc(r), "JSC (reference)": jsc(r)}, "Dissertation fig 26: end-effector paths, TSC")),
    ("27", "End-effector x and y over time, TSC.",
     lambda r: rf.ee_components({"TSC": tsc(r)}, "Dissertation fig 27: end-effector x, y, TSC", (0, 1), ("x (m)", "y (m)"))),
    ("28", "End-effector z-rotation over time, TSC.",
     lambda r: rf.ee_components({"TSC": tsc(r)}, "Dissertation fig 28: end-effector z-rotation, TSC", (2,), ("z-rotation (deg)",))),
    ("29", "End-effector position tracking error in the plane (x error against y error), TSC.",
     lambda r: rf.ee_plane_errors(tsc(r), jsc(r), "Dissertation fig 29: end-effector position error, TSC")),
    ("30", "End-effector x and y tracking errors over time, TSC.",
     lambda r: rf.tracking_errors(tsc(r), jsc(r), "Dissertation fig 30: end-effector x, y errors, TSC", (0, 1),
                                  ("x error (m)", "y error (m)"))),
):
    entry(DISSERTATION, f"Fig {number}", caption, TS, draw, None, TS_NOTE)


def _table2_rows(r: Results) -> list[Row]:
    low, high = r.report(TS)["tsc_condition_range"]
    return _table_rows(r, "table2", TABLE_2, "RMS error") + [
        row(f"overall, arm {k + 1}, analytic qddot_d", TABLE_2["overall"][k], v)
        for k, v in enumerate(r.report(TS)["qddot_analytic"]["table2_analytic"]["overall"])] + [
        row("condition number of J* along the TSC run, min / max", None, f"{low:.4g} / {high:.4g}")]


entry(DISSERTATION, "Table 2", "Task-space tracking: RMS of the end-effector pose error (x, y in m, z-rotation in deg), "
      "per arm and overall.", TS, None, _table2_rows,
      TS_NOTE + " The rows 'analytic qddot_d' differentiate eq 138 with dJ*/dt instead of the backward difference "
      "(the printed rows use the backward difference, as the first rows do). Overall = RMS of the x, y and z-rotation rows. "
      "The condition number is largest at the start (every joint 0.5 deg off the stretched arms) and falls as the arms "
      "bend to 5.5 deg.")
entry(DISSERTATION, "Fig 31", "End-effector z-rotation tracking error over time, TSC.", TS,
      lambda r: rf.tracking_errors(tsc(r), jsc(r), "Dissertation fig 31: end-effector z-rotation error, TSC", (2,),
                                   ("z-rotation error (deg)",)), None, TS_NOTE)
entry(DISSERTATION, "Fig 32", "Kinematic consistency of the E-GJM, linear rates: E-GJM rates minus differentiated motion, TSC.", TS,
      lambda r: rf.kjc(r.arrays(TS, "kjc"), "Dissertation fig 32: KJC linear, TSC", (0, 1), ("vx (m/s)", "vy (m/s)")), None,
      "E-GJM rates against central differences of the recorded pose; what remains is the differences' truncation error.")
entry(DISSERTATION, "Fig 33", "Kinematic consistency of the E-GJM, angular rate, TSC.", TS,
      lambda r: rf.kjc(r.arrays(TS, "kjc"), "Dissertation fig 33: KJC angular, TSC", (2,), ("wz (deg/s)",)), None,
      "As fig 32.")
entry(DISSERTATION, "Table 3", "KJC: RMS of the E-GJM rates minus the differentiated motion (m/s, deg/s), per arm.", TS, None,
      lambda r: _table_rows(r, "table3", TABLE_3, "KJC"),
      "Central differences of the sampled pose (every 10th step of the run); what remains is the differences' "
      "truncation error, so it depends on the sampling, which the document does not state.")
entry(DISSERTATION, "Fig 34", "Joint control torques, TSC.", TS,
      lambda r: rf.per_arm({"TSC": tsc(r)}, "tau", "Dissertation fig 34: joint torques, TSC", "tau (N m)"), None, TS_NOTE)
entry(DISSERTATION, "Fig 35", "Joint trajectories, TSC.", TS,
      lambda r: rf.per_arm({"TSC": tsc(r), "JSC": jsc(r)}, "joints", "Dissertation fig 35: joints, TSC", "q (deg)", np.degrees(1.0)),
      None, TS_NOTE)
#: Table 4 as printed: per arm, joint angles (deg) at the start and the end of both runs.
TABLE_4 = {1: ([0.5] * 4, [5.5] * 4), 2: ([89.5, -0.5, -0.5, -0.5], [84.5, -5.5, -5.5, -5.5]),
           3: ([-0.5] * 4, [-5.5] * 4), 4: ([90.5, 0.5, 0.5, 0.5], [95.5, 5.5, 5.5, 5.5])}
entry(DISSERTATION, "Table 4", "Joint angles (deg) at the start and end of the JSC and TSC runs.", TS, None,
      lambda r: [row(f"{run} arm {k} {which} (deg)", ", ".join(f"{v:g}" for v in TABLE_4[k][w]),
                     ", ".join(f"{v:.4g}" for v in r.report(TS)["table4"][run][f"{which}_deg"][4 * k - 4:4 * k]))
                 for run in ("JSC", "TSC") for k in TABLE_4 for w, which in enumerate(("start", "end"))],
      "The quintic moves every joint 5 deg from 0.5 deg off the stretched posture; with --quick the runs last 0.5 s "
      "of the 5 s task, so the end is not reached.")
entry(DISSERTATION, "Table 5", "End-effector x, y (m) and z-rotation (deg) at the start and end of the runs.", TS, None,
      lambda r: [x for run in ("JSC", "TSC") for arm in range(4) for which in ("start", "end")
                 for x in _table5_rows(r, run, arm, which)],
      "Printed values are rounded to two decimals (start y 0.13 is the 0.5 deg offset). Arms 3 and 4 end at -7.78 "
      "where arms 1 and 2 end at 7.34: their -0.5 deg start breaks the mirror symmetry. Their z-rotations differ from "
      "the printed ones by 180 deg: the dissertation measures them in the arm's base frame, turned 180 deg.")
entry(DISSERTATION, "Fig 36", "Base trajectory, TSC.", TS,
      lambda r: rf.base_motion({"TSC": tsc(r), "JSC": jsc(r)}, "Dissertation fig 36: base, TSC"), None, TS_NOTE)
entry(DISSERTATION, "Fig 37", "System CoM trajectory, TSC.", TS,
      lambda r: rf.com_drift({"TSC": tsc(r), "JSC": jsc(r)}, "Dissertation fig 37: CoM drift, TSC"),
      lambda r: [row("max |CoM - CoM(0)| (m), TSC", None, float(np.linalg.norm(tsc(r)["com"] - tsc(r)["com"][0], axis=1).max()))],
      "Zero momentum: the CoM stays put to round-off on the exact plant.")
for number, offset in (("38", "0.1"), ("39", "1.0"), ("40", "0.0")):
    entry(DISSERTATION, f"Fig {number}", f"Condition number of the E-GJM along the first second from a {offset} deg start offset.", TS,
          lambda r, o=offset, n=number: rf.condition_numbers(r.report(TS)["condition_study"], f"Dissertation fig {n}: cond(J*), {o} deg", o),
          lambda r, o=offset: [row("condition number min / max", None,
                                   f"{min(r.report(TS)['condition_study'][o]['condition']):.4g} / "
                                   f"{max(r.report(TS)['condition_study'][o]['condition']):.4g}")] + (
              [row("plain inversion at 0 deg", "fails", r.report(TS)["condition_study"]["plain_inversion_at_0_deg"][:60])]
              if o == "0.0" else []),
          "At 0 deg the stretched arms are singular: the plain inversion is refused and damped least squares runs.")

# ------------------------------------------------------------------ sec 5.3: detumbling
SCENARIOS = {"45": ("detumble_impulse_arm1_joint4", "arm 1, joint 4"), "48": ("detumble_impulse_arm1_joint3", "arm 1, joint 3"),
             "51": ("detumble_impulse_arm2_joint4", "arm 2, joint 4"), "54": ("detumble_impulse_both_arms", "both arms, all joints")}
BASELINE = "detumble_impulse_baseline"


def _moved(r: Results, scene: str) -> np.ndarray:
    """Joint angles minus their start (N, n), rad."""
    joints = r.arrays("series", scene)["joints"]
    return joints - joints[0]


def _spin_rows(r: Results, scene: str) -> list[Row]:
    """Final end-effector rates on the exact plant and on the document's (FM-NIC-A, Euler at 1 ms),
    and how well the latter keeps the momentum the impulse gave."""
    exact, document = _summary(r, scene), _summary(r, scene + DOCUMENT)
    return ([row(f"{ee} final angular rate (rad/s)", None, w) for ee, w in exact["end_effector_angular_velocity_final"].items()]
            + [row(f"{ee} final angular rate (rad/s), FM-NIC-A plant", None, w)
               for ee, w in document["end_effector_angular_velocity_final"].items()]
            + [row("angular momentum balance, max (kg m^2/s), exact / FM-NIC-A plant", None,
                   f"{exact['angular_momentum_balance_max']:.3g} / {document['angular_momentum_balance_max']:.3g}")])


entry(DISSERTATION, "Fig 41", "Angular momentum after the capture impulse (500 N m for 10 ms): non-zero and constant.", "series",
      lambda r: rf.angular_momentum(r.arrays("series", "detumble_impulse_arm1_joint4"), "Dissertation fig 41: angular momentum, arm 1 joint 4"),
      lambda r: [row("L_z about the CoM at the end (kg m^2/s)", None,
                     float(r.arrays("series", "detumble_impulse_arm1_joint4")["L_com"][-1, 2])),
                 row("momentum balance, max (kg m^2/s)", None, _summary(r, "detumble_impulse_arm1_joint4")["angular_momentum_balance_max"])],
      "The document plots log |L - L0| only and prints no value; the impulse (500 N m, 5 ms linear rise, held over each "
      "1 ms period) sets L_z, which stays constant after it (balance column).")
entry(DISSERTATION, "Fig 42", "Joint angles and rates without detumbling (joints held at zero).", "series",
      lambda r: rf.angles_and_rates(r.arrays("series", BASELINE), "Dissertation fig 42: joints, no detumbling", True),
      lambda r: [row("largest |joint - start| during the capture (deg)", "near 0", float(np.degrees(np.abs(_moved(r, BASELINE)).max()))),
                 row("largest |joint - start| at the end (deg)", "near 0", float(np.degrees(np.abs(_moved(r, BASELINE)[-1]).max())))],
      "Built-in scene detumble_impulse_baseline (kp 2500, critically damped, so the posture comes back). freefloat "
      "applies the 500 N m to arm 1's last link, which it swings during the 10 ms impulse; the document applies the "
      "resultant to the system's momentum only (sec 5.3: 'the formulation does not consider the point of application').")
entry(DISSERTATION, "Fig 43", "Joint torques without detumbling.", "series",
      lambda r: rf.per_arm({"held": r.arrays("series", BASELINE)}, "tau", "Dissertation fig 43: joint torques, no detumbling", "tau (N m)"),
      lambda r: [row("peak joint torque (N m)", None, _summary(r, BASELINE)["peak_joint_torque"])],
      "freefloat holds the joints with stiffer gains (kp 2500, critically damped) than the document's Kp = 10, Kd = 100.")
entry(DISSERTATION, "Fig 44", "End-effector angles and rates without detumbling: both keep rotating together.", "series",
      lambda r: rf.angles_and_rates(r.arrays("series", BASELINE), "Dissertation fig 44: end-effectors, no detumbling", False),
      lambda r: _spin_rows(r, BASELINE), "The robot turns rigidly: both end-effectors keep the same constant rate "
      "(rows 'FM-NIC-A plant': the dissertation's own model and integrator).")
for first, (scene, label) in SCENARIOS.items():
    n = int(first)
    entry(DISSERTATION, f"Fig {n}", f"End-effector angles and rates, detumbling with {label}.", "series",
          lambda r, s=scene, t=f"Dissertation fig {n}: end-effectors, {label}": rf.angles_and_rates(r.arrays("series", s), t, False),
          lambda r, s=scene: _spin_rows(r, s) + ([row("arm 1 end-effector angle change during capture (mdeg)", 0.02,
                                                       float(1e3 * np.abs(r.arrays("series", s)["ee"][:, 0, 2] - r.arrays("series", s)["ee"][0, 0, 2]).max()))]
                                                  if s == "detumble_impulse_arm1_joint4" else []),
          "The detumbled end-effector's rate falls to round-off after the impulse on the exact plant; on the "
          "dissertation's own plant (FM-NIC-A with semi-implicit Euler at 1 ms, no substeps) the rates and the angular "
          "momentum's balance are in the rows: that model and step with non-zero momentum (docs/models.md). "
          "Its angle changes by tens of degrees "
          "during the capture, not the document's 0.02 mdeg: freefloat applies the 500 N m impulse to the last link "
          "itself (a 2 kg link, Izz 0.0277 kg m^2), which spins before the detumbling starts at 15 ms; the document's "
          "formulation takes only the resultant on the system (sec 5.3)." + (
              " Printed captions of figs 54-56 repeat 'arm 2, joint 4'; the text says two targets, all joints." if n == 54 else ""))
    entry(DISSERTATION, f"Fig {n + 1}", f"Joint angles and rates, detumbling with {label}.", "series",
          lambda r, s=scene, t=f"Dissertation fig {n + 1}: joints, {label}": rf.angles_and_rates(r.arrays("series", s), t, True),
          None, "The mission joint turns against the end-effector's spin.")
    entry(DISSERTATION, f"Fig {n + 2}", f"Joint torques, detumbling with {label}.", "series",
          lambda r, s=scene, t=f"Dissertation fig {n + 2}: joint torques, {label}": rf.per_arm({"detumbling": r.arrays("series", s)}, "tau", t, "tau (N m)"),
          lambda r, s=scene: [row("peak joint torque (N m)", None, _summary(r, s)["peak_joint_torque"])],
          "Joint 3 as mission joint needs more torque than joint 4 (figs 47 and 50), as the document says.")

# ------------------------------------------------------------------ dissertation errata
entry(DISSERTATION, "Eq 140", "Nested RMS metric: n_T printed as 500 samples.", "series", None,
      lambda r: [row("samples of a 5 s run at 1 ms (with t = 0)", 500, int(len(r.arrays("series", "sec51_exact_nidc")["t"])), "d")],
      "5 s at 1 ms gives 5000 steps (5001 samples with t = 0); freefloat's rms divides by the samples it has. "
      "With --quick the run lasts 0.5 s (501 samples).", erratum=True)
entry(DISSERTATION, "Eq 11", "Euler-rate matrix R_E as printed.", "models", None,
      lambda r: [row("max relative error of the printed R_E, 100 random angles and rates", None,
                     r.report("models")["attitude"]["eq11_printed_max_relative_error"])],
      "The printed matrix does not map XYZ Euler rates to the angular velocity; freefloat integrates the attitude on the "
      "Lie group.", erratum=True)
entry(DISSERTATION, "Sec 4.2.1", "Pivot of arm 4 printed '[-1, 75, 0, 0]'.", "series", None,
      lambda r: [row("arm 4 end-effector at the start (m)", "[-1, 75, 0, 0]",
                     ", ".join(f"{v:.4g}" for v in r.arrays("series", "sec51_exact_nidc")["ee"][0, 3, :2]))],
      "A typo for [0, -1.75, 0]: with it arm 4 ends at (0, -7.75) as the text's start posture says.", erratum=True)
entry(DISSERTATION, "Sec 5.3", "Sampling printed as '0.001 ms'.", "series", None,
      lambda r: [row("control period of the detumbling scenes (s)", "0.001 ms", float(np.diff(r.arrays("series", BASELINE)["t"][:2])[0]))],
      "1 ms, as in the earlier runs (1 s of 1000 samples).", erratum=True)
def momentum_eq_182(samples: int = 5, seed: int = 0) -> tuple[float, float]:
    """Largest relative error of the momentum about the inertial origin (6,) by eq 182 as printed
    and by the corrected form, against Pinocchio's centroidal momentum moved to the origin, at
    ``samples`` random states of the four-arm robot on a free-flyer base."""
    from ....dynamics import gjm
    from ....dynamics.reference import reference
    from ....dynamics.verify import random_state, relative_error
    from ....paths import URDF_DIR
    from ....robot.joints import JointCoordinates
    from ....robot.loading import load_robot

    robot = load_robot(URDF_DIR / "four_arm_planar.urdf", visuals=False)
    rng, coords, worst = np.random.default_rng(seed), JointCoordinates(robot), [0.0, 0.0]
    for _ in range(samples):
        q, v = random_state(robot, rng, coords)
        state, exact = gjm.compute(robot, q, v), reference(robot, q, v).momentum_origin
        for k, variant in enumerate(("printed_eq182", None)):
            value = gjm.momentum_about_origin(state, variant) if variant else gjm.momentum_about_origin(state)
            worst[k] = max(worst[k], relative_error(value, exact))
    return worst[0], worst[1]


entry(DISSERTATION, "Eq 182 (appendix B)", "Lower-right block of H0^C, the momentum about the inertial origin.", "", None,
      lambda r: [row("max relative error of the momentum about the origin, 5 random states", None,
                     "printed {:.3g} / corrected {:.3g}".format(*momentum_eq_182()))],
      "The derivation at eq 180 treats skew matrices as anticommuting; the corrected form (L_O = L_base + r0 x P) "
      "matches Pinocchio's centroidal momentum moved to the origin to round-off.", erratum=True)
entry(DISSERTATION, "Sec 3.5", "Claim that the base rows carry no non-inertial term (c0 = 0).", "models", None,
      lambda r: [row(f"max relative acceleration error, c0 = 0 / c0 = [0; v0 x P], {regime}", None,
                     f"{errors['standard_full_hdot']:.3g} / {errors['standard_corrected']:.3g}")
                 for regime, errors in r.report("models")["accuracy"]["errors"].items() if regime != "zero momentum"],
      "c0 = 0 holds only while the linear momentum is zero (or v0 x P = 0); with linear momentum the base rows need "
      "v0 x P (models study, part 1).", erratum=True)
entry(DISSERTATION, "Figs 17, 54-56", "Captions: fig 17 'ST-ST-A' for FM-ST-A; figs 54-56 repeat 'arm 2, joint 4' for the "
      "two-target scenario.", erratum=True, note="Caption typos; the entries above use the text's meaning.")

# ------------------------------------------------------------------ thesis sec 5.6
FB = "five_bar"


def five_bar_points() -> list[np.ndarray]:
    """The 5R at the start (0.07, 0.17) m: each chain's base joint, elbow and tip (3, 2), m."""
    from ....parallel.five_bar import FiveBarParameters, elbow_guess, five_bar

    p = FiveBarParameters()
    q = five_bar(p).assemble(np.array([0.07, 0.17]), elbow_guess(p, np.array([0.07, 0.17])))
    chains = []
    for side, (a, b) in ((1.0, q[2:4]), (-1.0, q[4:6])):
        base = np.array([side * p.l0, 0.0])
        elbow = base + p.l1 * np.array([side * np.cos(a), np.sin(a)])
        chains.append(np.array([base, elbow, elbow + p.l2 * np.array([side * np.cos(a + b), np.sin(a + b)])]))
    return chains


def _cases(r: Results, *names: str) -> dict[str, dict]:
    return {name: r.report(FB)["cases"][name] for name in names}


def _case_rows(r: Results, name: str, printed_error: tuple | None) -> list[Row]:
    c = r.report(FB)["cases"][name]
    rows = [row(f"{name}: max |error| after 0.2 s, {axis} (mm)", None if printed_error is None else printed_error[i],
                c["error_after_0.2s_mm"][i]) for i, axis in enumerate("xy")]
    if name.startswith("sliding"):
        rows.insert(0, row(f"{name}: reaching time of s_y, |s| < 0.02 (s)", 0.008, c["reaching_time_s"][1]))
    return rows


entry(THESIS, "Fig 6", "The 5R five-bar mechanism: two RR chains joined at a point end-effector.", "",
      lambda r: rf.five_bar_linkage(five_bar_points(), "Thesis fig 6: the 5R at (0.07, 0.17) m", ("chain 1", "chain 2")),
      lambda r: [row("tips of both chains (m)", "(0.07, 0.17)", "; ".join(", ".join(f"{v:.6f}" for v in c[-1]) for c in five_bar_points()))],
      "Base joints at x = +-l0 = +-0.05 m (l0 is not printed; the author's code uses 0.05 m).")
entry(THESIS, "Fig 7", "One RR serial chain (links l1, l2, joints q1, q2).", "",
      lambda r: rf.five_bar_linkage(five_bar_points()[:1], "Thesis fig 7: chain 1 (RR)", ("chain 1",)),
      lambda r: [row("link lengths l1, l2 (m)", "0.12, 0.15", ", ".join(f"{np.linalg.norm(np.diff(five_bar_points()[0], axis=0), axis=1)[i]:.4g}" for i in range(2)))])
entry(THESIS, "Table 2", "Denavit-Hartenberg parameters of the RR chain: a = l_i, alpha = 0, d = 0, theta = q_i.", "", None,
      lambda r: [row("a1, a2 (m)", "l1, l2 = 0.12, 0.15", ", ".join(f"{np.linalg.norm(np.diff(five_bar_points()[0], axis=0), axis=1)[i]:.4g}" for i in range(2))),
                 row("alpha, d", "0, 0", "0, 0 (a planar chain)")])
CIRCLE = np.column_stack((0.07 * np.cos(np.linspace(0, 2 * np.pi, 400)), 0.17 + 0.07 * np.sin(np.linspace(0, 2 * np.pi, 400))))


def _distance(points: list, path: np.ndarray = CIRCLE) -> float:
    """Smallest distance (m) from ``path`` (M, 2) to ``points`` (K, 2); inf without points."""
    points = np.asarray(points, float).reshape(-1, 2)
    return float(np.linalg.norm(path[:, None] - points[None], axis=2).min()) if len(points) else float("inf")


def _workspace_rows(r: Results) -> list[Row]:
    fb, threshold = r.report(FB), r.report(FB)["settings"]["max_condition"]
    w, sing = fb["workspace"], fb["singularities"]
    cell = (w["x"][1] - w["x"][0]) * (w["y"][1] - w["y"][0])
    reached = sum(v is not None for rw in w["condition"] for v in rw)
    return [row("workspace area (m^2), exact / grid cells reached", None,
                f"{sing['area_m2']:.4g} / {2 * reached * cell:.4g} (the grid covers y > 0; doubled by symmetry)"),
            row("non-singular grid points (condition < threshold)", None,
                int(sum(v is not None and v < threshold for rw in w["condition"] for v in rw))),
            row("threshold on cond(A°), cond(C^T U)", "not stated", threshold),
            row(f"circle's distance to the type II locus of mode {sing['mode']} (m)", None, _distance(sing["loci"].get("II", []))),
            row("circle's distance to the workspace boundary (m)", None,
                _distance([pt for arc in sing["boundary"] for pt in arc["points"]]))]


entry(THESIS, "Fig 8", "Workspace of the 5R: out of reach, near-singular and non-singular regions and the reference circle.", FB,
      lambda r: rf.workspace(r.report(FB)["workspace"], r.report(FB)["settings"]["max_condition"], CIRCLE,
                             "Thesis fig 8: 5R workspace", r.report(FB)["singularities"]),
      _workspace_rows,
      "Exact boundary in closed form and the singularity loci of the circle's working mode bisected from a grid "
      "(freefloat.parallel.maps), over the conditioning grid of the gain design. The thesis draws its near-singular "
      "region without a threshold; freefloat's is 6. With --quick the grids are 3 cm, else 1 cm (loci from 2 cm).")
entry(THESIS, "Eq 187", "Worst-case sliding-mode gains over the non-singular grid and the 64 extreme parameter sets (eta = 20).", FB, None,
      lambda r: [row(f"{key} {axis}", r.report(FB)["eq_187"][key][i], r.report(FB)["gains"][key][i])
                 for key in ("n", "xdot2", "xdot_ydot", "ydot2") for i, axis in enumerate("xy")],
      "The gains depend on the grid and its singularity threshold, which the thesis does not state.")
entry(THESIS, "Fig 9", "The saturation tanh(100 s) that replaces sign(s).", "", lambda r: rf.saturation("Thesis fig 9: tanh(100 s)"),
      lambda r: [row("f_sat(0.023)", 0.98, float(np.tanh(100 * 0.023))), row("f_sat'(0)", 100.0, float(100 * (1 - np.tanh(0.0) ** 2)))])
#: Thesis figs 10-25 by first figure: the cases drawn (the first is the thesis's), the parameter
#: error of its plant, the printed peak errors x, y (mm) if any, and the note.
FIVE_BAR_GROUPS = {
    10: (("sliding mode, 15 %", "sliding mode, eq 187's gains, 15 %"), "15 %", None,
         "Circle of eq 189 from (0.07, 0.17) at rest, lambda = 40, tanh(100 s): freefloat's gains over its grid, and "
         "eq 187's printed gains, with which s_y is reached in the document's ~0.008 s."),
    16: (("sliding mode, 50 %",), "50 %", None, "As figs 10-15 with the plant 50 % off; the errors stay in the "
         "hundredths of a millimetre, as the document says."),
    22: (("computed torque, 15 %", "computed torque, 50 %"), "15 %", (12.0, 27.0),
         "Computed torque (eq 190, lambda = 40, critically damped). The document's peaks (12 / 27 mm) match freefloat's "
         "run with the parameters 50 % off, not the 15 % the text states."),
}
for first, (cases, level, printed, note) in FIVE_BAR_GROUPS.items():
    law = "computed torque (eq 190)" if cases[0].startswith("computed") else "sliding mode"
    numbers = [("torque_Nm", 0, "actuator 1 torque (N m)"), ("torque_Nm", 1, "actuator 2 torque (N m)"),
               ("e_mm", 0, "error x (mm)"), ("e_mm", 1, "error y (mm)")]
    if law == "sliding mode":
        numbers += [("s", 0, "s_x (m/s)"), ("s", 1, "s_y (m/s)")]
    for k, (key, col, what) in enumerate(numbers):
        entry(THESIS, f"Fig {first + k}", f"{what.split(' (')[0].capitalize()}, {law}, parameters {level} off."
              + (" (Printed caption says 'x' for fig 19.)" if first + k == 19 else ""), FB,
              lambda r, key=key, col=col, what=what, cases=cases, n=first + k: rf.five_bar_series(
                  _cases(r, *cases), key, col, f"Thesis fig {n}: {what}", what, symlog=1e-3 if key != "torque_Nm" else None),
              (lambda r, cases=cases, printed=printed: [x for c in cases for x in _case_rows(r, c, printed)]) if k == 0 else None,
              note if k == 0 else "")
entry(THESIS, "Eq 142", "Tracking error printed as e = qddot_d - q.", FB, None,
      lambda r: [row("s(0) = -(edot + lambda e) at the start (m/s)", "[0, -2] (sec 5.6 text)",
                     ", ".join(f"{v:.3g}" for v in r.report(FB)["cases"]["sliding mode, 15 %"]["s"][0])),
                 row("s_x(0) with the printed e", "[0, -2]", f"{-40.0 * (-0.07 * 28.57 ** 2 - 0.07):.4g}")],
      "With e = q_d - q the start gives the s(0) = [0, -2] the text states; with the printed e it would not.", erratum=True)
entry(THESIS, "Eq 22", "DH matrix entry (1,3) printed sin(theta) cos(alpha).", "", None,
      lambda r: [row("entry (1,3) at theta = alpha = 30 deg", float(np.sin(np.pi / 6) * np.cos(np.pi / 6)), float(np.sin(np.pi / 6) ** 2))],
      "The standard matrix has sin(theta) sin(alpha); for the 5R (alpha = 0) both vanish, so its results do not depend on it.",
      erratum=True)
