"""Closed-chain mechanism experiments: a mechanism from the registry tracks a platform
reference under computed torque (eq 190) or sliding mode (eq 153) on its nominal model.

The plant is integrated by :func:`freefloat.parallel.mechanism.simulate` (RK4 or semi-implicit
Euler on ``q = [q#; q°]``, Baumgarte-stabilised), the controller's efforts held over each step.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...dynamics.metrics import rms
from ...dynamics.telemetry import MechanismTelemetry
from ...errors import FreefloatError, SceneError
from ...parallel.closed_chain import ClosedChain
from ...parallel.mechanism import ParallelMechanism, simulate
from ...parallel.platform_control import CircleReference, printed_gains
from ...parallel.registry import REGISTRY, MechanismSetup
from ...parallel.sliding_mode import PlatformControl
from ..scenes import MechanismScene, resolve_file
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
    p = setup.nominal.p
    if len(setup.nominal.actuated) != p:
        raise FreefloatError(f"mechanism '{scene.mechanism.name}': {len(setup.nominal.actuated)} actuators for "
                             f"{p} platform coordinates; platform control needs as many")

    def sized(key: str, value, shape: tuple[int, ...]) -> np.ndarray:
        array = np.asarray(value, float)
        if array.shape != shape:
            raise SceneError(f"{where}'{key}' must have shape {shape} for '{scene.mechanism.name}' "
                             f"(p = {p} platform coordinates), got {array.shape}")
        return array

    traj, ctrl, start = scene.trajectory, scene.controller, scene.initial
    if max(traj.axes) >= p:
        raise SceneError(f"{where}'trajectory.axes' {list(traj.axes)} must index the {p} platform coordinates")
    reference = CircleReference(sized("trajectory.center", traj.center, (p,)), traj.radius, traj.rate, traj.axes)
    gains = None
    if ctrl.kind == "sliding_mode":
        gains = printed_gains(sized("controller.n", ctrl.n, (p,)), sized("controller.T", ctrl.T, (p, p)),
                              {_pair(where, key, p): sized(f"controller.n_ij.{key}", v, (p,)) for key, v in ctrl.n_ij.items()})
    controller = PlatformControl(setup.nominal, reference, ctrl.lam, gains, ctrl.saturation)
    q_sharp = reference(0.0)[0] if start.platform is None else sized("initial.platform", start.platform, (p,))
    rates = np.zeros(p) if start.platform_velocity is None else sized("initial.platform_velocity",
                                                                      start.platform_velocity, (p,))
    try:
        q0 = setup.plant.assemble(q_sharp, setup.guess(q_sharp))
    except FreefloatError as exc:
        raise SceneError(f"{where}'initial.platform': {exc}") from exc
    prepared = PreparedMechanism(scene, setup, closure, controller, q0, setup.plant.velocity_map(q0) @ rates)
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
    forward = seconds_per_call(lambda: plant.forward(prepared.q0, prepared.qd0, u, sim.baumgarte))
    control = seconds_per_call(lambda: prepared.controller.efforts(0.0, prepared.q0, prepared.qd0))
    calls = 4 if sim.integrator == "rk4" else 1
    check_budget(scene.name, memory, 1.5 * steps * (calls * forward + control),
                 "'simulation.duration' and 'simulation.step'")


def _pair(where: str, key: str, p: int) -> tuple[int, int]:
    """``"i,j"`` -> (i, j) with 0 <= j <= i < p.

    Raises:
        SceneError: naming ``controller.n_ij`` and the key.
    """
    try:
        i, j = (int(x) for x in key.split(","))
    except ValueError:
        i = j = -1
    if not 0 <= j <= i < p:
        raise SceneError(f"{where}'controller.n_ij' key '{key}' must be \"i,j\" with 0 <= j <= i < {p}")
    return i, j


def run(prepared: PreparedMechanism, progress: Progress | None = None,
        checkpoint: Checkpoint | None = None) -> Outcome:
    """The mechanism's loop, its summary and its drawings.

    A run that blows up (loop-closure residual above 1 m or not finite, or a singular solve) or
    is interrupted (Ctrl-C) returns what it computed, with the status and a message.

    Args:
        progress: called with the number of steps started, about 200 times per run.
        checkpoint: called with the telemetry of every :data:`CHUNK_STEPS` steps started.
    """
    scene = prepared.scene
    sim, plant, controller = scene.simulation, prepared.setup.plant, prepared.controller
    steps = round(sim.duration / sim.step)
    report_every = max(1, steps // 200)
    log: list[tuple[float, np.ndarray, np.ndarray]] = []  # (t_k, q_k, efforts held from t_k)

    def efforts(t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        u = controller.efforts(t, q, qd)
        log.append((t, q.copy(), u))
        if progress is not None and len(log) % report_every == 0:
            progress(len(log))
        if checkpoint is not None and len(log) % CHUNK_STEPS == 0:
            checkpoint(_recorded(controller, plant, log[-CHUNK_STEPS:]))
        return u

    status, message = "completed", ""
    start = time.perf_counter()
    try:
        t, q, drift = simulate(plant, prepared.q0, prepared.qd0, efforts, sim.duration, sim.step, sim.baumgarte,
                               sim.integrator)
        wall = time.perf_counter() - start
        efforts_held = np.array([row[2] for row in log]).reshape(-1, len(plant.actuated))
        telemetry = record(controller, plant, t, q, efforts_held, drift)
        if len(t) < steps + 1:
            status = "diverged"
            message = (f"loop-closure residual {drift[-1]:.3g} m at t = {t[-1]:.6g} s (step {len(t) - 1}): "
                       "the mechanism came apart")
    except (KeyboardInterrupt, np.linalg.LinAlgError) as exc:
        wall = time.perf_counter() - start
        at = log[-1][0] if log else 0.0
        status, message = (("interrupted", f"interrupted by the user at t = {at:.6g} s")
                           if isinstance(exc, KeyboardInterrupt) else ("diverged", f"at t = {at:.6g} s: {exc}"))
        telemetry = _recorded(controller, plant, log, len(prepared.q0))
    summary = summarize_mechanism(telemetry, scene.metrics.reaching_phase)
    steps_done = max(len(telemetry.t) - 1, 0)
    summary.update(status=status, message=message, steps=steps_done, sim_wall_time_s=wall)
    return outcome(prepared, telemetry, status, message, steps_done, wall, summary)


def outcome(prepared: PreparedMechanism, telemetry: MechanismTelemetry, status: str, message: str, steps: int,
            wall: float, summary: dict[str, object]) -> Outcome:
    """The outcome of a mechanism run: telemetry named by the tree's joints and actuators,
    provenance, platform figures and the animated spanning tree."""
    from ..viz.mechanism import write_mechanism_figures, write_mechanism_html

    scene, chain = prepared.scene, prepared.setup.display
    joints = _joint_names(chain, len(prepared.q0))
    actuated = [chain.model.names[j] for j in chain.actuated]
    q = np.hstack((telemetry.platform, telemetry.joints))
    return Outcome(
        telemetry=telemetry, status=status, message=message, steps=steps, wall_time_s=wall, summary=summary,
        names={"joint_names": joints, "actuated": actuated},
        provenance={
            "mechanism": {"name": scene.mechanism.name, "closure": str(prepared.closure), "plant": scene.mechanism.plant,
                          "platform_coordinates": prepared.setup.nominal.p, "joints": joints, "actuated": actuated},
            "settings": {"integrator": scene.simulation.integrator, "step": scene.simulation.step,
                         "baumgarte": scene.simulation.baumgarte, "controller": scene.controller.kind},
        },
        headline=HEADLINE,
        figures=lambda folder: write_mechanism_figures(telemetry, folder, chain),
        page=lambda path, fps: write_mechanism_html(chain, telemetry.t, q, path, fps),
    )


def _joint_names(chain: ClosedChain, n_q: int) -> list[str]:
    """Name of the tree joint behind each of Orsino's joint coordinates ``q°`` (n_q - p), from
    :attr:`ClosedChain.joint_coordinates` (the first joint where several share one coordinate)."""
    owner = {i: chain.model.names[j] for j, i in sorted(chain.joint_coordinates.items(), reverse=True)}
    return [owner.get(i, "?") for i in range(chain.mechanism.p, n_q)]


def integration_steps(scene: MechanismScene) -> int:
    """Integration steps in the scene's duration."""
    return round(scene.simulation.duration / scene.simulation.step)


def _recorded(controller: PlatformControl, plant: ParallelMechanism,
              rows: list[tuple[float, np.ndarray, np.ndarray]], n_q: int | None = None) -> MechanismTelemetry:
    """Telemetry of logged ``(t_k, q_k, efforts held from t_k)`` rows, drift recomputed."""
    q = np.array([row[1] for row in rows]).reshape(-1, n_q or len(rows[0][1]))
    drift = np.array([np.abs(plant.constraint(qk)).max() for qk in q])
    efforts = np.array([row[2] for row in rows]).reshape(-1, len(plant.actuated))
    return record(controller, plant, np.array([row[0] for row in rows]), q, efforts, drift)


def record(controller: PlatformControl, plant: ParallelMechanism, t: np.ndarray, q: np.ndarray,
           efforts: np.ndarray, drift: np.ndarray) -> MechanismTelemetry:
    """Telemetry rows from times (N,), the plant's coordinates (N, n_q), the efforts of the steps
    started (M <= N, k) and drifts (N,); rows without efforts get NaN."""
    p = controller.model.p
    held = np.full((len(t), efforts.shape[1]), np.nan)
    held[: len(efforts)] = efforts[: len(t)]
    reference = np.array([controller.reference(tk)[0] for tk in t]).reshape(-1, p)
    orientation = np.abs(plant.orientation_residual(q)).max(axis=-1, initial=0.0)
    return MechanismTelemetry(t=t, platform=q[:, :p], platform_reference=reference, joints=q[:, p:],
                              efforts=held, drift=drift, orientation_drift=orientation)


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


#: Steps of telemetry per checkpoint.
CHUNK_STEPS = 1024

#: Summary keys the command line prints for a mechanism run.
HEADLINE = ("tracking_error_max", "tracking_error_rms", "loop_closure_drift_max", "orientation_drift_max",
            "peak_efforts")

EXPERIMENT = Experiment("mechanism", "a closed-chain mechanism tracks a platform reference", prepare, integration_steps, run)
