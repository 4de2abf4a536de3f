"""``freefloat reproduce series``: the runs behind the dissertation's time-series figures of secs
5.1 and 5.3, saved for the report (``freefloat reproduce all``) to draw.

1. Sec 5.1 (figs 8-19, Table 1): the chapter-4 joint-space task (four-arm planar robot, quintic
   5 deg in 5 s, computed torque Kp = 10 I, Kd = 100 I, 1 ms) with the controller's model FM-NIC-A
   (``nidc``) and FM-ST-A (``standard``), on the exact plant (RKMK4) and on the dissertation's own
   plant FM-NIC-A with its semi-implicit Euler.
2. Sec 5.3 (figs 41-56): the built-in scenes ``detumble_impulse_baseline`` (joints held, figs
   42-44) and the four detumbling scenarios (figs 45-56), on the exact plant and on the
   dissertation's own (FM-NIC-A, semi-implicit Euler at 1 ms: ``<scene>_fm_nic_a``); and the
   baseline held with the document's gains Kp = 10, Kd = 100 instead of the scene's kp = 2500
   (``detumble_impulse_baseline_document_gains``, exact plant); and each with the capture's couple
   on the base instead of the last link, the dissertation's resultant-only application
   (``<scene>_resultant``, exact plant).

Each run is saved as ``<run>.npz`` (:func:`series_arrays`); ``report.json`` holds each run's
summary numbers (nested RMS per arm, CoM drift, end-effector spin).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from ...app.outputs import write_report
from ...app.runner import prepare, simulate
from ...app.scenes import DEFAULT_SCENE, find_scene
from ...app.viz.figures import angular_momentum_about_com, base_attitude, skeleton
from ...dynamics.telemetry import Telemetry
from ...robot.robot import Robot
from . import printed
from .interrupts import finished

#: Sec 5.1's runs: name -> (plant, controller model, integrator).
SEC_51 = {"sec51_exact_nidc": ("exact", "nidc", "rkmk4"), "sec51_exact_standard": ("exact", "standard", "rkmk4"),
          "sec51_nidc_nidc": ("nidc", "nidc", "euler"), "sec51_nidc_standard": ("nidc", "standard", "euler")}
#: Suffix of a sec-5.3 run on the dissertation's own plant: FM-NIC-A (``nidc``) with its
#: semi-implicit Euler at the 1 ms period, no substeps.
DOCUMENT = "_fm_nic_a"
#: Sec 5.3's scenes, in the figures' order (baseline, then scenarios 1-4).
SEC_53 = ("detumble_impulse_baseline", "detumble_impulse_arm1_joint4", "detumble_impulse_arm1_joint3",
          "detumble_impulse_arm2_joint4", "detumble_impulse_both_arms")
#: Suffix of a sec-5.3 run with the capture applied as the dissertation applies it: "the formulation
#: does not consider the torque's point of application, only its resultant" (sec 5.3), i.e. the
#: 500 N m couple on the base link, where it changes the system's momentum by the same impulse and
#: puts no generalised force on the joints (the scenes put it on the detumbled arm's last link).
RESULTANT = "_resultant"
#: The baseline of figs 42-44 held with the dissertation's gains (:data:`~.printed.COMPUTED_TORQUE_GAINS`).
BASELINE_DOCUMENT_GAINS = "detumble_impulse_baseline_document_gains"


def with_document_gains(scene):
    """``scene`` with its computed-torque gains set to the dissertation's Kp = 10, Kd = 100."""
    return dataclasses.replace(scene, controller=scene.controller.with_settings(**printed.COMPUTED_TORQUE_GAINS))


def with_resultant_capture(scene, base_link: str):
    """``scene`` with every ``wrench_profile`` entry moved onto ``base_link`` (:data:`RESULTANT`)."""
    return dataclasses.replace(scene, environment=tuple(
        e.with_settings(link=base_link) if e.kind == "wrench_profile" else e for e in scene.environment))


def chapter_four_scene(plant: str, controller: str, integrator: str, duration: float):
    """The default scene (chapter-4 task) with the given plant, controller model and integrator,
    run for ``duration`` s (the task shortened with it), no files."""
    scene = find_scene(DEFAULT_SCENE)
    return dataclasses.replace(
        scene,
        controller=scene.controller.with_settings(model=controller),
        simulation=dataclasses.replace(scene.simulation, model=plant, integrator=integrator, duration=duration),
        task=dataclasses.replace(scene.task, duration=min(scene.task.duration, duration)),
        output=dataclasses.replace(scene.output, html=False, figures=False),
    )


def series_arrays(robot: Robot, tel: Telemetry) -> dict[str, np.ndarray]:
    """What the report draws of a planar robot's run, N samples, k end-effectors, n joints:

    ``t`` (N,) s; ``joints``, ``joint_reference``, ``joint_rates`` (N, n) rad, rad/s; ``tau`` (N, n)
    N m; ``ee`` (N, k, 3) end-effector x, y (m) and z-rotation (deg, unwrapped), inertial frame;
    ``ee_wz`` (N, k) end-effector angular rate about z, rad/s (Pinocchio frame velocity);
    ``base`` (N, 3) base CoM x, y (m) and yaw (deg); ``base_twist`` (N, 6) [v0; w0] of the base
    CoM, inertial frame; ``com`` (N, 3) system CoM, m; ``L_com`` (N, 3) angular momentum about the
    system CoM, inertial axes, kg m^2/s; ``skeleton_start``, ``skeleton_end`` (S, 2, 3) link
    segments at the first and last sample (:func:`~freefloat.app.viz.figures.skeleton`).
    """
    model, data = robot.model, robot.model.createData()
    wz = []
    for q, v in zip(tel.q, tel.v):
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        wz.append([pin.getFrameVelocity(model, data, f, pin.LOCAL_WORLD_ALIGNED).angular[2]
                   for f in robot.end_effector_frame_ids])
    ee_yaw = np.stack([base_attitude(tel.ee_quaternion[:, k])[:, 2] for k in range(tel.ee_quaternion.shape[1])], axis=1)
    return {"t": tel.t, "joints": tel.joint_positions, "joint_reference": tel.joint_reference,
            "joint_rates": tel.v[:, robot.n_base:], "tau": tel.tau,
            "ee": np.concatenate((tel.ee_position[..., :2], np.degrees(ee_yaw)[..., None]), axis=2),
            "ee_wz": np.array(wz), "base": np.column_stack((tel.base_position[:, :2],
                                                          np.degrees(base_attitude(tel.base_quaternion)[:, 2]))),
            "base_twist": tel.base_twist, "com": tel.com, "L_com": angular_momentum_about_com(tel),
            "skeleton_start": np.array(skeleton(robot, tel.q[0])), "skeleton_end": np.array(skeleton(robot, tel.q[-1]))}


SUMMARY_KEYS = ("status", "tracking_rms_overall", "tracking_rms_per_arm", "com_drift_max", "base_displacement",
                "end_effector_angular_velocity_final", "end_effector_angular_velocity_settling_time",
                "detumbled_rows_speed_final", "peak_joint_torque", "angular_momentum_balance_max")


def run_and_save(scene, out: Path, name: str) -> dict:
    """Run ``scene``, save its :func:`series_arrays` as ``out/<name>.npz``; its summary numbers."""
    robot = prepare(scene).robot
    outcome = finished(simulate(scene))
    np.savez_compressed(out / f"{name}.npz", **series_arrays(robot, outcome.telemetry))
    return {k: outcome.summary[k] for k in SUMMARY_KEYS if k in outcome.summary}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run secs 5.1 and 5.3 and write ``report.json``, ``report.md`` and one ``.npz`` per run."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    duration = 0.5 if quick else 5.0
    runs = {name: run_and_save(chapter_four_scene(*spec, duration), out, name) for name, spec in SEC_51.items()}
    for name in SEC_53:
        scene = find_scene(name)
        if quick:
            scene = dataclasses.replace(scene, simulation=dataclasses.replace(scene.simulation, duration=0.3))
        runs[name] = run_and_save(scene, out, name)
        runs[f"{name}{DOCUMENT}"] = run_and_save(dataclasses.replace(scene, simulation=dataclasses.replace(
            scene.simulation, model="nidc", integrator="euler", substeps=1)), out, f"{name}{DOCUMENT}")
        runs[f"{name}{RESULTANT}"] = run_and_save(with_resultant_capture(scene, prepare(scene).robot.base_link), out,
                                                  f"{name}{RESULTANT}")
        if name == SEC_53[0]:
            runs[BASELINE_DOCUMENT_GAINS] = run_and_save(with_document_gains(scene), out, BASELINE_DOCUMENT_GAINS)
    report = {"settings": {"quick": quick, "sec51_duration_s": duration, "sec51": SEC_51, "sec53": list(SEC_53)},
              "runs": runs}
    return write_report(out, report, markdown, start)


def markdown(report: dict) -> str:
    """One line per run: its summary numbers."""
    lines = ["# Time series of secs 5.1 and 5.3 (the runs behind the report's figures)", "",
             f"Settings {report['settings']}; wall time {report['wall_time_s']:.0f} s.", ""]
    lines += [f"- {name}: {summary}" for name, summary in report["runs"].items()]
    return "\n".join(lines) + "\n"
