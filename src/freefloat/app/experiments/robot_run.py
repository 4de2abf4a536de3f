"""What every robot experiment shares: the scene's robot and initial state, its plant model and
integrator, the simulation loop, and the outcome with its figures and page."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ...dynamics.balance import balance
from ...dynamics.closures import ClosedModel
from ...dynamics.integrators import INTEGRATORS, Integrator, make_integrator
from ...dynamics.metrics import UNITS as METRIC_UNITS
from ...dynamics.metrics import summarize
from ...dynamics.models import DynamicsModel, make_model
from ...dynamics.simulation import Controller, Result, run
from ...dynamics.telemetry import Telemetry
from ...dynamics.wrenches import ExternalWrench, WrenchField
from ...errors import RobotModelError, SceneError, did_you_mean
from ...robot.catalog import find_robot, is_name
from ...robot.conventions import state_from_base
from ...robot.joints import JointCoordinates, prismatic_columns
from ...robot.loading import load_robot
from ...robot.locking import LockedJoints
from ...robot.robot import Robot
from ...robot.wheels import Wheels
from ...space.orbit.field import OrbitField
from ...space.orbit.lvlh import base_in_lvlh
from ...space.thrusters import ThrusterSet
from ..environments import ENVIRONMENTS, environment_units
from ..figure_set import drawn
from ..scenes import Scene, resolve_file
from .base import Checkpoint, Outcome, Progress
from .budget import check_budget, seconds_per_call_once
from .locked_run import full_telemetry, lock_for
from .scene_closures import assemble, scene_closures
from .sensor_summary import HEADLINE as SENSOR_HEADLINE
from .sensor_summary import UNITS as SENSOR_UNITS
from .sensor_summary import sensor_summary
from .wheel_run import HEADLINE as WHEEL_HEADLINE
from .wheel_run import UNITS as WHEEL_UNITS
from .wheel_run import WheelTelemetry, scene_wheels, wheel_attitude_control, wheel_summary, wheel_telemetry

#: Summary keys the command line prints for every robot run (those it has: drifts without
#: external wrenches, balances with them), then those of its task (``task_headline`` of
#: :func:`robot_outcome`), the wheels', the sensors' and :data:`LAST_HEADLINE`.
HEADLINE = ("model_auto", "tracking_rms_overall", "com_drift_max", "momentum_drift_max", "energy_drift_max",
            "momentum_balance_max", "momentum_balance_relative", "energy_balance_max", "external_work",
            "base_displacement", "closure_drift_max")
#: A task's headline keys for a run whose spin settles (detumbling and capture runs).
SPIN_HEADLINE = ("settling_time", "base_angular_velocity_final")
#: What the command line prints last about a robot run: the figures it left out, and why.
LAST_HEADLINE = ("figures_not_drawn",)
#: The unit of each key of a robot run's summary, every kind's (the metrics, the wheels', the
#: closures', the run's own; "" for a pure number or a text): each kind adds its task's.
UNITS = {
    **METRIC_UNITS, **WHEEL_UNITS, **SENSOR_UNITS, "closure_drift_max": "m", "closure_rotation_drift_max": "rad",
    "model_auto": "", "model_choice": "", "figures_not_drawn": "", "status": "", "message": "", "steps": "",
    "sim_wall_time_s": "s", "model_evaluations": "", "loop": "",
}


@dataclass
class RobotSetup:
    """A robot scene resolved before the loop: the robot, the initial Pinocchio state ``q0``
    (nq,), ``v0`` (nv,), the plant model and integrator, the controller (None: torque-free), the
    external wrenches, the locked joints (None: none), how ``simulation.model = "auto"`` chose
    the plant (None: the scene named it), and the reaction wheels (None: none) with the
    controller the loop ran (``[attitude]`` composed with ``controller``), and the fields of the
    ``environment`` besides the wrench profiles (:mod:`freefloat.app.environments`) and what their
    entries measure from the run (``environment_summaries``: ``summarise(telemetry) -> dict``).
    With locked joints the model, integrator and controller are built on :attr:`plant` (the
    reduced robot); ``robot``, ``q0`` and ``v0`` stay the full robot's, as the outputs show it."""

    scene: Scene
    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    model: DynamicsModel
    integrator: Integrator
    controller: Controller | None = None
    wrenches: tuple[ExternalWrench, ...] = ()
    lock: LockedJoints | None = None
    model_choice: dict[str, Any] | None = None
    wheels: Wheels | None = None
    wheel_control: Controller | None = None
    environment: tuple[WrenchField, ...] = ()
    environment_summaries: tuple[Callable[[Telemetry], dict[str, Any]], ...] = ()

    @property
    def plant(self) -> Robot:
        """The robot the loop simulates: the reduced robot when joints are locked."""
        return self.robot if self.lock is None else self.lock.robot

    def plant_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The initial state of :attr:`plant`: ``(q0, v0)``, reduced when joints are locked."""
        return (self.q0, self.v0) if self.lock is None else self.lock.reduce(self.q0, self.v0)

    @property
    def plant_wheels(self) -> Wheels | None:
        """The wheels on :attr:`plant` (None without any): mounted on the reduced robot when joints
        are locked."""
        return self.wheels if self.wheels is None or self.lock is None else self.wheels.on(self.lock.robot)

    def plant_joints(self, values: np.ndarray) -> np.ndarray:
        """The columns of a full joint vector (n_joints,) that :attr:`plant` keeps."""
        return values if self.lock is None else values[self.lock.free_joints]


def refuse_two_hand_keys(scene: Scene) -> None:
    """Refuse the keys only a two-hand capture reads (``controller.torque_limit``,
    ``controller.squeeze``, ``target.second_grasp``) in a scene of another kind, which would
    ignore them.

    Raises:
        SceneError: naming the key, the scene's kind and what reads it.
    """
    if scene.kind == "two_hand_capture":
        return
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    ctrl, target = scene.controller, scene.target
    given = [key for key, value in (("controller.torque_limit", getattr(ctrl, "torque_limit", None) is not None),
                                    ("controller.squeeze", getattr(ctrl, "squeeze", 0.0) != 0.0),
                                    ("target.second_grasp", target is not None and target.second_grasp is not None))
             if value]
    if given:
        raise SceneError(f"{where}'{given[0]}' is read by two-hand captures only ([target] second_end_effector); this "
                         f"{scene.kind.replace('_', '-')} scene would ignore it: remove it")


def prepare_robot(scene: Scene) -> RobotSetup:
    """Load the scene's robot and build its initial state, plant model, integrator and wrenches
    (no controller).

    Raises:
        SceneError: naming the key for an unknown file, joint or end-effector, a bad start, or a
            key of two-hand captures (:func:`refuse_two_hand_keys`).
    """
    refuse_two_hand_keys(scene)
    robot = load_robot(
        _urdf_of(scene), base=scene.robot.base,
        end_effectors=scene.robot.end_effectors, gravity=scene.robot.gravity, visuals=scene.output.html,
        inertias=scene.robot.inertias,
    )
    wheels = scene_wheels(scene, robot)
    robot = robot if wheels is None else wheels.robot
    s, ini = scene.angle_scale, scene.initial
    joint_q0 = joint_table(robot, ini.joint_positions, s, "initial.joint_positions")
    joint_v0 = joint_table(robot, ini.joint_velocities, s, "initial.joint_velocities")
    q_joints = pin.neutral(robot.model)
    JointCoordinates(robot).set(q_joints, joint_q0)
    x0dot = np.concatenate((ini.base_linear_velocity, np.multiply(ini.base_angular_velocity, s)))
    rotation0 = pin.rpy.rpyToMatrix(*(np.multiply(ini.base_rpy, s)))
    try:
        q0, v0 = state_from_base(
            robot, np.array(ini.base_position), rotation0, x0dot,
            q_joints[robot.model.nqs[1]:], joint_v0,
        )
    except Exception as exc:
        raise SceneError(f"scene '{scene.name}': [initial] {exc}") from exc
    displacement = joint_table(robot, scene.task.displacement, s, "task.displacement")
    explicit = joint_table(robot, dict.fromkeys(scene.robot.locked_joints or (), 1.0), 1.0,
                           "robot.locked_joints") != 0.0
    sim = scene.simulation
    if sim.model == "auto":
        raise SceneError(f"scene '{scene.name}': 'simulation.model = \"auto\"' is chosen by a pilot run; prepare "
                         "the scene with freefloat.app.runner.prepare")
    closures = scene_closures(scene, robot)
    if closures:
        check_closed_scene(scene, explicit.any())
        q0, v0 = assemble(scene, robot, closures, q0, v0)
    lock = None if closures else lock_for(scene, robot, q0, v0, displacement, explicit,
                                          () if wheels is None else wheels.columns)
    plant = robot if lock is None else lock.robot
    specs = [ENVIRONMENTS[e.kind] for e in scene.environment]
    fields = [spec.build(plant, e.settings) for spec, e in zip(specs, scene.environment)]
    wrenches = tuple(f for f in fields if isinstance(f, ExternalWrench))
    if lock is not None and len(wrenches) < len(fields):
        raise SceneError(f"scene '{scene.name}': [[environment]] fields other than 'wrench_profile' are not available "
                         "with locked joints ('robot.locked_joints', 'simulation.lock')")
    setup = RobotSetup(
        scene=scene, robot=robot, q0=q0, v0=v0,
        model=ClosedModel(plant, closures, sim.baumgarte) if closures else make_model(sim.model, plant),
        integrator=make_integrator(sim.integrator, plant.model, sim.substeps, sim.rtol, sim.atol,
                                   project_momentum=sim.project_momentum),
        wrenches=wrenches, environment=tuple(f for f in fields if not isinstance(f, ExternalWrench)),
        environment_summaries=tuple(partial(spec.summarise, f, plant) for spec, f in zip(specs, fields)
                                    if spec.summarise is not None),
        lock=lock, wheels=wheels,
    )
    check_run_size(setup)
    return setup


def check_closed_scene(scene: Scene, locks: bool) -> None:
    """What a scene with ``[[closures]]`` may ask for: the exact plant, no controller (the
    robot controllers do not know the loop), no locked joints.

    Raises:
        SceneError: naming the key that asks for more.
    """
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    if scene.simulation.model != "exact":
        raise SceneError(f"{where}'simulation.model' is '{scene.simulation.model}'; a scene with [[closures]] "
                         "simulates the exact plant with its loops (model = \"exact\" or \"auto\")")
    if scene.controller.kind != "none" or scene.kind != "joint_space":
        raise SceneError(f"{where}[[closures]] run torque-free ('controller.kind = \"none\"', no [task] or "
                         "[target]); a grasp that closes a loop is a [target] with 'second_end_effector'")
    if locks or scene.simulation.lock != "none":
        raise SceneError(f"{where}'robot.locked_joints' and 'simulation.lock' are not available with [[closures]]")


def check_run_size(setup: RobotSetup) -> None:
    """Refuse a run whose telemetry would not fit in memory or that would take more than a day
    (model evaluations x the measured cost of one).

    Raises:
        SceneError: naming ``simulation.duration``, ``control_period``, ``substeps`` and
            ``record_every`` with the estimate.
    """
    scene, robot = setup.scene, setup.robot
    sim, model = scene.simulation, robot.model
    steps = control_steps(scene) + approach_periods(scene)
    row = 8 * (1 + model.nq + model.nv + 3 * robot.n_joints + 13 + 7 * len(robot.end_effectors) + 11)
    memory = 2 * (steps // sim.record_every + 2) * row  # the chunks, then their concatenation
    q0, v0 = setup.plant_state()
    tau = np.zeros(len(v0))
    structure = (type(setup.model).__name__, getattr(setup.model, "name", ""), model.nq, model.nv, tuple(model.names))
    per_call = seconds_per_call_once(structure, lambda: setup.model.acceleration(q0, v0, tau))
    calls = steps * sim.substeps * INTEGRATORS[sim.integrator].stages
    keys = "'simulation.duration', 'control_period', 'substeps'" + (", 'record_every' and 'target.contact_time'"
                                                                   if scene.target else " and 'record_every'")
    check_budget(scene.name, memory, 1.5 * calls * per_call, keys)


#: A capture's approach runs this long past the target's contact time before it gives up, s.
APPROACH_MARGIN = 0.5


def approach_periods(scene: Scene) -> int:
    """Control periods a capture scene's approach may take (up to the contact time plus
    :data:`APPROACH_MARGIN`); 0 without a ``[target]``."""
    if scene.target is None:
        return 0
    return round((scene.target.contact_time + APPROACH_MARGIN) / scene.simulation.control_period)


def _urdf_of(scene: Scene) -> Path:
    """The file ``robot.urdf`` names: a file (see :func:`resolve_file`) or a known robot's name.

    Raises:
        SceneError: naming the key, the places searched and the known robots like it.
    """
    urdf = scene.robot.urdf
    try:
        return resolve_file(scene, urdf, "robot.urdf")
    except SceneError:
        if not is_name(urdf):
            raise
    try:
        return find_robot(urdf)
    except RobotModelError as exc:
        raise SceneError(f"scene '{scene.name}': robot.urdf {exc}") from exc


def joint_table(robot: Robot, table: dict[str, float], angle_scale: float, key: str) -> np.ndarray:
    """Per-joint values (n_joints,) from a table keyed by joint or end-effector (= its whole arm).

    Revolute values are scaled by ``angle_scale`` (the scene's angle unit), prismatic ones are m.

    Raises:
        SceneError: naming ``key`` and the unknown name, with the valid names.
    """
    out = np.zeros(robot.n_joints)
    named = _named_columns(robot)
    for name, value in table.items():
        if name not in named:
            raise SceneError(f"'{key}': '{name}' is neither a joint nor an end-effector"
                             f"{did_you_mean(name, (*robot.joint_names, *robot.end_effectors), 'joints and end-effectors')}")
        out[named[name]] = value
    return out * _angle_scales(robot, angle_scale)


@functools.lru_cache(maxsize=16)
def _named_columns(robot: Robot) -> dict[str, slice | np.ndarray]:
    """The joint velocity columns (of the n_joints) of each joint and of each end-effector's arm,
    by name; kept for the last robots, as :func:`~freefloat.robot.joints.prismatic_columns`."""
    model, nb = robot.model, robot.n_base
    idx_vs, nvs = list(model.idx_vs), list(model.nvs)  # each attribute read copies the whole vector
    named: dict[str, slice | np.ndarray] = {name: slice(idx_vs[j] - nb, idx_vs[j] + nvs[j] - nb)
                                             for j, name in enumerate(model.names) if j > 1}
    named.update({arm.end_effector: arm.v_indices - nb for arm in robot.arms})
    return named


def _angle_scales(robot: Robot, angle_scale: float) -> np.ndarray:
    """``angle_scale`` for revolute coordinates, 1 for prismatic ones (n_joints,)."""
    return np.where(prismatic_columns(robot), 1.0, angle_scale)


def control_steps(scene: Scene) -> int:
    """Control periods in the scene's duration."""
    return round(scene.simulation.duration / scene.simulation.control_period)


def run_loop(setup: RobotSetup, progress: Progress | None, checkpoint: Checkpoint | None) -> Result:
    """The scene's loop: :func:`freefloat.dynamics.simulation.run` over its duration, on the
    plant; with locked joints, its telemetry (and every checkpointed chunk) is the full robot's
    (:func:`~freefloat.app.experiments.locked_run.full_telemetry`)."""
    sim, lock = setup.scene.simulation, setup.lock
    q0, v0 = setup.plant_state()
    controller = setup.controller
    if setup.wheels is not None:
        closed = setup.model
        closed = ClosedModel(closed.robot, closed.closures, closed.baumgarte) if isinstance(closed, ClosedModel) else None
        controller = setup.wheel_control = wheel_attitude_control(setup.scene, setup.plant_wheels, controller, q0,
                                                                  closed)

    def on_chunk(chunk: Telemetry) -> None:
        checkpoint(chunk if lock is None else full_telemetry(lock, chunk, setup.wrenches))

    result = run(setup.plant, q0, v0, sim.duration, sim.control_period, setup.integrator, setup.model,
                 controller, wrenches=setup.wrenches, record_every=sim.record_every, progress=progress,
                 checkpoint=None if checkpoint is None else on_chunk, backend=sim.backend,
                 environment=setup.environment)
    if lock is not None:
        result.telemetry = full_telemetry(lock, result.telemetry, setup.wrenches)
    return result


def summary_of(setup: RobotSetup, result: Result, **task: Any) -> dict[str, Any]:
    """The run's figures of merit (:func:`freefloat.dynamics.metrics.summarize`: with the scene's
    external wrenches, balances against what they applied instead of drifts), then what the
    environment's entries measure (``summarise``), then the task's own, then the sensors'
    (:func:`~freefloat.app.experiments.sensor_summary.sensor_summary`), then status, steps, wall
    time and model evaluations."""
    tel = result.telemetry
    summary = summarize(tel, setup.robot, setup.wrenches, setup.scene.simulation.control_period,
                        setup.environment) if len(tel.t) else {}
    for measured in setup.environment_summaries if len(tel.t) else ():
        summary.update(measured(tel))
    summary.update(task)
    summary.update(sensor_summary(setup.controller, tel, setup.scene.simulation.control_period))
    if isinstance(setup.model, ClosedModel) and len(tel.t):
        position, rotation = closure_drifts(setup.model, tel.q)
        summary.update(closure_drift_max=float(position.max()), closure_rotation_drift_max=float(rotation.max()))
    summary.update(result.loop_summary())
    return summary


def robot_outcome(setup: RobotSetup, robot: Robot, telemetry: Telemetry, result: Result,
                  summary: dict[str, Any], animation: tuple[np.ndarray, np.ndarray] | None = None,
                  extra_bodies: Callable[[], list] | None = None, extra_telemetry: dict[str, Telemetry] | None = None,
                  events: list[tuple[float, str]] | None = None, wrenches: tuple[ExternalWrench, ...] | None = None,
                  spin: bool = False, settle_threshold: float | None = None, task_headline: tuple[str, ...] = (),
                  approach: Telemetry | None = None, wheel_rows: WheelTelemetry | None = None, lvlh: Any = None,
                  environment: tuple[WrenchField, ...] | None = None) -> Outcome:
    """The outcome of a robot run on ``robot`` (the scene's, or the merged one after a capture):
    telemetry named by its joints and end-effectors, provenance, the figures as one picklable job
    (:class:`~freefloat.app.viz.figure_job.RobotFigures`, which the figure helper draws while the
    run writes the rest: :func:`~freefloat.app.viz.figures.write_figures`, the conservation
    balance when the run has ``wrenches``, default the scene's, or fields of the environment
    (their balance computed here, where the fields are); the angular rates with ``spin``,
    against ``settle_threshold``; the closures' drift) and the animation of ``animation = (t, q)`` (default: the telemetry)
    with the bodies ``extra_bodies()`` lists (called when the page is drawn: (name, meshcat object, (n, 4, 4)
    poses)) and the named moments ``events`` ((time s, label)); with ``approach``
    (a planned capture's pre-capture phase on the scene's robot) also its joint tracking against the
    plan; with ``wheel_rows`` the wheels' rows of a run on another ``robot`` than the scene's (a
    capture's phases) in place of those of ``telemetry``; with thrusters, their thrust and
    propellant; in orbit, the relative orbit of ``lvlh``
    (:class:`~freefloat.app.viz.figure_job.LvlhRows`; default: the base CoM's, from the telemetry).
    ``environment``: the fields ``robot`` flew in over ``telemetry`` (default: the scene's, on its robot).
    The figures left out because their data is identically zero are named in the summary's
    ``figures_not_drawn``."""
    from ..viz.figure_data import empty_figures
    from ..viz.figure_job import ClosedLoop, LvlhRows, RobotFigures, ThrusterRows, WheelRows

    t, q = animation or (telemetry.t, telemetry.q)
    sim = setup.scene.simulation
    wrenches = setup.wrenches if wrenches is None else wrenches
    closed = setup.model if isinstance(setup.model, ClosedModel) and robot is setup.robot else None
    wheels = setup.wheels if (robot is setup.robot or wheel_rows is not None) and len(telemetry.t) else None
    extra_telemetry = dict(extra_telemetry or {})
    if wheels is not None:
        if wheel_rows is None:
            wheel_rows = wheel_telemetry(wheels, telemetry, wrenches, sim.control_period, setup.environment)
        extra_telemetry["wheels"] = wheel_rows
        summary = {**summary, **wheel_summary(wheels, setup.wheel_control, wheel_rows, telemetry)}
    fields = setup.environment if environment is None else environment
    thrusters = next((f for f in fields if isinstance(f, ThrusterSet)), None)
    orbit = next((f.orbit for f in fields if isinstance(f, OrbitField)), None)
    if lvlh is None and orbit is not None:
        lvlh = LvlhRows(telemetry.t, ["base CoM"], base_in_lvlh(orbit, telemetry).position[:, None, :])
    residuals = None
    if fields and len(telemetry.t) >= 2 and "conservation_balance" in drawn(setup.scene):
        residuals = balance(robot, telemetry, wrenches, sim.control_period, fields)
    if setup.scene.output.figures and len(telemetry.t) >= 2:
        left_out = empty_figures(robot, telemetry, spin)
        if approach is not None and "joint_errors" in left_out:
            left_out["joint_errors"] = "the phase after the grasp has no joint reference (the approach's: approach_joint_errors)"
        if left_out:
            summary = {**summary, "figures_not_drawn": left_out}
    return Outcome(
        telemetry=telemetry, status=result.status, message=result.message, steps=result.steps,
        wall_time_s=result.wall_time_s, evaluations=result.evaluations, backend=result.backend, summary=summary,
        names={"joint_names": list(robot.joint_names), "end_effectors": list(robot.end_effectors)},
        provenance={
            "robot": {"urdf": str(robot.urdf_path), "base": robot.base, "nq": robot.model.nq, "nv": robot.model.nv,
                      "end_effectors": list(robot.end_effectors), "loader_notes": [*robot.warnings, *robot.notes]},
            "settings": {"integrator": setup.integrator.name, "model": setup.model.name,
                         "control_period": sim.control_period,
                         "locked_joints": [] if setup.lock is None else list(setup.lock.names)},
        },
        headline=headline_of(task_headline + tuple(environment_units(setup.scene.environment)), wheels is not None),
        extra_telemetry=extra_telemetry,
        figures=RobotFigures(
            robot, telemetry, wrenches, sim.control_period, spin, settle_threshold,
            loop=None if closed is None else ClosedLoop(telemetry.t, None, None, *closure_drifts(closed, telemetry.q)),
            approach=approach, approach_robot=setup.robot,
            wheels=None if wheels is None else WheelRows(wheel_rows.t, [w.name for w in wheels.wheels],
                                                            wheel_rows.momentum, wheels.max_momenta,
                                                            wheel_rows.torque, wheels.max_torques),
            residuals=residuals, lvlh=lvlh,
            thrusters=None if thrusters is None else ThrusterRows(telemetry.t, *thrusters.rows(telemetry.t),
                                                                  thrusters.specific_impulse)),
        page=lambda path, fps: _write_page(robot, t, q, path, fps, extra_bodies, events),
    )


def _write_page(robot: Robot, t: np.ndarray, q: np.ndarray, path: Path, fps: float,
                extra_bodies: Callable[[], list] | None, events: list[tuple[float, str]] | None) -> Path:
    """The run's meshcat page (meshcat imported here: a run without a page never imports it)."""
    from ..viz.meshcat_html import write_trajectory_html

    return write_trajectory_html(robot, t, q, path, fps=fps, extra=extra_bodies() if extra_bodies else None,
                                 events=events)


def headline_of(task_headline: tuple[str, ...], wheels: bool = True) -> tuple[str, ...]:
    """The headline keys of a robot run whose task adds ``task_headline`` (with ``wheels``: the
    wheels' too)."""
    return HEADLINE + task_headline + (WHEEL_HEADLINE if wheels else ()) + SENSOR_HEADLINE + LAST_HEADLINE


def closure_drifts(model: ClosedModel, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Largest closure position (m) and rotation (rad) residual at each sample of ``qs`` (N,), (N,)."""
    drifts = np.array([model.drift(q) for q in qs])
    return drifts[:, 0], drifts[:, 1]


__all__ = ["APPROACH_MARGIN", "HEADLINE", "LAST_HEADLINE", "SPIN_HEADLINE", "UNITS", "RobotSetup", "approach_periods",
           "control_steps", "headline_of", "joint_table", "prepare_robot", "robot_outcome", "run_loop", "summary_of"]
