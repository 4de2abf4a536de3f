"""The dissertation's entries in the report (chapters 4-5: figs 6-56, tables 1-5, then its errata),
in its order: :data:`ENTRIES`.

Each entry is declared once; the figures that differ only by their controller, run or start offset
(figs 9-19, 38-40, 45-56) come from one function each. What the dissertation prints is in
:mod:`..printed`; what the report computes itself, in :mod:`.checks`.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from ....documents import DIRECTION, FIGS_38_40_OFFSET_DEG, TASK_DEG
from .. import printed
from ..series_report import BASELINE_DOCUMENT_GAINS, DOCUMENT, RESULTANT
from . import figures as rf
from .checks import external_forces_eqs_95_99, momentum_eq_182, summed_arms_eqs_109_115
from .entry import DISSERTATION, Entry, Row, row
from .results import Results

# ------------------------------------------------------------------ chapter 4 / sec 5.1
#: The sec-5.1 runs of each controller: on the exact plant (RKMK4) and on FM-NIC-A (the document's).
SEC51 = {"FM-NIC-A": ("sec51_exact_nidc", "sec51_nidc_nidc"), "FM-ST-A": ("sec51_exact_standard", "sec51_nidc_standard")}
#: The dissertation's controller names -> freefloat's model names.
CONTROLLER_MODELS = {"FM-NIC-A": "nidc", "FM-ST-A": "standard"}
SEC51_NOTE = ("In this scene the base does not turn and the momentum is zero, so the FM-NIC-A, FM-ST-A and exact "
              "models describe the same motion; the tracking error is set by the integrator (semi-implicit Euler "
              "against RKMK4) and by the zero-order hold of the torques, not by the controller's model. Table 1's "
              "236-fold gap between the two controllers is not reproduced (docs/models.md).")


def sec51(res: Results, controller: str) -> dict[str, dict]:
    """The sec-5.1 runs with ``controller``'s model: on the exact plant and on FM-NIC-A."""
    exact, document = SEC51[controller]
    return {"exact plant (RKMK4)": res.arrays("series", exact),
            "FM-NIC-A plant (semi-implicit Euler)": res.arrays("series", document)}


def _summary(res: Results, run: str) -> dict:
    return res.report("series")["runs"][run]


def _start_rows(res: Results) -> list[Row]:
    ee = res.arrays("series", "sec51_exact_nidc")["ee"]
    return [row(f"arm {k + 1} end-effector x, y (m)", p, ", ".join(f"{v:.4g}" for v in ee[0, k, :2]))
            for k, p in enumerate(printed.FIG_6_END_EFFECTORS)]


def _reference_rows(res: Results) -> list[Row]:
    reference = res.arrays("series", "sec51_exact_nidc")["joint_reference"]
    return [row(f"arm {k + 1} reference displacement (deg)", TASK_DEG * DIRECTION[4 * k],
                float(np.degrees(np.mean(np.diff(reference[[0, -1], 4 * k:4 * k + 4], axis=0)))))
            for k in range(4)]


def _sec51_rms_rows(res: Results, controller: str) -> list[Row]:
    value = printed.TABLE_1[CONTROLLER_MODELS[controller]][-1]
    exact, document = SEC51[controller]
    return [row("nested RMS overall (rad), exact plant", value, _summary(res, exact)["tracking_rms_overall"]),
            row("nested RMS overall (rad), FM-NIC-A plant", value, _summary(res, document)["tracking_rms_overall"])]


def _table_1_rows(res: Results) -> list[Row]:
    def ours(controller: str, k: int) -> float:
        run = _summary(res, SEC51[controller][1])
        return run["tracking_rms_overall"] if k == 4 else list(run["tracking_rms_per_arm"].values())[k]

    return ([row(f"{c}, {'overall' if k == 4 else f'arm {k + 1}'}", printed.TABLE_1[m][k], ours(c, k))
             for c, m in CONTROLLER_MODELS.items() for k in range(5)]
            + [row("FM-ST-A / FM-NIC-A, overall", printed.TABLE_1_RATIO, ours("FM-ST-A", 4) / ours("FM-NIC-A", 4))]
            + _sec51_rms_rows(res, "FM-NIC-A")[:1])


def _torque_rows(res: Results, controller: str) -> list[Row]:
    return [row("peak joint torque (N m), exact plant", None, _summary(res, SEC51[controller][0])["peak_joint_torque"])]


def _end_rows(res: Results, controller: str) -> list[Row]:
    ee = res.arrays("series", SEC51[controller][0])["ee"]
    return [row(f"arm {k + 1} end-effector end x, y (m)", None, ", ".join(f"{v:.4g}" for v in ee[-1, k, :2]))
            for k in range(4)]


def _base_rows(res: Results, controller: str) -> list[Row]:
    run = res.arrays("series", SEC51[controller][0])
    dx, dy, _ = run["base"][-1] - run["base"][0]
    return [row("base displacement x, y (m), exact plant", "along the (-x, -y) bisector", f"{dx:.4g}, {dy:.4g}"),
            row("largest |base yaw| (deg)", "~0", float(np.abs(run["base"][:, 2]).max()))]


def _com_rows(res: Results, controller: str) -> list[Row]:
    exact, document = SEC51[controller]
    return [row("max CoM drift (m), exact plant", printed.COM_DRIFT_M, _summary(res, exact)["com_drift_max"]),
            row("max CoM drift (m), FM-NIC-A plant", printed.COM_DRIFT_M, _summary(res, document)["com_drift_max"])]


def _errors_figure(res: Results, controller: str, title: str):
    return rf.joint_errors(sec51(res, controller), f"{title}: joint tracking errors, controller {controller}")


def _torques_figure(res: Results, controller: str, title: str):
    return rf.per_arm(sec51(res, controller), "tau", f"{title}: joint torques, controller {controller}", "tau (N m)")


def _paths_figure(res: Results, controller: str, title: str):
    return rf.ee_paths(sec51(res, controller), f"{title}: end-effector paths, controller {controller}")


def _base_figure(res: Results, controller: str, title: str):
    return rf.base_motion(sec51(res, controller), f"{title}: base CoM and yaw, controller {controller}")


def _final_figure(res: Results, controller: str, title: str):
    return rf.configuration(res.arrays("series", "sec51_exact_nidc")["skeleton_end"], f"{title}: final posture")


def _com_figure(res: Results, controller: str, title: str):
    return rf.com_drift(sec51(res, controller), f"{title}: CoM drift, controller {controller}")


#: What figs 9-19 show, by kind: the caption (without its full stop), the figure and the rows
#: (``(results, controller)``), and the note.
SEC51_KINDS = {
    "errors": ("Joint tracking errors, controller {}", _errors_figure, _sec51_rms_rows, SEC51_NOTE),
    "torques": ("Joint control torques, controller {}", _torques_figure, _torque_rows,
                "The document prints no torque values; the curves are the computed torque of the quintic."),
    "paths": ("End-effector trajectories, controller {}", _paths_figure, _end_rows,
              "The document prints no end values for this run (Table 5 is sec 5.2's)."),
    "base": ("Base trajectory, controller {}", _base_figure, _base_rows,
             "Sec 4.2.2 expects the base to translate along the (-x, -y) bisector with no rotation: both hold "
             "(x = y displacement, yaw at round-off)."),
    "final": ("Final posture of the four-arm robot", _final_figure, None,
              "The arms turned by the quintic's 5 deg; the base moved along the bisector."),
    "com": ("System CoM trajectory, controller {}", _com_figure, _com_rows,
            "The dissertation's ~1e-7 m drift 'by the sequential base/joint update' is integration error: it falls "
            "to round-off with RKMK4 on the exact plant."),
}


def sec51_figure(number: int, controller: str, kind: str, ending: str = ".") -> Entry:
    """Fig ``number``, of kind ``kind`` (:data:`SEC51_KINDS`), for ``controller``'s runs."""
    caption, draw, rows, note = SEC51_KINDS[kind]
    return Entry(DISSERTATION, f"Fig {number}", caption.format(controller) + ending, "series",
                 partial(draw, controller=controller, title=f"Dissertation fig {number}"),
                 rows and partial(rows, controller=controller), note)


# ------------------------------------------------------------------ sec 5.2: joint-space and task-space runs
TS = "task_space"
TS_NOTE = ("Exact plant, RKMK4 at 0.1 ms. The dissertation simulated FM-NIC-A, which describes the same motion as "
           "the exact plant when the momentum is zero and the base does not turn (the models study: on sec 5.1's task every "
           "plant gives the same tracking error with the same integrator; here the base yaw "
           "stays below 3e-11 deg), so only the exact plant is run. The start is every joint 0.5 deg off the stretched "
           "posture along the motion (Table 4).")


def jsc(r: Results) -> dict:
    return r.arrays(TS, "jsc")


def tsc(r: Results) -> dict:
    return r.arrays(TS, "tsc")


def _table_rows(r: Results, table: str, values: dict, label: str) -> list[Row]:
    ours = r.report(TS)[table]
    return [row(f"{label} {key}, arm {k + 1}", values[key][k], ours[key][k]) for key in ("x", "y", "z_deg", "overall")
            for k in range(4)]


def _table_2_rows(r: Results) -> list[Row]:
    low, high = r.report(TS)["tsc_condition_range"]
    document, feedback = r.report(TS)["table2_document_setting"], r.report(TS)["table2_position_feedback"]
    return _table_rows(r, "table2", printed.TABLE_2, "RMS error") + [
        row(f"overall, arm {k + 1}, analytic qddot_d", printed.TABLE_2["overall"][k], v)
        for k, v in enumerate(r.report(TS)["qddot_analytic"]["table2_analytic"]["overall"])] + [
        row(f"overall, arm {k + 1}, document's setting", printed.TABLE_2["overall"][k], v)
        for k, v in enumerate(document["table2"]["overall"])] + [
        row("document's setting: its JSC end-effector path from the exact plant's, max (m)", None,
            document["jsc_distance_from_exact_max_m"])] + [
        row(f"overall, arm {k + 1}, position feedback (K_x = {feedback['kx']:g} 1/s)", printed.TABLE_2["overall"][k], v)
        for k, v in enumerate(feedback["table2"]["overall"])] + [
        row("end-effector distance from the JSC path at the end (m), eq 139 open loop / position feedback", None,
            "{open_loop:.3g} / {position_feedback:.3g}".format(**feedback["final_distance_m"]))] + [
        row("condition number of J* along the TSC run, min / max", None, f"{low:.4g} / {high:.4g}")]


def _table_4_rows(r: Results) -> list[Row]:
    return [row(f"{run} arm {k} {which} (deg)", ", ".join(f"{v:g}" for v in printed.TABLE_4[k][w]),
                ", ".join(f"{v:.4g}" for v in r.report(TS)["table4"][run][f"{which}_deg"][4 * k - 4:4 * k]))
            for run in ("JSC", "TSC") for k in printed.TABLE_4 for w, which in enumerate(("start", "end"))]


def _table_5_rows(r: Results) -> list[Row]:
    out = []
    for run in ("JSC", "TSC"):
        for arm in range(4):
            for w, which in enumerate(("start", "end")):
                ours = r.report(TS)["table5"][run][which][arm]
                out += [row(f"{run} arm {arm + 1} {which} {c}", p, o)
                        for c, p, o in zip(("x (m)", "y (m)", "z-rotation (deg)"), printed.TABLE_5[f"arm{arm + 1}"][w], ours)]
    return out


def _com_motion_rows(r: Results) -> list[Row]:
    return [row("max |CoM - CoM(0)| (m), TSC", None, float(np.linalg.norm(tsc(r)["com"] - tsc(r)["com"][0], axis=1).max()))]


def _condition_rows(r: Results, offset: str) -> list[Row]:
    study = r.report(TS)["condition_study"]
    rows = [row("condition number min / max", None,
                f"{min(study[offset]['condition']):.4g} / {max(study[offset]['condition']):.4g}")]
    return rows + ([row("plain inversion at 0 deg", "fails", study["plain_inversion_at_0_deg"][:60])]
                   if offset == "0.0" else [])


def condition_figure(number: int, offset_deg: float) -> Entry:
    """Figs 38-40: the condition number of the E-GJM from a start offset of ``offset_deg``."""
    offset = str(offset_deg)
    return Entry(DISSERTATION, f"Fig {number}", f"Condition number of the E-GJM along the first second from a {offset} "
                 "deg start offset.", TS,
                 lambda r: rf.condition_numbers(r.report(TS)["condition_study"],
                                                f"Dissertation fig {number}: cond(J*), {offset} deg", offset),
                 partial(_condition_rows, offset=offset),
                 "At 0 deg the stretched arms are singular: the plain inversion is refused and damped least squares runs.")


# ------------------------------------------------------------------ sec 5.3: detumbling
#: The detumbling scenarios of figs 45-56, by first figure: the built-in scene and what it detumbles with.
SCENARIOS = {45: ("detumble_impulse_arm1_joint4", "arm 1, joint 4"), 48: ("detumble_impulse_arm1_joint3", "arm 1, joint 3"),
             51: ("detumble_impulse_arm2_joint4", "arm 2, joint 4"), 54: ("detumble_impulse_both_arms", "both arms, all joints")}
BASELINE = "detumble_impulse_baseline"
DETUMBLING_NOTE = (
    "The detumbled end-effector's rate falls to round-off after the impulse on the exact plant; on the "
    "dissertation's own plant (FM-NIC-A with semi-implicit Euler at 1 ms, no substeps) the rates and the angular "
    "momentum's balance are in the rows: that model and step with non-zero momentum (docs/models.md). "
    "Its angle changes by tens of degrees "
    "during the capture, not the document's 0.02 mdeg: freefloat applies the 500 N m impulse to the last link "
    "itself (a 2 kg link, Izz 0.0277 kg m^2), which spins before the detumbling starts at 15 ms; the document's "
    "formulation takes only the resultant on the system (sec 5.3). Applied that way (the couple on the base, "
    "where it changes the momentum by the same impulse and puts no generalised force on the joints: run "
    "'<scene>_resultant') the change falls by over an order of magnitude, still far above the printed 0.02 mdeg.")


def _moved(r: Results, scene: str) -> np.ndarray:
    """Joint angles minus their start (N, n), rad."""
    joints = r.arrays("series", scene)["joints"]
    return joints - joints[0]


def _baseline_joint_rows(r: Results) -> list[Row]:
    """Fig 42: the largest joint excursion during the run and at its end, held with kp = 2500 (the
    scene) and with the document's Kp = 10, Kd = 100."""
    rows = []
    for scene, gains in ((BASELINE, ""), (BASELINE_DOCUMENT_GAINS, ", document's gains")):
        moved = np.degrees(np.abs(_moved(r, scene)))
        rows += [row(f"largest |joint - start| during the run (deg){gains}", "near 0", float(moved.max())),
                 row(f"largest |joint - start| at the end (deg){gains}", "near 0", float(moved[-1].max()))]
    return rows


def _spin_rows(r: Results, scene: str) -> list[Row]:
    """Final end-effector rates on the exact plant and on the document's (FM-NIC-A, Euler at 1 ms),
    and how well the latter keeps the momentum the impulse gave."""
    exact, document = _summary(r, scene), _summary(r, scene + DOCUMENT)
    return ([row(f"{ee} final angular rate (rad/s)", None, w) for ee, w in exact["end_effector_angular_velocity_final"].items()]
            + [row(f"{ee} final angular rate (rad/s), FM-NIC-A plant", None, w)
               for ee, w in document["end_effector_angular_velocity_final"].items()]
            + [row("angular momentum balance, max (kg m^2/s), exact / FM-NIC-A plant", None,
                   f"{exact['angular_momentum_balance_max']:.3g} / {document['angular_momentum_balance_max']:.3g}")])


def _detumbled_rows(r: Results, scene: str) -> list[Row]:
    """:func:`_spin_rows`, and for arm 1 joint 4 the end-effector's angle change during the capture
    with the couple on the last link (the scene) and on the base (the document's resultant)."""
    if scene != "detumble_impulse_arm1_joint4":
        return _spin_rows(r, scene)
    rows = _spin_rows(r, scene)
    for run, how in ((scene, ""), (scene + RESULTANT, ", couple on the base (the document's resultant)")):
        ee = r.arrays("series", run)["ee"]
        rows.append(row(f"arm 1 end-effector angle change during capture (mdeg){how}", printed.CAPTURE_ANGLE_CHANGE_MDEG,
                        float(1e3 * np.abs(ee[:, 0, 2] - ee[0, 0, 2]).max())))
    return rows


def detumbling_figures(first: int, scene: str, label: str) -> tuple[Entry, Entry, Entry]:
    """Figs ``first`` to ``first + 2``: end-effectors, joints and torques of the detumbling ``scene``."""
    angles = "Dissertation fig {}: {}, " + label
    return (
        Entry(DISSERTATION, f"Fig {first}", f"End-effector angles and rates, detumbling with {label}.", "series",
              lambda r: rf.angles_and_rates(r.arrays("series", scene), angles.format(first, "end-effectors"), False),
              partial(_detumbled_rows, scene=scene),
              DETUMBLING_NOTE + (" Printed captions of figs 54-56 repeat 'arm 2, joint 4'; the text says two targets, "
                                 "all joints." if first == 54 else "")),
        Entry(DISSERTATION, f"Fig {first + 1}", f"Joint angles and rates, detumbling with {label}.", "series",
              lambda r: rf.angles_and_rates(r.arrays("series", scene), angles.format(first + 1, "joints"), True),
              None, "The mission joint turns against the end-effector's spin."),
        Entry(DISSERTATION, f"Fig {first + 2}", f"Joint torques, detumbling with {label}.", "series",
              lambda r: rf.per_arm({"detumbling": r.arrays("series", scene)}, "tau",
                                   angles.format(first + 2, "joint torques"), "tau (N m)"),
              lambda r: [row("peak joint torque (N m)", None, _summary(r, scene)["peak_joint_torque"])],
              "Joint 3 as mission joint needs more torque than joint 4 (figs 47 and 50), as the document says."),
    )


# ------------------------------------------------------------------ the entries
ENTRIES: tuple[Entry, ...] = (
    Entry(DISSERTATION, "Fig 6", "Start posture of the four-arm robot: arms stretched along +x, +y, -x, -y.", "series",
          lambda r: rf.configuration(r.arrays("series", "sec51_exact_nidc")["skeleton_start"],
                                     "Dissertation fig 6: start posture"), _start_rows),
    Entry(DISSERTATION, "Fig 7", "Flowchart of the joint-space simulation loop (dynamic matrices, control law, model "
          "update).", note="A diagram, no data: freefloat's one loop (plant x integrator x controller) is described in "
          "docs/architecture.md; nothing to compare."),
    Entry(DISSERTATION, "Fig 8", "Joint reference trajectories: quintic polynomials, 5 deg in 5 s.", "series",
          lambda r: rf.per_arm({"reference": r.arrays("series", "sec51_exact_nidc")}, "joint_reference",
                               "Dissertation fig 8: joint references", "q_d (deg)", np.degrees(1.0)),
          _reference_rows, "With --quick the run and the quintic last 0.5 s, so the displacement reached is the same "
          "5 deg in a tenth of the time."),
    *(sec51_figure(n, "FM-NIC-A", kind) for n, kind in zip(range(9, 15), ("errors", "torques", "paths", "base", "final",
                                                                          "com"))),
    sec51_figure(15, "FM-ST-A", "errors"),
    sec51_figure(16, "FM-ST-A", "torques"),
    Entry(DISSERTATION, "Table 1", "Nested RMS joint tracking error (eq 140) per arm and overall, plant FM-NIC-A, "
          "controllers FM-NIC-A and FM-ST-A.", "series", None, _table_1_rows, SEC51_NOTE),
    sec51_figure(17, "FM-ST-A", "paths", " (printed 'ST-ST-A')."),
    sec51_figure(18, "FM-ST-A", "base"),
    sec51_figure(19, "FM-ST-A", "com"),
    Entry(DISSERTATION, "Fig 20", "Joint trajectories, joint-space control (JSC).", TS,
          lambda r: rf.per_arm({"JSC": jsc(r)}, "joints", "Dissertation fig 20: joints, JSC", "q (deg)", np.degrees(1.0)),
          None, TS_NOTE),
    Entry(DISSERTATION, "Fig 21", "End-effector paths in the plane, JSC.", TS,
          lambda r: rf.ee_paths({"JSC": jsc(r)}, "Dissertation fig 21: end-effector paths, JSC"), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 22", "End-effector x and y over time, JSC.", TS,
          lambda r: rf.ee_components({"JSC": jsc(r)}, "Dissertation fig 22: end-effector x, y, JSC", (0, 1),
                                     ("x (m)", "y (m)")), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 23", "End-effector z-rotation over time, JSC.", TS,
          lambda r: rf.ee_components({"JSC": jsc(r)}, "Dissertation fig 23: end-effector z-rotation, JSC", (2,),
                                     ("z-rotation (deg)",)), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 24", "Base trajectory, JSC.", TS,
          lambda r: rf.base_motion({"JSC": jsc(r)}, "Dissertation fig 24: base, JSC"), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 25", "Joint control torques, JSC.", TS,
          lambda r: rf.per_arm({"JSC": jsc(r)}, "tau", "Dissertation fig 25: joint torques, JSC", "tau (N m)"),
          None, TS_NOTE),
    Entry(DISSERTATION, "Fig 26", "End-effector paths in the plane, task-space control (TSC).", TS,
          lambda r: rf.ee_paths({"TSC": tsc(r), "JSC (reference)": jsc(r)}, "Dissertation fig 26: end-effector paths, "
                                "TSC"), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 27", "End-effector x and y over time, TSC.", TS,
          lambda r: rf.ee_components({"TSC": tsc(r)}, "Dissertation fig 27: end-effector x, y, TSC", (0, 1),
                                     ("x (m)", "y (m)")), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 28", "End-effector z-rotation over time, TSC.", TS,
          lambda r: rf.ee_components({"TSC": tsc(r)}, "Dissertation fig 28: end-effector z-rotation, TSC", (2,),
                                     ("z-rotation (deg)",)), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 29", "End-effector position tracking error in the plane (x error against y error), TSC.",
          TS, lambda r: rf.ee_plane_errors(tsc(r), jsc(r), "Dissertation fig 29: end-effector position error, TSC"),
          None, TS_NOTE),
    Entry(DISSERTATION, "Fig 30", "End-effector x and y tracking errors over time, TSC.", TS,
          lambda r: rf.tracking_errors(tsc(r), jsc(r), "Dissertation fig 30: end-effector x, y errors, TSC", (0, 1),
                                       ("x error (m)", "y error (m)")), None, TS_NOTE),
    Entry(DISSERTATION, "Table 2", "Task-space tracking: RMS of the end-effector pose error (x, y in m, z-rotation in "
          "deg), per arm and overall.", TS, None, _table_2_rows,
          TS_NOTE + " The rows 'analytic qddot_d' differentiate eq 138 with dJ*/dt instead of the backward difference "
          "(the printed rows use the backward difference, as the first rows do). The rows 'document's setting' run "
          "both runs as the dissertation does: plant FM-NIC-A with its semi-implicit Euler, both laws on FM-ST-A "
          "(the first rows: exact plant, RKMK4, exact laws); neither setting gives the printed 3.1e-4. The rows 'position "
          "feedback' add K_x times the end-effector pose error to the rates before the inversion (sec 4.4's "
          "position-level route); the printed law integrates eq 139 open loop. Overall = RMS of the x, y and z-rotation "
          "rows. The condition number is largest at the start (every joint 0.5 deg off the stretched arms) and falls as "
          "the arms bend to 5.5 deg."),
    Entry(DISSERTATION, "Fig 31", "End-effector z-rotation tracking error over time, TSC.", TS,
          lambda r: rf.tracking_errors(tsc(r), jsc(r), "Dissertation fig 31: end-effector z-rotation error, TSC", (2,),
                                       ("z-rotation error (deg)",)), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 32", "Kinematic consistency of the E-GJM, linear rates: E-GJM rates minus differentiated "
          "motion, TSC.", TS,
          lambda r: rf.kjc(r.arrays(TS, "kjc"), "Dissertation fig 32: KJC linear, TSC", (0, 1), ("vx (m/s)", "vy (m/s)")),
          None, "E-GJM rates against central differences of the recorded pose; what remains is the differences' "
          "truncation error."),
    Entry(DISSERTATION, "Fig 33", "Kinematic consistency of the E-GJM, angular rate, TSC.", TS,
          lambda r: rf.kjc(r.arrays(TS, "kjc"), "Dissertation fig 33: KJC angular, TSC", (2,), ("wz (deg/s)",)), None,
          "As fig 32."),
    Entry(DISSERTATION, "Table 3", "KJC: RMS of the E-GJM rates minus the differentiated motion (m/s, deg/s), per arm.",
          TS, None, lambda r: _table_rows(r, "table3", printed.TABLE_3, "KJC"),
          "Central differences of the sampled pose (every 10th step of the run); what remains is the differences' "
          "truncation error, so it depends on the sampling, which the document does not state."),
    Entry(DISSERTATION, "Fig 34", "Joint control torques, TSC.", TS,
          lambda r: rf.per_arm({"TSC": tsc(r)}, "tau", "Dissertation fig 34: joint torques, TSC", "tau (N m)"), None,
          TS_NOTE),
    Entry(DISSERTATION, "Fig 35", "Joint trajectories, TSC.", TS,
          lambda r: rf.per_arm({"TSC": tsc(r), "JSC": jsc(r)}, "joints", "Dissertation fig 35: joints, TSC", "q (deg)",
                               np.degrees(1.0)), None, TS_NOTE),
    Entry(DISSERTATION, "Table 4", "Joint angles (deg) at the start and end of the JSC and TSC runs.", TS, None,
          _table_4_rows, "The quintic moves every joint 5 deg from 0.5 deg off the stretched posture; with --quick the "
          "runs last 0.5 s of the 5 s task, so the end is not reached."),
    Entry(DISSERTATION, "Table 5", "End-effector x, y (m) and z-rotation (deg) at the start and end of the runs.", TS,
          None, _table_5_rows, "Printed values are rounded to two decimals (start y 0.13 is the 0.5 deg offset). Arms 3 "
          "and 4 end at -7.78 where arms 1 and 2 end at 7.34: their -0.5 deg start breaks the mirror symmetry. Their "
          "z-rotations differ from the printed ones by 180 deg: the dissertation measures them in the arm's base frame, "
          "turned 180 deg."),
    Entry(DISSERTATION, "Fig 36", "Base trajectory, TSC.", TS,
          lambda r: rf.base_motion({"TSC": tsc(r), "JSC": jsc(r)}, "Dissertation fig 36: base, TSC"), None, TS_NOTE),
    Entry(DISSERTATION, "Fig 37", "System CoM trajectory, TSC.", TS,
          lambda r: rf.com_drift({"TSC": tsc(r), "JSC": jsc(r)}, "Dissertation fig 37: CoM drift, TSC"),
          _com_motion_rows, "Zero momentum: the CoM stays put to round-off on the exact plant."),
    *(condition_figure(number, offset) for number, offset in FIGS_38_40_OFFSET_DEG.items()),
    Entry(DISSERTATION, "Fig 41", "Angular momentum after the capture impulse (500 N m for 10 ms): non-zero and "
          "constant.", "series",
          lambda r: rf.angular_momentum(r.arrays("series", "detumble_impulse_arm1_joint4"),
                                        "Dissertation fig 41: angular momentum, arm 1 joint 4"),
          lambda r: [row("L_z about the CoM at the end (kg m^2/s)", None,
                         float(r.arrays("series", "detumble_impulse_arm1_joint4")["L_com"][-1, 2])),
                     row("momentum balance, max (kg m^2/s)", None,
                         _summary(r, "detumble_impulse_arm1_joint4")["angular_momentum_balance_max"])],
          "The document plots log |L - L0| only and prints no value; the impulse (500 N m, 5 ms linear rise, held over "
          "each 1 ms period) sets L_z, which stays constant after it (balance column)."),
    Entry(DISSERTATION, "Fig 42", "Joint angles and rates without detumbling (joints held at zero).", "series",
          lambda r: rf.angles_and_rates(r.arrays("series", BASELINE), "Dissertation fig 42: joints, no detumbling", True),
          _baseline_joint_rows,
          "Built-in scene detumble_impulse_baseline (kp 2500, critically damped, so the posture comes back). freefloat "
          "applies the 500 N m to arm 1's last link, which it swings during the 10 ms impulse; the document applies the "
          "resultant to the system's momentum only (sec 5.3: 'the formulation does not consider the point of "
          "application'). With the document's own gains (Kp = 10, Kd = 100: a pole near kp/kd = 0.1 1/s) the swung "
          "joints stay tens of degrees away at the end (rows 'document's gains')."),
    Entry(DISSERTATION, "Fig 43", "Joint torques without detumbling.", "series",
          lambda r: rf.per_arm({"held": r.arrays("series", BASELINE)}, "tau",
                               "Dissertation fig 43: joint torques, no detumbling", "tau (N m)"),
          lambda r: [row("peak joint torque (N m)", None, _summary(r, BASELINE)["peak_joint_torque"]),
                     row("peak joint torque (N m), document's gains", None,
                         _summary(r, BASELINE_DOCUMENT_GAINS)["peak_joint_torque"])],
          "freefloat holds the joints with stiffer gains (kp 2500, critically damped) than the document's Kp = 10, "
          "Kd = 100; the second row is the same run with the document's gains."),
    Entry(DISSERTATION, "Fig 44", "End-effector angles and rates without detumbling: both keep rotating together.",
          "series",
          lambda r: rf.angles_and_rates(r.arrays("series", BASELINE), "Dissertation fig 44: end-effectors, no detumbling",
                                        False),
          lambda r: _spin_rows(r, BASELINE) + [
              row(f"{ee} final angular rate (rad/s), document's gains", None, w)
              for ee, w in _summary(r, BASELINE_DOCUMENT_GAINS)["end_effector_angular_velocity_final"].items()],
          "The robot turns rigidly: both end-effectors keep the same constant rate (rows 'FM-NIC-A plant': the "
          "dissertation's own model and integrator). With the document's gains (Kp = 10, Kd = 100) arm 1's joints are "
          "still returning at the end, so its end-effector's rate differs from arm 2's (rows 'document's gains')."),
    *(entry for first, (scene, label) in SCENARIOS.items() for entry in detumbling_figures(first, scene, label)),
    # errata
    Entry(DISSERTATION, "Eq 140", "Nested RMS metric: n_T printed as 500 samples.", "series", None,
          lambda r: [row("samples of a 5 s run at 1 ms (with t = 0)", printed.EQ_140_SAMPLES,
                         int(len(r.arrays("series", "sec51_exact_nidc")["t"])), "d")],
          "5 s at 1 ms gives 5000 steps (5001 samples with t = 0); freefloat's rms divides by the samples it has. "
          "With --quick the run lasts 0.5 s (501 samples).", erratum=True),
    Entry(DISSERTATION, "Eq 11", "Euler-rate matrix R_E as printed.", "models", None,
          lambda r: [row("max relative error of the printed R_E, 100 random angles and rates", None,
                         r.report("models")["attitude"]["eq11_printed_max_relative_error"])],
          "The printed matrix does not map XYZ Euler rates to the angular velocity; freefloat integrates the attitude "
          "on the Lie group.", erratum=True),
    Entry(DISSERTATION, "Sec 4.2.1", f"Pivot of arm 4 printed '{printed.ARM_4_PIVOT}'.", "series", None,
          lambda r: [row("arm 4 end-effector at the start (m)", printed.ARM_4_PIVOT,
                         ", ".join(f"{v:.4g}" for v in r.arrays("series", "sec51_exact_nidc")["ee"][0, 3, :2]))],
          "A typo for [0, -1.75, 0]: with it arm 4 ends at (0, -7.75) as the text's start posture says.", erratum=True),
    Entry(DISSERTATION, "Sec 5.3", f"Sampling printed as '{printed.SEC_5_3_SAMPLING}'.", "series", None,
          lambda r: [row("control period of the detumbling scenes (s)", printed.SEC_5_3_SAMPLING,
                         float(np.diff(r.arrays("series", BASELINE)["t"][:2])[0]))],
          "1 ms, as in the earlier runs (1 s of 1000 samples).", erratum=True),
    Entry(DISSERTATION, "Eq 182 (appendix B)", "Lower-right block of H0^C, the momentum about the inertial origin.", "",
          None, lambda r: [row("max relative error of the momentum about the origin, 5 random states", None,
                               "printed {:.3g} / corrected {:.3g}".format(*momentum_eq_182()))],
          "The derivation at eq 180 treats skew matrices as anticommuting; the corrected form (L_O = L_base + r0 x P) "
          "matches Pinocchio's centroidal momentum moved to the origin to round-off.", erratum=True),
    Entry(DISSERTATION, "Eqs 95-99", "The GJM models with external forces and gravity (sec 3.7: the under-actuated "
          "model 'stays valid with external forces applied').", "",
          None, lambda r: [row(f"{name}: max relative acceleration error against ABA, zero momentum / random state", None,
                               f"{zero:.3g} / {any_:.3g}")
                           for name, (zero, any_) in external_forces_eqs_95_99().items()],
          "Four-arm robot with gravity and a wrench on every joint, 5 states each, against ABA with the same forces: "
          "only standard_corrected (full Hdot, c0 = [0; v0 x P]) is exact, which is the one model = 'auto' keeps "
          "besides exact when the momentum is not conserved; standard_full_hdot is exact only at zero linear momentum, "
          "the stand-alone and momentum forms drop the base rows' force even at zero momentum (docs/models.md).",
          erratum=True),
    Entry(DISSERTATION, "Eqs 109-115", "Multi-arm numerical model: every arm's joint equations summed (operator I_n) "
          "and the summed matrix inverted.", "",
          None, lambda r: [row("max relative error against ABA / ABA's residual in the summed equations, four-arm "
                               "robot, 5 random states with wrenches", None,
                               "{:.3g} / {:.3g}".format(*summed_arms_eqs_109_115()))],
          "The sum holds for the exact accelerations but gives m equations for the N = n m joint accelerations (n arms "
          "of m joints): the printed inverse of an m x N matrix does not exist. freefloat keeps each arm's equations "
          "(eq 113 stacked); the printed form is freefloat.dynamics.models.summed_arms (its inverse read as the "
          "pseudo-inverse), exact with one arm only (docs/models.md).", erratum=True),
    Entry(DISSERTATION, "Sec 3.5", "Claim that the base rows carry no non-inertial term (c0 = 0).", "models", None,
          lambda r: [row(f"max relative acceleration error, c0 = 0 / c0 = [0; v0 x P], {regime}", None,
                         f"{errors['standard_full_hdot']:.3g} / {errors['standard_corrected']:.3g}")
                     for regime, errors in r.report("models")["accuracy"]["errors"].items() if regime != "zero momentum"],
          "c0 = 0 holds only while the linear momentum is zero (or v0 x P = 0); with linear momentum the base rows need "
          "v0 x P (models study, part 1).", erratum=True),
    Entry(DISSERTATION, "Figs 17, 54-56", "Captions: fig 17 'ST-ST-A' for FM-ST-A; figs 54-56 repeat 'arm 2, joint 4' "
          "for the two-target scenario.", erratum=True, note="Caption typos; the entries above use the text's meaning."),
)
