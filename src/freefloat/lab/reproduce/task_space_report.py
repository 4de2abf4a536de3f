"""``freefloat reproduce task_space``: the dissertation's sec 5.2 (Tables 2-5, figs 20-40).

1. The joint-space run (JSC): the chapter-4 task from Table 4's start (every joint 0.5 deg off
   the stretched posture, in the direction it moves), exact plant, RKMK4, 0.1 ms.
2. The task-space run (TSC): the end-effector rates (vx, vy, wz of each arm) of the JSC run as
   references, joint references by the inverse E-GJM (eqs 138-139), same plant and step, with
   qddot_d by the dissertation's backward difference; and the same run with the analytic
   qddot_d (the derivative of eq 138 with dJ*/dt from ``gjm.jacobian_rates`` and the JSC's exact
   end-effector accelerations), its Table 2 and its distance from the first; and both runs again
   in the dissertation's own setting (:data:`DOCUMENT`: plant FM-NIC-A with its semi-implicit
   Euler, both laws on FM-ST-A), its Table 2 beside the exact plant's; and the TSC run with
   position feedback on the end-effector poses (:data:`POSITION_GAIN`) beside eq 139's open loop.
3. Table 2: RMS of the TSC end-effector pose error against the JSC path (x, y in m, z-rotation in
   deg), per arm, overall = RMS of the three; Table 3: KJC of the TSC run (E-GJM rates against
   central differences of the simulated motion; m/s and deg/s); Tables 4-5: joint and end-effector
   start/end values of both runs, beside the dissertation's.
4. Figs 38-40: condition number of the E-GJM along the first second of the joint-space task from
   offsets of 1, 0.1 and 0 deg; at 0 deg the plain inversion is refused and damped least squares
   is run instead.
5. The runs themselves for figs 20-37: ``jsc.npz`` and ``tsc.npz``
   (:func:`~.series_report.series_arrays`) and ``kjc.npz`` (:func:`kjc_series`).
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...app.outputs import write_report
from ...app.viz.figures import base_attitude
from ...documents import DIRECTION, FIGS_38_40_OFFSET_DEG, TABLE_4_OFFSET_DEG, TASK_DEG, TASK_S, start_angles
from ...dynamics import gjm
from ...dynamics.integrators import make_integrator
from ...dynamics.metrics import rms
from ...dynamics.models import make_model
from ...dynamics.simulation import run
from ...errors import SingularityError
from ...paths import URDF_DIR
from ...robot.joints import JointCoordinates
from ...robot.loading import load_robot
from ...space.control import ComputedTorque, QuinticTrajectory
from ...space.control.inverse_egjm import InverseEGJM
from ...space.control.task_space import TaskSpaceComputedTorque
from ...space.detumbling import task_rows
from .interrupts import finished
from .printed import TABLE_2, TABLE_3, TABLE_5
from .series_report import series_arrays

ROWS = [(f"arm{i}_ee", c) for i in range(1, 5) for c in ("vx", "vy", "wz")]


class Setting(NamedTuple):
    """Where a run of sec 5.2 happens: the plant's model, its integrator, the controllers' model
    (names of :data:`~freefloat.dynamics.models.MODELS` and of the integrators' registry)."""

    plant: str
    integrator: str
    controller: str


#: freefloat's setting: the exact plant (Pinocchio's ABA), RKMK4, exact computed torque.
EXACT = Setting("exact", "rkmk4", "exact")
#: The dissertation's own (sec 5.1.3, chapter 5): plant FM-NIC-A with its sequential base/joint
#: update (semi-implicit Euler), both laws on FM-ST-A.
DOCUMENT = Setting("nidc", "euler", "standard")


def joint_space_run(robot, offset_deg: float, duration: float, dt: float, record_every: int,
                    setting: Setting = EXACT):
    """The chapter-4 quintic task from ``start_angles(offset_deg)`` in ``setting``."""
    start = start_angles(offset_deg)
    q0 = robot.neutral()
    JointCoordinates(robot).set(q0, start)
    end = start + np.radians(TASK_DEG) * np.array(DIRECTION)
    ctrl = ComputedTorque(robot, QuinticTrajectory(start, end, TASK_S), 10.0, 100.0, model=setting.controller)
    return finished(run(robot, q0, np.zeros(robot.model.nv), duration, dt, make_integrator(setting.integrator, robot.model),
                        make_model(setting.plant, robot), ctrl, record_every=record_every)).telemetry


def end_effector_rates(robot, tel, rows: np.ndarray) -> np.ndarray:
    """Exact end-effector rates of the task rows at each sample (N, len(rows)), Pinocchio."""
    data, out = robot.model.createData(), []
    for q, v in zip(tel.q, tel.v):
        pin.forwardKinematics(robot.model, data, q, v)
        twists = [pin.getFrameVelocity(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector for fid in robot.end_effector_frame_ids]
        out.append(np.concatenate(twists)[rows])
    return np.array(out)


def end_effector_accelerations(robot, tel, rows: np.ndarray) -> np.ndarray:
    """Exact end-effector accelerations (d/dt of the rates of :func:`end_effector_rates`) at each
    sample (N, len(rows)): Pinocchio's classical frame accelerations, joint accelerations by ABA
    from the recorded torques (held over each step, so exact at the samples)."""
    data, out = robot.model.createData(), []
    nb = robot.n_base
    for q, v, tau in zip(tel.q, tel.v, tel.tau):
        a = pin.aba(robot.model, data, q, v, np.concatenate((np.zeros(nb), tau)))
        pin.forwardKinematics(robot.model, data, q, v, a)
        acc = [pin.getFrameClassicalAcceleration(robot.model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
               for fid in robot.end_effector_frame_ids]
        out.append(np.concatenate(acc)[rows])
    return np.array(out)


def interpolated(t_samples: np.ndarray, values: np.ndarray):
    """``t -> values`` interpolated linearly per column (len(columns),)."""
    return lambda t: np.array([np.interp(t, t_samples, values[:, i]) for i in range(values.shape[1])])


def interpolated_poses(tel):
    """``t -> [M_d]``: the end-effectors' placements along ``tel`` (pin.SE3 per end-effector),
    positions linear and quaternions normalised-linear between samples."""
    def poses(t: float) -> list[pin.SE3]:
        k = int(np.clip(np.searchsorted(tel.t, t) - 1, 0, len(tel.t) - 2))
        s = float(np.clip((t - tel.t[k]) / (tel.t[k + 1] - tel.t[k]), 0.0, 1.0))
        p = (1 - s) * tel.ee_position[k] + s * tel.ee_position[k + 1]
        quat = (1 - s) * tel.ee_quaternion[k] + s * tel.ee_quaternion[k + 1]
        return [pin.SE3(pin.Quaternion(*(x / np.linalg.norm(x))[[3, 0, 1, 2]]).matrix(), y) for x, y in zip(quat, p)]
    return poses


def task_space_run(robot, jsc, rows, dt: float, duration: float, record_every: int, qddot: str, acceleration=None,
                   setting: Setting = EXACT, kx: float = 0.0):
    """The TSC run tracking the JSC end-effector rates, with the given qddot_d method, in ``setting``;
    with ``kx`` > 0 (1/s) also the JSC end-effector poses by position feedback."""
    reference = interpolated(jsc.t, end_effector_rates(robot, jsc, rows))
    feedback = {"pose_reference": interpolated_poses(jsc), "kx": kx} if kx > 0.0 else {}
    ctrl = TaskSpaceComputedTorque(robot, InverseEGJM(rows), reference, jsc.joint_positions[0], dt,
                                   model=setting.controller, qddot=qddot, acceleration=acceleration, **feedback)
    tel = finished(run(robot, jsc.q[0], jsc.v[0], duration, dt, make_integrator(setting.integrator, robot.model),
                       make_model(setting.plant, robot), ctrl, record_every=record_every)).telemetry
    return ctrl, tel


def table2(tsc, jsc) -> dict:
    """Table 2: RMS of the TSC end-effector pose error against the JSC path, per arm and axis."""
    per_axis = rms(planar_pose(tsc) - planar_pose(jsc), axis=0)
    return {"x": per_axis[:, 0].tolist(), "y": per_axis[:, 1].tolist(), "z_deg": per_axis[:, 2].tolist(),
            "overall": rms(per_axis, axis=1).tolist()}


def qddot_comparison(robot, jsc, tsc, rows, dt: float, duration: float, record_every: int) -> dict:
    """The TSC run again with the analytic qddot_d; its Table 2 and how far it ends from ``tsc``."""
    acceleration = interpolated(jsc.t, end_effector_accelerations(robot, jsc, rows))
    _, analytic = task_space_run(robot, jsc, rows, dt, duration, record_every, "analytic", acceleration)
    difference = planar_pose(analytic) - planar_pose(tsc)
    return {"table2_analytic": table2(analytic, jsc),
            "position_difference_max_m": float(np.abs(difference[..., :2]).max()),
            "angle_difference_max_deg": float(np.abs(difference[..., 2]).max()),
            "joint_difference_max_deg": float(np.degrees(np.abs(analytic.joint_positions - tsc.joint_positions).max()))}


#: K_x of the position-feedback run, 1/s.
POSITION_GAIN = 20.0


def position_feedback(robot, jsc, tsc, rows, dt: float, duration: float, record_every: int) -> dict:
    """The TSC run again with position feedback (:data:`POSITION_GAIN`): its Table 2 and both runs'
    end-effector distance from the JSC path at the end, m."""
    _, closed = task_space_run(robot, jsc, rows, dt, duration, record_every, "backward_difference", kx=POSITION_GAIN)
    final = {name: float(np.linalg.norm(tel.ee_position[-1] - jsc.ee_position[-1], axis=1).max())
             for name, tel in (("open_loop", tsc), ("position_feedback", closed))}
    return {"kx": POSITION_GAIN, "table2": table2(closed, jsc), "final_distance_m": final}


def document_setting(robot, exact_jsc, dt: float, duration: float, record_every: int) -> dict:
    """Both runs again in the dissertation's own setting (:data:`DOCUMENT`): its Table 2 and the
    largest distance (m) of its JSC end-effector path from ``exact_jsc``'s."""
    jsc = joint_space_run(robot, TABLE_4_OFFSET_DEG, duration, dt, record_every, DOCUMENT)
    _, tsc = task_space_run(robot, jsc, task_rows(robot, ROWS), dt, duration, record_every, "backward_difference",
                            setting=DOCUMENT)
    distance = np.abs(planar_pose(jsc)[..., :2] - planar_pose(exact_jsc)[..., :2]).max()
    return {"setting": DOCUMENT._asdict(), "table2": table2(tsc, jsc), "jsc_distance_from_exact_max_m": float(distance)}


def planar_pose(tel) -> np.ndarray:
    """End-effector (x, y, yaw in deg) over time (N, k, 3), yaw unwrapped."""
    yaw = np.stack([base_attitude(tel.ee_quaternion[:, k])[:, 2] for k in range(tel.ee_quaternion.shape[1])], axis=1)
    return np.concatenate((tel.ee_position[..., :2], np.degrees(yaw)[..., None]), axis=2)


def kjc_series(robot, tel) -> dict[str, np.ndarray]:
    """E-GJM end-effector rates and central differences of the simulated planar pose at the inner
    samples: ``t`` (N-2,), ``rates`` and ``differences`` (N-2, k, 3): vx, vy in m/s, wz in deg/s."""
    pose = planar_pose(tel)
    dt = np.diff(tel.t)
    fd = (pose[2:] - pose[:-2]) / (dt[1:] + dt[:-1])[:, None, None]
    rates = np.array([gjm.compute(robot, q, v).end_effector_velocity().reshape(-1, 6)[:, [0, 1, 5]]
                      for q, v in zip(tel.q[1:-1], tel.v[1:-1])])
    rates[..., 2] = np.degrees(rates[..., 2])
    return {"t": tel.t[1:-1], "rates": rates, "differences": fd}


def kjc_table(kjc: dict[str, np.ndarray]) -> dict:
    """Table 3: RMS of the E-GJM rates minus the differences (:func:`kjc_series`), per arm and axis."""
    per_axis = rms(kjc["rates"] - kjc["differences"], axis=0)                      # (k, 3)
    return {"x": per_axis[:, 0].tolist(), "y": per_axis[:, 1].tolist(), "z_deg": per_axis[:, 2].tolist(),
            "overall": rms(per_axis, axis=1).tolist()}


def condition_study(robot, offsets=tuple(sorted(FIGS_38_40_OFFSET_DEG.values(), reverse=True)), duration: float = 1.0,
                    dt: float = 1e-3) -> dict:
    """cond(J*) along the joint-space task for each offset, and what the inversion does at 0 deg."""
    inverse = InverseEGJM(task_rows(robot, ROWS))
    out = {}
    for offset in offsets:
        tel = joint_space_run(robot, offset, duration, dt, record_every=10)
        conds = [inverse.condition(gjm.compute(robot, q, v)) for q, v in zip(tel.q, tel.v)]
        out[str(offset)] = {"t": tel.t.tolist(), "condition": conds}
    q0, v0 = robot.neutral(), np.zeros(robot.model.nv)
    JointCoordinates(robot).set(q0, start_angles(0.0))
    state = gjm.compute(robot, q0, v0)
    try:
        inverse.joint_rates(state, np.ones(len(inverse.rows)))
        out["plain_inversion_at_0_deg"] = "solved"
    except SingularityError as exc:
        out["plain_inversion_at_0_deg"] = f"refused: {exc}"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        damped = InverseEGJM(inverse.rows, damping=1e-3).joint_rates(state, np.ones(len(inverse.rows)))
    out["damped_max_rate_at_0_deg"] = float(np.abs(damped).max())
    return out


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run sec 5.2 and write ``report.json``, ``report.md`` and figures into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    robot = load_robot(URDF_DIR / "four_arm_planar.urdf", base="planar", visuals=False)
    dt, duration = (1e-3, 0.5) if quick else (1e-4, 5.0)
    record_every = 1 if quick else 10
    jsc = joint_space_run(robot, TABLE_4_OFFSET_DEG, duration, dt, record_every)
    rows = task_rows(robot, ROWS)
    ctrl, tsc = task_space_run(robot, jsc, rows, dt, duration, record_every, "backward_difference")
    kjc = kjc_series(robot, tsc)
    for name, tel in (("jsc", jsc), ("tsc", tsc)):  # the runs the report draws (figs 20-37)
        np.savez_compressed(out / f"{name}.npz", **series_arrays(robot, tel))
    np.savez_compressed(out / "kjc.npz", **kjc)
    report = {
        "settings": {"dt": dt, "duration": duration, "record_every": record_every, "quick": quick,
                     "plant": EXACT._asdict()},
        "table2": table2(tsc, jsc),
        "table2_document_setting": document_setting(robot, jsc, dt, duration, record_every),
        "table2_position_feedback": position_feedback(robot, jsc, tsc, rows, dt, duration, record_every),
        "qddot_analytic": qddot_comparison(robot, jsc, tsc, rows, dt, duration, record_every),
        "table3": kjc_table(kjc),
        "table4": {run_name: {"start_deg": np.degrees(tel.joint_positions[0]).round(4).tolist(),
                              "end_deg": np.degrees(tel.joint_positions[-1]).round(4).tolist()} for run_name, tel in (("JSC", jsc), ("TSC", tsc))},
        "table5": {run_name: {"start": planar_pose(tel)[0].round(4).tolist(), "end": planar_pose(tel)[-1].round(4).tolist()}
                   for run_name, tel in (("JSC", jsc), ("TSC", tsc))},
        "tsc_condition_range": [float(min(ctrl.condition_numbers)), float(max(ctrl.condition_numbers))],
        "condition_study": condition_study(robot, duration=0.2 if quick else 1.0),
    }
    write_report(out, report, markdown, start)
    figure(report, out / "condition.png")
    return report


def markdown(report: dict) -> str:
    """The tables, ours beside the dissertation's."""
    f = lambda x: f"{x:.2e}"  # noqa: E731
    lines = ["# Sec 5.2: task-space control through the inverse E-GJM", "",
             f"Settings {report['settings']}; wall time {report['wall_time_s']:.0f} s.", "",
             "## Table 2: task-space tracking (RMS of the TSC end-effector pose minus the JSC path)", "",
             "| | arm 1 | arm 2 | arm 3 | arm 4 |", "|---|---|---|---|---|"]
    for key, label in (("x", "x (m)"), ("y", "y (m)"), ("z_deg", "z-rotation (deg)"), ("overall", "overall")):
        lines.append(f"| {label}, freefloat | " + " | ".join(f(x) for x in report["table2"][key]) + " |")
        lines.append(f"| {label}, dissertation | " + " | ".join(f(x) for x in TABLE_2[key]) + " |")
    ds = report["table2_document_setting"]
    lines += ["", f"## Table 2 in the dissertation's own setting {ds['setting']} (backward difference)", "",
              "| | arm 1 | arm 2 | arm 3 | arm 4 |", "|---|---|---|---|---|"]
    for key, label in (("x", "x (m)"), ("y", "y (m)"), ("z_deg", "z-rotation (deg)"), ("overall", "overall")):
        lines.append(f"| {label}, document setting | " + " | ".join(f(x) for x in ds["table2"][key]) + " |")
    lines += ["", f"Its JSC end-effector path from the exact one's, max: {ds['jsc_distance_from_exact_max_m']:.2e} m."]
    pf = report["table2_position_feedback"]
    lines += ["", f"## Table 2 with position feedback (K_x = {pf['kx']:g} 1/s on the end-effector pose error)", "",
              "| | arm 1 | arm 2 | arm 3 | arm 4 |", "|---|---|---|---|---|"]
    for key, label in (("x", "x (m)"), ("y", "y (m)"), ("z_deg", "z-rotation (deg)"), ("overall", "overall")):
        lines.append(f"| {label}, position feedback | " + " | ".join(f(x) for x in pf["table2"][key]) + " |")
    lines += ["", "End-effector distance from the JSC path at the end (m), eq 139 open loop / position feedback: "
              f"{pf['final_distance_m']['open_loop']:.2e} / {pf['final_distance_m']['position_feedback']:.2e}."]
    qa = report["qddot_analytic"]
    lines += ["", "## Table 2 with the analytic qddot_d (dJ*/dt in place of the backward difference)", "",
              "| | arm 1 | arm 2 | arm 3 | arm 4 |", "|---|---|---|---|---|"]
    for key, label in (("x", "x (m)"), ("y", "y (m)"), ("z_deg", "z-rotation (deg)"), ("overall", "overall")):
        lines.append(f"| {label}, analytic | " + " | ".join(f(x) for x in qa["table2_analytic"][key]) + " |")
    lines += ["", f"Analytic run minus backward-difference run, max: end-effector position {qa['position_difference_max_m']:.2e} m, "
              f"z-rotation {qa['angle_difference_max_deg']:.2e} deg, joints {qa['joint_difference_max_deg']:.2e} deg."]
    lines += ["", "## Table 3: KJC (E-GJM rates vs differences of the simulated motion; m/s, deg/s)", "",
              "| | arm 1 | arm 2 | arm 3 | arm 4 |", "|---|---|---|---|---|"]
    for key, label in (("x", "x"), ("y", "y"), ("z_deg", "z-rotation"), ("overall", "overall")):
        lines.append(f"| {label}, freefloat | " + " | ".join(f(x) for x in report["table3"][key]) + " |")
        lines.append(f"| {label}, dissertation | " + " | ".join(f(x) for x in TABLE_3[key]) + " |")
    lines += ["", "## Table 4: joints (deg), start -> end", "", "| run | arm | start | end |", "|---|---|---|---|"]
    for run_name, t4 in report["table4"].items():
        for arm in range(4):
            lines.append(f"| {run_name} | {arm + 1} | {t4['start_deg'][4 * arm:4 * arm + 4]} | {t4['end_deg'][4 * arm:4 * arm + 4]} |")
    lines += ["", "## Table 5: end-effectors (x m, y m, z-rotation deg), start -> end", "",
              "| run | arm | start | end |", "|---|---|---|---|"]
    for run_name, t5 in report["table5"].items():
        for arm in range(4):
            lines.append(f"| {run_name} | {arm + 1} | {t5['start'][arm]} | {t5['end'][arm]} |")
    for arm, (s0, s1) in TABLE_5.items():
        lines.append(f"| dissertation | {arm[-1]} | {list(s0)} | {list(s1)} |")
    cs = report["condition_study"]
    lines += ["", "## Figs 38-40: condition number of the E-GJM along the first second", "",
              "| start offset (deg) | min | max |", "|---|---|---|"]
    for offset in ("1.0", "0.1", "0.0"):
        c = cs[offset]["condition"]
        lines.append(f"| {offset} | {min(c):.3g} | {max(c):.3g} |")
    lines += ["", f"Plain inversion at 0 deg: {cs['plain_inversion_at_0_deg']}", "",
              f"Damped least squares (lambda = 1e-3) at 0 deg: max joint rate {cs['damped_max_rate_at_0_deg']:.3g} for unit task rates.",
              f"Condition number along the TSC run: {report['tsc_condition_range'][0]:.4g} to {report['tsc_condition_range'][1]:.4g}.", ""]
    return "\n".join(lines)


def figure(report: dict, path: Path) -> None:
    """Condition number along the run for each start offset (figs 38-40)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for offset in ("1.0", "0.1", "0.0"):
        c = report["condition_study"][offset]
        ax.semilogy(c["t"], c["condition"], label=f"start offset {offset} deg")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("condition number of J* (vx, vy, wz rows)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
