"""A capture by contact (issue 39 item 3; docs/contact.md): a free target drifts into the robot's
hand, the two touch through the scene's ``[[environment]] kind = "contact"`` (a compliant
Hunt-Crossley law with regularised Coulomb friction), and the ``[latch]`` closes the hand's weld
to the target once they have touched below a relative speed for a hold time
(:class:`~freefloat.space.contact.latch.LatchWatch`, then the exact impulse of
:func:`~freefloat.space.contact.latch.close_weld`); the run then goes on with the weld as a loop
closure (:class:`~freefloat.dynamics.closures.ClosedModel`). A fast approach bounces off before
the hold time: a rebound.

The target is ``[free_target]`` (mass, principal inertia, CoM position and velocity), appended to
the robot's model by :func:`~freefloat.space.contact.target.with_free_target`: its joint
``target`` is what the contact entry names as one of its links, the hand the other. The robot
floats torque-free (``task.kind = controller.kind = "none"``), so robot + target momentum is
conserved through the contact and the latch: the summary's ``capture_momentum_drift``.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from functools import partial
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from ...arguments import real_number
from ...dynamics.closures import ClosedModel
from ...dynamics.integrators import make_integrator
from ...dynamics.models import make_model
from ...dynamics.result import Result
from ...dynamics.simulation import run as run_engine
from ...dynamics.telemetry import Telemetry
from ...dynamics.wrenches import ExternalWrench
from ...errors import InvalidArgument, SceneError
from ...space.contact.field import WORLD, ContactField, ContactSettings
from ...space.contact.latch import Latch, LatchWatch, close_weld
from ...space.contact.summary import contact_summary
from ...space.contact.target import TARGET, target_state, with_free_target
from ...space.dual_capture import grasp_welds
from ..environments import ENVIRONMENTS
from ..scenes import Scene
from .base import Checkpoint, Experiment, Outcome, Progress
from .robot_run import UNITS as ROBOT_UNITS
from .robot_run import RobotSetup, control_steps, headline_of, prepare_robot, robot_outcome, summary_of


@dataclass(frozen=True)
class FreeTargetSection:
    """``[free_target]``: a free rigid body of ``mass`` (kg) and principal moments ``inertia``
    about its CoM (kg m^2), its CoM starting at ``position`` (m) with ``velocity`` (m/s), both in
    the inertial frame, not turning."""

    mass: float
    inertia: tuple[float, float, float]
    position: tuple[float, float, float]
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        real_number("mass", self.mass, above=0.0)
        for value in self.inertia:
            real_number("inertia", value, above=0.0)


#: What a run's contact came to, by code (the atlas map's ``outcome``).
OUTCOMES = ("latched", "rebound", "neither")


@dataclass
class ContactCaptureSetup(RobotSetup):
    """A capture-by-contact scene resolved before the loop (:class:`RobotSetup` on the robot with
    the target appended): the contact entry's ``settings`` and ``field`` between the ``hand``
    (the frame the weld closes on) and the target, and the ``latch`` (None: none)."""

    settings: ContactSettings | None = None
    field: ContactField | None = None
    hand: str = ""
    latch: Latch | None = None


class Capture(NamedTuple):
    """What the loop of a capture by contact computed.

    Attributes:
        result: the run, its telemetry the rows before the latch then (from the latch's time, its
            first row the state the weld's impulse left) those after.
        latch_time: when the weld closed, s (None: never).
        gap_speed: the hand-target relative twist the weld's impulse removed (m/s and rad/s rows
            together; None without a latch).
        outcome: an entry of :data:`OUTCOMES`.
        energy_loss: the kinetic energy the weld's impulse took (J, >= 0: a perfectly inelastic
            closure; None without a latch).
    """

    result: Result
    latch_time: float | None
    gap_speed: float | None
    outcome: str
    energy_loss: float | None = None


def takes(scene: object) -> bool:
    """A robot scene with a ``[free_target]``."""
    return isinstance(scene, Scene) and "free_target" in scene.sections


def prepare(scene: Scene) -> ContactCaptureSetup:
    """The robot with the free target appended, the state of both, the contact field between the
    target and the hand and the latch.

    Raises:
        SceneError: naming the key, for a scene whose robot is driven (``task.kind``,
            ``controller.kind``), has ``[[wheels]]``, ``[[closures]]``, a ``[target]``, locked
            joints or a plant model other than the exact one, or that has no contact entry (or
            more than one) between the target and a link of the robot.
    """
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    for key, given in (("task.kind", scene.task.kind != "none"), ("controller.kind", scene.controller.kind != "none"),
                       ("[[wheels]]", bool(scene.wheels)), ("[[closures]]", bool(scene.closures)),
                       ("[target]", scene.target is not None), ("robot.locked_joints", bool(scene.robot.locked_joints)),
                       ("simulation.lock", scene.simulation.lock != "none"),
                       ("simulation.model", scene.simulation.model != "exact")):
        if given:
            raise SceneError(f"{where}'{key}': a capture by contact ([free_target]) floats torque-free on the exact "
                             "plant (task and controller kind \"none\", model \"exact\"), without wheels, closures, "
                             "a [target] or locked joints")
    contacts = [e.settings for e in scene.environment
                if e.kind == "contact" and TARGET in (e.settings.first, e.settings.second)]
    if len(contacts) != 1 or WORLD in (contacts[0].first, contacts[0].second):
        raise SceneError(f"{where}[free_target] needs one [[environment]] kind = \"contact\" between a link of the "
                         f"robot and \"{TARGET}\" (first or second), found {len(contacts)}")
    base = prepare_robot(dataclasses.replace(scene, environment=()))
    tg = scene.sections["free_target"]
    robot = with_free_target(base.robot, tg.mass, tg.inertia)
    qt, vt = target_state(tg.position, tg.velocity)
    specs = [ENVIRONMENTS[e.kind] for e in scene.environment]
    try:
        fields = [spec.build(robot, e.settings) for spec, e in zip(specs, scene.environment)]
    except InvalidArgument as exc:
        raise SceneError(f"{where}[[environment]] {exc}") from exc
    settings = contacts[0]
    field = next(f for f, e in zip(fields, scene.environment) if e.settings is settings)
    hand = settings.second if settings.first == TARGET else settings.first
    sim = scene.simulation
    return ContactCaptureSetup(
        scene=scene, robot=robot, q0=np.concatenate((base.q0, qt)), v0=np.concatenate((base.v0, vt)),
        model=make_model("exact", robot),
        integrator=make_integrator(sim.integrator, robot.model, sim.substeps, sim.rtol, sim.atol),
        wrenches=tuple(f for f in fields if isinstance(f, ExternalWrench)),
        environment=tuple(f for f in fields if not isinstance(f, ExternalWrench)),
        environment_summaries=tuple(partial(spec.summarise, f, robot) for spec, f in zip(specs, fields)
                                    if spec.summarise is not None),
        settings=settings, field=field, hand=hand,
        latch=scene.sections.get("latch"))


def at_approach(scene: Scene, speed: float | None = None, stiffness: float | None = None) -> Scene:
    """``scene`` with the target approaching at ``speed`` (m/s, along its own velocity's
    direction) and the contact's ``stiffness`` (N/m^n; the damping scaled with it, so that c / k,
    and with it the restitution at a given speed, stays), each when given.

    Raises:
        SceneError: a ``speed`` for a target that starts still (no direction to scale).
    """
    tg = scene.sections["free_target"]
    sections = dict(scene.sections)
    if speed is not None:
        now = float(np.linalg.norm(tg.velocity))
        if now == 0.0:
            raise SceneError(f"scene '{scene.name}': 'free_target.velocity' is zero: no approach direction to "
                             "give a speed")
        sections["free_target"] = dataclasses.replace(tg, velocity=tuple(np.multiply(tg.velocity, speed / now)))
    environment = scene.environment
    if stiffness is not None:
        environment = tuple(dataclasses.replace(e, settings=dataclasses.replace(
            e.settings, stiffness=stiffness, damping=e.settings.damping * stiffness / e.settings.stiffness))
            if e.kind == "contact" and TARGET in (e.settings.first, e.settings.second) else e for e in environment)
    return dataclasses.replace(scene, sections=sections, environment=environment)


def capture(setup: ContactCaptureSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None,
            until_decided: bool = False) -> Capture:
    """The loop of a capture by contact: the approach and contact until the latch fires (the
    engine's ``stop``), the weld's impulse, then the welded robot and target (a
    :class:`~freefloat.dynamics.closures.ClosedModel` with ``simulation.baumgarte``) to the end
    of ``simulation.duration``. With ``until_decided`` (the atlas), the run ends at the latch, or
    at the first period end at which the shapes are apart and separating after touching."""
    scene, sim, field = setup.scene, setup.scene.simulation, setup.field
    watch = None if setup.latch is None else LatchWatch(field, setup.latch)
    touched: list[bool] = []

    def stop(t: float, q: np.ndarray, v: np.ndarray) -> bool:
        if watch is not None and watch(t, q, v):
            return True
        if not until_decided:
            return False
        near, velocity = field.nearest(q, v)
        touched.extend([True] if near.depth > 0.0 else [])
        return bool(touched) and near.depth <= 0.0 and float(near.normal @ velocity) > 0.0

    def engine(q: np.ndarray, v: np.ndarray, duration: float, model: Any, start: float, done: int,
               event: Any) -> Result:
        return run_engine(setup.robot, q, v, duration, sim.control_period, setup.integrator, model,
                          wrenches=setup.wrenches, record_every=sim.record_every,
                          progress=None if progress is None else lambda k: progress(done + k), stop=event,
                          start_time=start, checkpoint=checkpoint, environment=setup.environment)

    result = engine(setup.q0, setup.v0, sim.duration, setup.model, 0.0, 0,
                    None if watch is None and not until_decided else stop)
    if watch is None or watch.closed_at is None:
        rebound = (result.status == "stopped" if until_decided
                   else contact_summary(field, setup.robot, result.telemetry)["contact_outcome"] == "rebound")
        return Capture(result, None, None, "rebound" if rebound else "neither")
    latched = watch.closed_at
    q, v = result.telemetry.q[-1], result.telemetry.v[-1]
    hit = close_weld(setup.robot.model, setup.hand, q, v)
    data = setup.robot.model.createData()
    loss = pin.computeKineticEnergy(setup.robot.model, data, q, v) - pin.computeKineticEnergy(
        setup.robot.model, data, q, hit.v_after)
    left = control_steps(scene) - round(latched / sim.control_period)
    if until_decided or left <= 0:
        return Capture(result, latched, hit.gap_speed_before, "latched", loss)
    pin.forwardKinematics(setup.robot.model, data, q)
    welded = ClosedModel(setup.robot, grasp_welds(setup.robot.model, data, (setup.hand,)), sim.baumgarte)
    after = engine(q, hit.v_after, left * sim.control_period, welded, latched, result.steps, None)
    both = Result(Telemetry.concatenate([result.telemetry, after.telemetry]), after.status, after.message,
                  result.steps + after.steps, result.wall_time_s + after.wall_time_s,
                  result.evaluations + after.evaluations, after.backend)
    return Capture(both, latched, hit.gap_speed_before, "latched", loss)


class ContactRows(NamedTuple):
    """The contact at each telemetry row: time (s), penetration depth (m, 0 while apart) and the
    contact force's size (N), (N,) each; the latch's time (s, or None)."""

    t: np.ndarray
    depth: np.ndarray
    force: np.ndarray
    latch_time: float | None


def contact_rows(field: ContactField, telemetry: Telemetry, latch_time: float | None) -> ContactRows:
    """:class:`ContactRows` of a run's ``telemetry`` (the field's model's)."""
    depth, force = np.zeros(len(telemetry.t)), np.zeros(len(telemetry.t))
    for k, (q, v) in enumerate(zip(telemetry.q, telemetry.v)):
        touch = field.contact(q, v)
        if touch is not None:
            depth[k], force[k] = touch[0].depth, float(np.linalg.norm(touch[1]))
    return ContactRows(telemetry.t, depth, force, latch_time)


def run(setup: ContactCaptureSetup, progress: Progress | None = None, checkpoint: Checkpoint | None = None) -> Outcome:
    """The capture (:func:`capture`), its summary (the robot run's, the contact's and
    :data:`UNITS`' keys) and its drawings, with the ``contact`` figure."""
    from ..viz.contact_figures import ContactFigures

    start = time.perf_counter()
    done = capture(setup, progress, checkpoint)
    tel = done.result.telemetry
    momentum = tel.momentum - tel.momentum[0]
    summary = summary_of(setup, done.result, captured=done.latch_time is not None, latch_time=done.latch_time,
                         rebound=done.outcome == "rebound", latch_gap_speed=done.gap_speed,
                         latch_energy_loss=done.energy_loss,
                         capture_momentum_drift=float(np.abs(momentum).max()),
                         capture_wall_time_s=time.perf_counter() - start)
    outcome = robot_outcome(setup, setup.robot, tel, done.result, summary, task_headline=TASK_HEADLINE,
                            events=None if done.latch_time is None else [(done.latch_time, "latch")],
                            extra_bodies=lambda: shape_bodies(setup, tel.q))
    outcome.figures = ContactFigures(outcome.figures, contact_rows(setup.field, tel, done.latch_time))
    return outcome


#: A quarter turn about x, taking a y-aligned body onto z (4, 4).
_Y_TO_Z = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def shape_bodies(setup: ContactCaptureSetup, qs: np.ndarray) -> list[tuple[str, object, np.ndarray]]:
    """The page's two contact shapes (the target's in the capture's colour, the hand's
    see-through), each (name, meshcat object, poses (N, 4, 4) in the inertial frame) over the
    configurations ``qs`` (N, nq); meshcat imported here, as every page does."""
    import meshcat.geometry as mg

    from .capture import TARGET_COLOR

    field, settings = setup.field, setup.settings
    data = field.model.createData()
    poses = np.empty((2, len(qs), 4, 4))
    for k, q in enumerate(qs):
        pin.forwardKinematics(field.model, data, q)
        for side, (joint, placement) in enumerate(zip(field.joints, field.placements)):
            poses[side, k] = (data.oMi[joint] * placement).homogeneous
    bodies = []
    for side, name in enumerate(("first", "second")):
        if getattr(settings, f"{name}_shape") in ("capsule", "cylinder"):
            poses[side] = poses[side] @ _Y_TO_Z  # meshcat's cylinder is along its y axis, coal's along z
        target = getattr(settings, name) == TARGET
        material = mg.MeshPhongMaterial(color=TARGET_COLOR if target else 0x4C72B0, opacity=1.0 if target else 0.4,
                                        transparent=not target)
        bodies.append((f"contact_{name}", mg.Mesh(_shape_geometry(getattr(settings, f"{name}_shape"),
                                                                  getattr(settings, f"{name}_size")), material),
                       poses[side]))
    return bodies


def _shape_geometry(shape: str, size: tuple[float, ...]) -> object:
    """A contact shape (:data:`~freefloat.space.contact.shapes.SHAPES`) as meshcat geometry in its
    shape frame (a capsule drawn as its cylinder: the page shows where, the figure how deep)."""
    import meshcat.geometry as mg

    if shape == "sphere":
        return mg.Sphere(size[0])
    if shape == "box":
        return mg.Box(list(size))
    return mg.Cylinder(size[1], size[0])  # along y: its poses turn it onto z (shape_bodies)


#: The headline keys: the capture's outcome, then the contact's.
TASK_HEADLINE = ("captured", "latch_time", "rebound", "latch_energy_loss", "capture_momentum_drift")
#: The unit of each key this kind adds.
UNITS = {"captured": "", "latch_time": "s", "rebound": "", "latch_gap_speed": "m/s or rad/s",
         "latch_energy_loss": "J",
         "capture_momentum_drift": "N s or N m s", "capture_wall_time_s": "s"}

EXPERIMENT = Experiment("contact_capture", "a free target drifts into a hand: contact, then a latch closes the weld "
                        "or the target rebounds", "robot scenes with a [free_target]", takes, prepare, control_steps,
                        run, headline_of(TASK_HEADLINE), {**ROBOT_UNITS, **UNITS},
                        {"free_target": FreeTargetSection, "latch": Latch})
