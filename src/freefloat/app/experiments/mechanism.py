"""Closed-chain mechanism experiments: a mechanism from the registry tracks a platform
reference under computed torque (eq 190) or sliding mode (eq 153) on its nominal model.

On a fixed base (``[mechanism] base = "fixed"``) the plant is the mechanism by Orsino's coupling
(eq 129, Baumgarte-stabilised) in the one loop (:func:`freefloat.parallel.closed_loop.track` ->
:func:`freefloat.dynamics.simulation.run_plant`, compiled when it can), any integrator of the
registry on ``q = [q#; q°]``, the controller's efforts held over each step. On a planar or free
base the plant is the spanning tree with its root joint and the closures
(:mod:`freefloat.parallel.free_base`): freefloat's constrained dynamics in the compiled robot
loop (``closed_tree``, the default there) or Pinocchio's ``constraintDynamics`` in the Python loop,
the same law acting in the base frame, and the run also reports the base's motion and the
system's momentum.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...dynamics.integrators import INTEGRATORS
from ...dynamics.metrics import rms
from ...dynamics.result import Result
from ...dynamics.telemetry import MechanismTelemetry, PlantTelemetry
from ...errors import FreefloatError, SceneError
from ...parallel import free_base
from ...parallel.closed_chain import ClosedChain
from ...parallel.closed_loop import track
from ...parallel.platform_control import CircleReference
from ...parallel.registry import REGISTRY, MechanismSetup
from ...parallel.sliding_mode import PlatformControl
from ..controllers import ControlContext, build_controller
from ..scenes import MechanismScene, resolve_file
from ..scenes.mechanism_schema import ALIASES
from ..viz.figure_job import MechanismFigures
from .base import Checkpoint, Experiment, Outcome, Progress
from .budget import check_budget, seconds_per_call


@dataclass
class PreparedMechanism:
    """A mechanism scene resolved before the loop: the registry's setup, the closure file, the
    controller, and the assembled initial state ``q0``, ``qd0`` (n_q,) of the plant."""

    scene: MechanismScene
    setup: MechanismSetup
    closure: Path
    controller: PlatformControl
    q0: np.ndarray
    qd0: np.ndarray
    floating: free_base.FloatingMechanism | None = None


def takes(scene: object) -> bool:
    """A mechanism scene (``[mechanism]``)."""
    return isinstance(scene, MechanismScene)


def prepare(scene: MechanismScene) -> PreparedMechanism:
    """Load the mechanism, check the scene's sizes against its p platform coordinates, build the
    reference and controller, assemble the plant at the start.

    Raises:
        SceneError: naming the scene file and the key for a wrong size, a bad ``n_ij`` key, or a
            start where the mechanism cannot be assembled.
    """
    where = f"{scene.source}: " if scene.source else f"scene '{scene.name}': "
    closure = resolve_file(scene, scene.mechanism.closure, "mechanism.closure")
    setup = REGISTRY[scene.mechanism.name].build(closure, scene.mechanism.plant)
    if scene.mechanism.gravity is not None:
        gravity = np.asarray(scene.mechanism.gravity)
        setup = setup._replace(nominal=setup.nominal.with_gravity(gravity), plant=setup.plant.with_gravity(gravity))
    p = setup.nominal.p
    if len(setup.nominal.actuated) != p:
        raise SceneError(f"mechanism '{scene.mechanism.name}': {len(setup.nominal.actuated)} actuators for "
                         f"{p} platform coordinates; platform control needs as many")

    def sized(key: str, value, shape: tuple[int, ...]) -> np.ndarray:
        array = np.asarray(value, float)
        if array.shape != shape:
            raise SceneError(f"{where}'{key}' must have shape {shape} for '{scene.mechanism.name}' "
                             f"(p = {p} platform coordinates), got {array.shape}")
        return array

    traj, start = scene.trajectory, scene.initial
    if max(traj.axes) >= p:
        raise SceneError(f"{where}'trajectory.axes' {list(traj.axes)} must index the {p} platform coordinates")
    reference = CircleReference(sized("trajectory.center", traj.center, (p,)), traj.radius, traj.rate, traj.axes)
    controller = build_controller(ControlContext(scene, setup.nominal, reference, scene.simulation.step), "mechanism")
    q_sharp = reference(0.0)[0] if start.platform is None else sized("initial.platform", start.platform, (p,))
    rates = np.zeros(p) if start.platform_velocity is None else sized("initial.platform_velocity",
                                                                      start.platform_velocity, (p,))
    try:
        q0 = setup.plant.assemble(q_sharp, setup.guess(q_sharp))
    except FreefloatError as exc:
        raise SceneError(f"{where}'initial.platform': {exc}") from exc
    prepared = PreparedMechanism(scene, setup, closure, controller, q0, setup.plant.velocity_map(q0) @ rates)
    mech = scene.mechanism
    if mech.plant_kind != "coupled_chain":  # a tree plant: on a moving base, or on the ground
        base = free_base.BaseBody(mech.base, mech.base_mass, mech.base_inertia, mech.base_com, mech.gravity)
        prepared.floating = free_base.FloatingMechanism(setup.display, closure, base, setup.tree_inertias)
    check_run_size(prepared)
    return prepared


def check_run_size(prepared: PreparedMechanism) -> None:
    """Refuse a run whose samples would not fit in memory or that would take more than a day
    (plant evaluations x the measured cost of one, plus the controller's).

    Raises:
        SceneError: naming ``simulation.duration`` and ``simulation.step`` with the estimate.
    """
    scene, plant = prepared.scene, prepared.setup.plant
    sim = scene.simulation
    steps = integration_steps(scene)
    n_q, k = len(prepared.q0), len(plant.actuated)
    memory = steps * (8 * (3 * n_q + 2 * k + 8) + 200)  # plant samples, the control log, telemetry
    u = np.zeros(k)
    if prepared.floating is None:
        forward = seconds_per_call(lambda: plant.forward(prepared.q0, prepared.qd0, u, sim.baumgarte))
        control = seconds_per_call(lambda: prepared.controller.torque(0.0, prepared.q0, prepared.qd0))
    else:
        tree = prepared.floating.plant(sim.baumgarte, dynamics=scene.mechanism.plant_kind)
        q, v = prepared.floating.tree_state(prepared.q0, prepared.qd0)
        law = free_base.BaseFrameControl(prepared.controller, prepared.floating)
        forward = seconds_per_call(lambda: tree.acceleration(q, v, u))
        control = seconds_per_call(lambda: law.torque(0.0, q, v))
    calls = INTEGRATORS[integrator_name(scene)].stages
    check_budget(scene.name, memory, 1.5 * steps * (calls * forward + control),
                 "'simulation.duration' and 'simulation.step'")


def integrator_name(scene: MechanismScene) -> str:
    """The registry name of the scene's integrator (``rk4`` is ``rkmk4``)."""
    return ALIASES.get(scene.simulation.integrator, scene.simulation.integrator)


def run(prepared: PreparedMechanism, progress: Progress | None = None,
        checkpoint: Checkpoint | None = None) -> Outcome:
    """The mechanism's loop, its summary and its drawings.

    A run that blows up (loop-closure residual above 1 m or not finite, or a singular pose) or
    is interrupted (Ctrl-C) returns what it computed, with the status and a message.

    Args:
        progress: as :data:`~.base.Progress`.
        checkpoint: called with the telemetry of every chunk of steps as it fills.
    """
    scene = prepared.scene
    sim, controller = scene.simulation, prepared.controller
    if prepared.floating is not None:
        return run_on_moving_base(prepared, progress, checkpoint)
    result = track(prepared.setup.plant, controller, prepared.q0, sim.duration, sim.step, sim.step, sim.baumgarte,
                   integrator_name(scene), prepared.qd0, rtol=sim.rtol, atol=sim.atol, progress=progress,
                   checkpoint=None if checkpoint is None else (lambda chunk: checkpoint(record(controller, chunk))))
    telemetry = record(controller, result.telemetry, result.status == "completed")
    summary = summarize_mechanism(telemetry, scene.metrics.reaching_phase)
    summary.update(status=result.status, message=result.message, steps=result.steps, sim_wall_time_s=result.wall_time_s,
                   loop=result.backend)
    return outcome(prepared, telemetry, result, summary)


def run_on_moving_base(prepared: PreparedMechanism, progress: Progress | None = None,
                       checkpoint: Checkpoint | None = None) -> Outcome:
    """The loop of a mechanism on a planar or free base (:func:`freefloat.parallel.free_base.track`):
    the mechanism's telemetry in Orsino's coordinates relative to the base (what the law sees),
    the base's and the system's in ``telemetry_base.npz``, and the summary's base keys
    (:func:`summarize_base`)."""
    scene, floating = prepared.scene, prepared.floating
    sim, controller = scene.simulation, prepared.controller

    def relative(chunk: PlantTelemetry, completed: bool = False) -> MechanismTelemetry:
        q, qd = floating.relative_rows(chunk.q, chunk.v)
        return record(controller, PlantTelemetry(t=chunk.t, q=q, v=qd, efforts=chunk.efforts, reference=chunk.reference,
                                                 drift=chunk.drift, orientation_drift=chunk.orientation_drift), completed)

    q0, v0 = floating.tree_state(prepared.q0, prepared.qd0)
    result = free_base.track(floating, controller, q0, v0, sim.duration, sim.step, sim.baumgarte, integrator_name(scene),
                             scene.mechanism.plant_kind, rtol=sim.rtol, atol=sim.atol, progress=progress,
                             checkpoint=None if checkpoint is None else (lambda chunk: checkpoint(relative(chunk))))
    telemetry = relative(result.telemetry, result.status == "completed")
    base = floating.describe(result.telemetry) if floating.root_nv else None
    summary = summarize_mechanism(telemetry, scene.metrics.reaching_phase)
    if base is not None:
        summary.update(summarize_base(floating, base))
    summary.update(status=result.status, message=result.message, steps=result.steps, sim_wall_time_s=result.wall_time_s,
                   loop=result.backend)
    return outcome(prepared, telemetry, result, summary, base)


def summarize_base(floating: free_base.FloatingMechanism, base: free_base.BaseTelemetry) -> dict[str, object]:
    """A moving base's figures of merit (SI units), over the finite samples: ``base`` (its kind),
    ``base_rotation_max`` (rad, the largest angle the base turned from its attitude at t = 0),
    ``base_displacement_max`` (m, the root link origin's largest distance from its start),
    ``momentum_drift_max`` (N s or N m s, the largest change of a component of the system's
    momentum that nothing outside changes, gravity's impulse taken out:
    :meth:`~freefloat.parallel.free_base.FloatingMechanism.momentum_drift`),
    ``momentum_components`` (which: indices into ``[linear; angular]``) and ``com_drift_max`` (m,
    the system CoM's largest distance from ``com(0) + t P(0)/m + g t^2/2``)."""
    rows = np.isfinite(base.q).all(axis=1) & np.isfinite(base.v).all(axis=1)
    if not rows.any():
        return {"base": floating.base.kind}
    tel = base.truncated(int(np.argmin(rows)) if not rows.all() else len(rows))
    t = tel.t - tel.t[0]
    free_motion = tel.com[0] + np.outer(t, tel.momentum[0, :3] / floating.mass) + 0.5 * np.outer(t * t, floating.model.gravity.linear)
    return {"base": floating.base.kind,
            "base_rotation_max": float(np.linalg.norm(tel.base_rotation, axis=1).max()),
            "base_displacement_max": float(np.linalg.norm(tel.base_position - tel.base_position[0], axis=1).max()),
            "momentum_drift_max": float(floating.momentum_drift(tel).max()),
            "momentum_scale": float(max(np.linalg.norm(tel.momentum[:, :3], axis=1).max(),
                                        np.linalg.norm(tel.momentum[:, 3:], axis=1).max())),
            "momentum_components": list(floating.conserved),
            "com_drift_max": float(np.linalg.norm(tel.com - free_motion, axis=1).max())}


def outcome(prepared: PreparedMechanism, telemetry: MechanismTelemetry, result: Result, summary: dict[str, object],
            base: free_base.BaseTelemetry | None = None) -> Outcome:
    """The outcome of a mechanism run (``result``, its loop's, with ``telemetry`` in its place): telemetry named by the tree's joints and actuators,
    provenance, platform figures and the animated linkage with the platform and reference paths;
    on a moving base (``base``, its telemetry) also the base's figures, and the page moves the
    linkage with the base (matplotlib and meshcat imported only when they are drawn)."""
    scene, chain = prepared.scene, prepared.setup.display
    joints = _joint_names(chain, len(prepared.q0))
    actuated = [chain.model.names[j] for j in chain.actuated]
    q = np.hstack((telemetry.platform, telemetry.joints))
    floating = prepared.floating
    poses = None if base is None else np.array([floating.base_placement(qk).homogeneous for qk in base.q])

    def page(path: Path, fps: float) -> Path:
        from ..viz.mechanism_page import write_mechanism_html

        return write_mechanism_html(chain, telemetry.t, q, path, fps, telemetry.platform_reference, base=poses)

    settings = {"integrator": scene.simulation.integrator, "step": scene.simulation.step,
                "baumgarte": scene.simulation.baumgarte, "controller": scene.controller.kind,
                "dynamics": scene.mechanism.plant_kind}
    if base is not None:
        settings.update(base=scene.mechanism.base, base_mass=floating.model.inertias[1].mass,
                        base_inertia=floating.model.inertias[1].inertia.diagonal().tolist(),
                        gravity=floating.model.gravity.linear.tolist())
    return Outcome(
        telemetry=telemetry, status=result.status, message=result.message, steps=result.steps,
        wall_time_s=result.wall_time_s, evaluations=result.evaluations, backend=result.backend, summary=summary,
        names={"joint_names": joints, "actuated": actuated},
        provenance={
            "mechanism": {"name": scene.mechanism.name, "closure": str(prepared.closure), "plant": scene.mechanism.plant,
                          "platform_coordinates": prepared.setup.nominal.p, "joints": joints, "actuated": actuated},
            "settings": settings,
        },
        headline=HEADLINE if base is None else HEADLINE + BASE_HEADLINE,
        extra_telemetry={} if base is None else {"base": base},
        figures=MechanismFigures(telemetry, chain.actuators(), base,
                                 None if base is None else floating.momentum_drift(base)),
        page=page,
    )


def _joint_names(chain: ClosedChain, n_q: int) -> list[str]:
    """Name of the tree joint behind each of Orsino's joint coordinates ``q°`` (n_q - p), from
    :attr:`ClosedChain.joint_coordinates` (the first joint where several share one coordinate)."""
    owner = {i: chain.model.names[j] for j, i in sorted(chain.joint_coordinates.items(), reverse=True)}
    return [owner.get(i, "?") for i in range(chain.mechanism.p, n_q)]


def integration_steps(scene: MechanismScene) -> int:
    """Integration steps in the scene's duration."""
    return round(scene.simulation.duration / scene.simulation.step)


def record(controller: PlatformControl, telemetry: PlantTelemetry, completed: bool = False) -> MechanismTelemetry:
    """A mechanism's telemetry from the loop's rows: Orsino's ``q = [q#; q°]`` split into the
    platform and the joints, the controller's reference, the efforts held from each row (the last
    row of a ``completed`` run, which starts no step, NaN) and the law's sliding variables s at
    each row's state (:meth:`~freefloat.parallel.sliding_mode.PlatformControl.sliding_variables`)."""
    p = controller.model.p
    efforts = telemetry.efforts.copy()
    if completed and len(efforts):
        efforts[-1] = np.nan
    _, sliding = controller.sliding_variables(telemetry.t, telemetry.q, telemetry.v)
    return MechanismTelemetry(t=telemetry.t, platform=telemetry.q[:, :p], platform_reference=telemetry.reference,
                              joints=telemetry.q[:, p:], efforts=efforts, drift=telemetry.drift,
                              orientation_drift=telemetry.orientation_drift, sliding=sliding)


def summarize_mechanism(telemetry: MechanismTelemetry, reaching_phase: float) -> dict[str, object]:
    """Figures of merit (SI units): per platform coordinate, the max and RMS tracking error
    ``|q#_d - q#|`` over the finite samples at or after ``reaching_phase`` s (None when there are
    none); the max loop-closure residuals (position, m; orientation of angular constraints, rad)
    and per-actuator peak |effort| over the finite samples."""
    tel = telemetry
    error = tel.platform_reference - tel.platform
    late = (tel.t >= reaching_phase) & np.isfinite(error).all(axis=1)
    finite_efforts = tel.efforts[np.isfinite(tel.efforts).all(axis=1)]
    finite_drift = tel.drift[np.isfinite(tel.drift)]
    finite_orientation = tel.orientation_drift[np.isfinite(tel.orientation_drift)]
    return {
        "reaching_phase": reaching_phase,
        "tracking_error_max": np.abs(error[late]).max(axis=0).tolist() if late.any() else None,
        "tracking_error_rms": rms(error[late]).tolist() if late.any() else None,
        "loop_closure_drift_max": float(finite_drift.max()) if len(finite_drift) else None,
        "orientation_drift_max": float(finite_orientation.max()) if len(finite_orientation) else None,
        "peak_efforts": np.abs(finite_efforts).max(axis=0).tolist() if len(finite_efforts) else None,
    }


#: Summary keys the command line prints for a mechanism run.
HEADLINE = ("tracking_error_max", "tracking_error_rms", "loop_closure_drift_max", "orientation_drift_max",
            "peak_efforts")
#: Further keys it prints for a mechanism on a moving base.
BASE_HEADLINE = ("base_rotation_max", "base_displacement_max", "momentum_drift_max")
#: The unit of each key of a mechanism run's summary (:func:`summarize_mechanism`,
#: :func:`summarize_base`, the run's own; "" for a pure number or a text). Platform coordinates
#: are m (positions) or rad (angles), actuator efforts N (prismatic) or N m (revolute).
UNITS = {
    "reaching_phase": "s", "tracking_error_max": "m or rad", "tracking_error_rms": "m or rad",
    "loop_closure_drift_max": "m", "orientation_drift_max": "rad", "peak_efforts": "N or N m",
    "base": "", "base_rotation_max": "rad", "base_displacement_max": "m", "momentum_drift_max": "N s or N m s", "momentum_scale": "N s or N m s",
    "momentum_components": "", "com_drift_max": "m",
    "status": "", "message": "", "steps": "", "sim_wall_time_s": "s", "loop": "",
}

EXPERIMENT = Experiment("mechanism", "a closed-chain mechanism tracks a platform reference",
                        "mechanism scenes ([mechanism])", takes, prepare, integration_steps, run,
                        HEADLINE + BASE_HEADLINE, UNITS)
