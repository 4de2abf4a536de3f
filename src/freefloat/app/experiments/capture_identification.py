"""A capture whose target is identified (issue 39 item 4): the robot grasps the scene's target
(:func:`freefloat.space.capture.grasp`), runs the ``[identification]`` manoeuvre
(:func:`freefloat.space.after_capture.manoeuvre`), identifies the target's mass, CoM and inertia
from the manoeuvre's q and v read through seeded noise
(:func:`freefloat.space.target_identification.identify_measured`), then detumbles it with the
law computing on the identified model (:func:`freefloat.space.after_capture.detumble`). The
summary sets the estimates and their 95 % intervals beside the true values."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...arguments import real_number, whole_number
from ...dynamics.metrics import spin_summary, summarize
from ...dynamics.result import Result
from ...errors import InvalidArgument, SceneError, did_you_mean
from ...space.capture import SUMMARY_UNITS as CAPTURE_UNITS
from ...space.capture import grasp
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .capture import CaptureSetup, grasp_time, plan_tracking, refuse_environment
from .capture import prepare as prepare_capture
from .capture import takes as takes_capture
from .detumbling import mission_joints, rows_spec
from .robot_run import APPROACH_MARGIN, SPIN_HEADLINE, control_steps, headline_of, robot_outcome
from .robot_run import UNITS as ROBOT_UNITS

#: The manoeuvre's bounds when the scene gives none: displacement (rad) and rate (rad/s) per joint.
DISPLACEMENT, RATE = 0.3, 0.5
#: The detumbled target counts as settled below this angular speed, rad/s.
SETTLE_BELOW = 1e-6


@dataclass(frozen=True)
class IdentificationSection:
    """``[identification]`` (with a ``[target]`` one hand grasps, on a free base): after the
    grasp, ``joints`` (default: the holding arm's) follow a Fourier trajectory (``harmonics``,
    ``period`` s, within ``displacement`` of the grasp posture and ``rate``, in angle_unit and
    angle_unit/s; default 0.3 rad and 0.5 rad/s; coefficients drawn with ``excitation_seed``) for
    ``duration`` s by computed torque on the robot alone; the record, read through ``noise`` (a
    fraction of each coordinate's size over it, drawn with ``seed``) and smoothed over ``window``
    samples (odd), gives the target's mass, CoM and inertia with their intervals; then the
    ``[task]`` detumbles it for ``simulation.duration`` s on the identified model."""

    duration: float = 10.0
    joints: tuple[str, ...] | None = None
    harmonics: int = 5
    period: float = 10.0
    displacement: float | None = None
    rate: float | None = None
    excitation_seed: int = 0
    noise: float = 0.01
    window: int = 101
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("duration", "period", "displacement", "rate"):
            if getattr(self, name) is not None:
                real_number(name, getattr(self, name), above=0.0)
        real_number("noise", self.noise, low=0.0)
        whole_number("harmonics", self.harmonics)
        whole_number("excitation_seed", self.excitation_seed, low=0)
        whole_number("seed", self.seed, low=0)
        if whole_number("window", self.window) % 2 == 0:
            raise InvalidArgument(f"'window' must be odd (a centred local fit), got {self.window}")


def takes(scene: object) -> bool:
    """A capture scene (one hand grasps its ``[target]``) with ``[identification]``."""
    return takes_capture(scene) and "identification" in scene.sections


def prepare(scene: Scene) -> CaptureSetup:
    """The capture's setup (:func:`freefloat.app.experiments.capture.prepare`), the
    ``[identification]`` checked on its robot.

    Raises:
        SceneError: naming ``robot.base`` when it is not free (a planar base does not conserve
            the whole momentum the identification reads) or an unknown ``identification.joints``
            name, an ``[[environment]]``; or what the capture refuses.
    """
    refuse_environment(scene, "a capture with [identification]")
    setup = prepare_capture(scene)
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    if setup.robot.base != "free":
        raise SceneError(f"{where}[identification] needs 'robot.base = \"free\"' (a planar base conserves only its "
                         f"in-plane momentum), got '{setup.robot.base}'")
    for name in manoeuvre_joints(scene, setup.robot):
        if name not in setup.robot.joint_names:
            raise SceneError(f"{where}'identification.joints': '{name}' is not a joint"
                             f"{did_you_mean(name, setup.robot.joint_names, 'joints')}")
    return setup


def manoeuvre_joints(scene: Scene, robot: Any) -> list[str]:
    """``identification.joints``, or the joints of the arm that holds the target."""
    ident = scene.sections["identification"]
    if ident.joints is not None:
        return list(ident.joints)
    arm = next(a for a in robot.arms if a.end_effector == scene.target.end_effector)
    return [robot.joint_names[i - robot.n_base] for i in arm.v_indices]


def run(setup: CaptureSetup, progress: Progress | None = None,
        checkpoint: Checkpoint | None = None) -> Outcome:
    """Grasp, manoeuvre, identification, detumbling on the identified model; the summary of the
    detumbling run with the identification's estimates, intervals and true values. (One call: no
    progress report nor checkpoints.)"""
    # here, not at the module's top: identification brings scipy (0.9 s) into every scene's start
    from ...dynamics.identification.excitation import random_trajectory
    from ...space.after_capture import detumble, manoeuvre
    from ...space.target_identification import held_parameters, identify_measured, with_target
    from ..viz.identification_figures import IdentificationFigures, IdentifiedParameters

    scene, robot = setup.scene, setup.robot
    tg, sim, ctrl, ident = scene.target, scene.simulation, scene.controller, scene.sections["identification"]
    start = time.perf_counter()
    held = grasp(robot, setup.target, tg.end_effector, sim.control_period, tg.contact_time + APPROACH_MARGIN,
                 tg.tolerance, sim.integrator, setup.q0, setup.v0, ctrl.kp, ctrl.kd, ctrl.model,
                 plan_tracking(setup), grasp_time(setup))
    joints = manoeuvre_joints(scene, robot)
    s = scene.angle_scale
    trajectory = random_trajectory(
        np.zeros(len(joints)), ident.harmonics, ident.period,
        DISPLACEMENT if ident.displacement is None else ident.displacement * s,
        RATE if ident.rate is None else ident.rate * s, np.random.default_rng(ident.excitation_seed))
    record = manoeuvre(held.merged, robot, held.q, held.v, trajectory, joints, ident.duration, sim.control_period,
                       integrator=sim.integrator).telemetry
    estimate = identify_measured(robot, tg.end_effector, record.q, record.v, ident.noise,
                                 np.random.default_rng(ident.seed), ident.window)
    believed = with_target(robot, tg.end_effector, estimate.parameters)
    after = detumble(held.merged, believed, record.q[-1], record.v[-1], rows_spec(scene), sim.duration, SETTLE_BELOW,
                     sim.control_period, scene.task.method, ctrl.kp, ctrl.kd, mission_joints(scene), sim.integrator)
    wall = time.perf_counter() - start
    tel = after.result.telemetry
    summary = summarize(tel, held.merged)  # after the grasp: no external wrench, so drifts
    summary.update(spin_summary(held.merged, tel))
    summary.update(identification_summary(estimate, held_parameters(held.merged, robot, tg.end_effector)),
                   identification_samples=len(record.t), identification_momentum_drift=float(
                       np.abs(record.momentum - record.momentum[0]).max()),
                   target_angular_velocity_final=after.final_speed, settling_time=after.settling_time,
                   settle_threshold=SETTLE_BELOW, peak_joint_torque=after.peak_torque, sim_wall_time_s=wall,
                   status=after.result.status)
    result = Result(tel, after.result.status, after.result.message, len(tel.t) - 1, wall, after.result.evaluations)
    outcome = robot_outcome(setup, held.merged, tel, result, summary, extra_telemetry={
        "pre_capture": held.pre.telemetry, "identification": record}, wrenches=(), spin=True,
        settle_threshold=SETTLE_BELOW, task_headline=TASK_HEADLINE)
    outcome.figures = IdentificationFigures(outcome.figures, IdentifiedParameters.of(summary))
    return outcome


def identification_summary(estimate: Any, truth: np.ndarray) -> dict[str, Any]:
    """The target's mass (kg), CoM (m, in the end-effector frame) and inertia about the CoM
    (kg m^2, its axes) identified (``_estimate``), with their 95 % half-widths (``_half_width``),
    the true values (``_true``) and the errors: relative for the mass, largest component for
    the CoM, relative Frobenius norm for the inertia; the fit's condition number."""
    from ...dynamics.identification.parameters import about_com

    m, c, inertia = estimate.physical()
    dm, dc, dinertia = estimate.physical_half_width(0.95)
    m_true, c_true, inertia_true = about_com(truth)
    return {"target_mass_estimate": m, "target_mass_half_width": dm, "target_mass_true": m_true,
            "target_mass_error": (m - m_true) / m_true,
            "target_com_estimate": c.tolist(), "target_com_half_width": dc.tolist(), "target_com_true": c_true.tolist(),
            "target_com_error": float(np.abs(c - c_true).max()),
            "target_inertia_estimate": inertia.tolist(), "target_inertia_half_width": dinertia.tolist(),
            "target_inertia_true": inertia_true.tolist(),
            "target_inertia_error": float(np.linalg.norm(inertia - inertia_true) / np.linalg.norm(inertia_true)),
            "identification_condition": estimate.estimate.condition}


#: The headline keys: the identification's errors, then the detumbling's settling.
TASK_HEADLINE = ("target_mass_estimate", "target_mass_half_width", "target_mass_true", "target_mass_error",
                 "target_com_error", "target_inertia_error", "target_angular_velocity_final", *SPIN_HEADLINE)
#: The unit of each key this kind adds.
UNITS = {"target_mass_estimate": "kg", "target_mass_half_width": "kg", "target_mass_true": "kg", "target_mass_error": "",
         "target_com_estimate": "m", "target_com_half_width": "m", "target_com_true": "m", "target_com_error": "m",
         "target_inertia_estimate": "kg m^2", "target_inertia_half_width": "kg m^2", "target_inertia_true": "kg m^2",
         "target_inertia_error": "", "identification_condition": "", "identification_samples": "",
         "identification_momentum_drift": "N s or N m s"}

EXPERIMENT = Experiment("capture_identification", "a robot grasps a target, identifies it and detumbles it on the "
                        "identified model", "robot scenes with a [target] grasped by one hand and [identification]",
                        takes, prepare, control_steps, run, headline_of(TASK_HEADLINE),
                        {**ROBOT_UNITS, **CAPTURE_UNITS, **UNITS}, {"identification": IdentificationSection})
