"""The simulation loop: zero-order-hold control periods, a dynamics model, an integrator."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import fields
from typing import Protocol

import numpy as np
import pinocchio as pin

from ..arguments import an_object, real_number, reals, whole_number
from ..errors import BadShape, InvalidArgument, SimulationDiverged
from ..robot.conventions import momentum_about_origin
from ..robot.joints import JointCoordinates
from ..robot.loading import BASE_COM_FRAME
from ..robot.robot import Robot
from ..robot.state import check_state
from ..robot.urdf_checks import usable_memory
from . import compiled, compiled_chain, stop_request
from .integrators import Integrator, TimeVarying, make_integrator
from .models import DynamicsModel, make_model
from .plant_periods import PlantPeriods
from .plants import Plant
from .result import Result
from .telemetry import Chunks, PlantTelemetry, Telemetry
from .threads import single_blas_thread
from .wrenches import ExternalWrench, WrenchField, WrenchProfiles, field_forces

__all__ = ["BACKENDS", "CHUNK_ROWS", "MAX_POSITION", "MAX_SPEED", "Controller", "PythonPeriods", "Recorder", "Result",
           "check_memory", "control_periods", "ended_by", "run", "run_plant"]

#: A generalized velocity component above this (m/s or rad/s) counts as a blow-up.
MAX_SPEED = 1e6
#: A configuration coordinate above this (m) counts as a blow-up.
MAX_POSITION = 1e12
#: Loops :func:`run` can use (see its ``backend`` argument).
BACKENDS = ("auto", "compiled", "python")
#: Telemetry rows per chunk (what ``checkpoint`` receives at a time).
CHUNK_ROWS = 1024
#: Periods the compiled loop runs between two returns to Python when no progress is reported (a
#: progress bar makes it 1/200 of the run): each return costs a few microseconds, so Ctrl-C and a
#: stop request still act within this many periods. One call per 1 s run at 1 ms instead of 200
#: made 24 tumbling runs of the four-arm robot 1.10x as fast on one thread (52.2 against 47.6
#: runs/s, best of five turns; the same final states).
UNREPORTED_PERIODS = 1000


class Controller(Protocol):
    """Gives joint torques (n_joints,) at the start of each control period (zero-order hold)."""

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...

    def reference(self, t: float) -> np.ndarray | None:
        """Reference joint positions (n_joints,) or None."""
        ...


class Recorder:
    """Fills telemetry rows from (q, v): kinematics, momentum, energy, into ``tel`` (a chunk, set
    before each row). One Pinocchio Data of its own."""

    def __init__(self, robot: Robot, telemetry: Telemetry | None = None):
        self.tel = telemetry
        self.model = robot.model
        self.data = robot.model.createData()
        self.joints = JointCoordinates(robot)
        self.ee_ids = robot.end_effector_frame_ids
        self.base_id = robot.model.getFrameId(BASE_COM_FRAME)
        self.mass = pin.computeTotalMass(robot.model)
        self.gravity = robot.model.gravity.linear.copy()

    def record(self, row: int, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
               reference: np.ndarray | None, work: float) -> None:
        """Write row ``row`` of the telemetry."""
        model, data, tel = self.model, self.data, self.tel
        tel.momentum[row] = momentum_about_origin(model, data, q, v)  # also kinematics and CoM
        com = data.com[0]
        tel.t[row], tel.q[row], tel.v[row], tel.tau[row] = t, q, v, tau
        tel.joint_positions[row] = self.joints.get(q)
        if reference is not None:
            tel.joint_reference[row] = reference
        tel.com[row] = com
        tel.energy[row] = pin.computeKineticEnergy(model, data) - self.mass * self.gravity @ com
        tel.work[row] = work
        base = pin.updateFramePlacement(model, data, self.base_id)
        tel.base_position[row] = base.translation
        tel.base_quaternion[row] = pin.Quaternion(base.rotation).coeffs()
        tel.base_twist[row] = pin.getFrameVelocity(model, data, self.base_id, pin.LOCAL_WORLD_ALIGNED).vector
        for i, fid in enumerate(self.ee_ids):
            frame = pin.updateFramePlacement(model, data, fid)
            tel.ee_position[row, i] = frame.translation
            tel.ee_quaternion[row, i] = pin.Quaternion(frame.rotation).coeffs()


def run(
    system: Robot | Plant,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    control_period: float,
    integrator: str | Integrator = "rkmk4",
    model: str | DynamicsModel | None = None,
    controller: Controller | None = None,
    wrenches: tuple[ExternalWrench, ...] = (),
    record_every: int = 1,
    progress: Callable[[int], None] | None = None,
    stop: Callable[[float, np.ndarray, np.ndarray], bool] | None = None,
    start_time: float = 0.0,
    checkpoint: Callable[[Telemetry], None] | None = None,
    backend: str = "auto",
    *,
    substeps: int = 1,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    per_stage: bool = False,
    environment: Sequence[WrenchField] = (),
) -> Result:
    """The engine: simulate ``system`` for ``duration`` s in control periods of ``control_period`` s.

    At the start of each period the controller's efforts are computed and held (zero-order hold),
    active external wrenches selected, and the integrator advances the state. A run that diverges
    (non-finite or > MAX_SPEED state) or is interrupted (Ctrl-C) stops and returns what it
    recorded, with the status and a message. A robot records :class:`~.telemetry.Telemetry`
    (kinematics, momentum, energy, end-effectors); a plant (a closed chain, a motor-driven tree:
    :mod:`freefloat.dynamics.plants`) :class:`~.telemetry.PlantTelemetry`, through
    :func:`run_plant`.

    Args:
        system: a robot (its tree, with any ``model``), or a plant.
        q0, v0: initial Pinocchio state (nq,), (nv,) (a plant's: in its own coordinates).
        duration: simulated time, s.
        control_period: zero-order-hold period, s.
        integrator: a name of :data:`freefloat.dynamics.integrators.INTEGRATORS`, built with
            ``substeps`` (fixed-step) or ``rtol``, ``atol`` (adaptive), or (robots) an integrator
            already built (:func:`~freefloat.dynamics.integrators.make_integrator`).
        model: (robots) a name of :data:`freefloat.dynamics.models.MODELS` or a model already
            built (:func:`~freefloat.dynamics.models.make_model`); default ``"exact"``
            (Pinocchio's ABA). A plant carries its own dynamics: None.
        controller: joint torques (a plant: its efforts) ``torque(t, q, v)`` and
            ``reference(t)``, or None for a torque-free run.
        wrenches: (robots) external wrenches on links (profiles; the compiled loop applies them).
        environment: (robots) fields of the environment that apply wrenches depending on time
            and state (:class:`~.wrenches.WrenchField`), evaluated at every integrator stage at
            the stage's own time and state; a run with any runs in the Python loop (they have no
            compiled twin).
        record_every: record one telemetry row every this many periods (and the last one).
        progress: called with the number of periods done: 0 as the loop starts (when its wall time
            starts), then about 200 times, the last one at the end of the loop.
        stop: ``stop(t, q, v)`` after each period; True ends the run there with status
            ``"stopped"`` (an event such as a contact, not a failure).
        start_time: time of the first sample, s (to chain runs, e.g. one per model phase).
        checkpoint: called with every chunk of :data:`CHUNK_ROWS` telemetry rows as it fills
            and with the last rows when the run ends (e.g. to save them as the run goes).
        backend: ``"compiled"``: the same loop in compiled code (:mod:`freefloat.dynamics.compiled`;
            the exact plant and an integrator of the registry without momentum projection; a
            controller without a compiled law and the stop event are then evaluated in Python
            between compiled periods, with the wrenches selected there too; a plant: see
            :func:`run_plant`); ``"python"``: this module's loop; ``"auto"`` (default): compiled
            when the plant and integrator allow it.
        substeps, rtol, atol: the settings of an integrator given by name.
        per_stage: (plants on a vector space) evaluate the controller at every integrator stage
            instead of holding its efforts over the period.

    Raises:
        InvalidArgument: for a state of the wrong size or not finite, a non-unit base quaternion,
            a duration that is not a positive whole number of control periods, an unknown
            backend, an argument the system does not take (naming it), an ``integrator``,
            ``model`` or ``controller`` that is not one, or ``"compiled"`` for a run it cannot do
            (with the reason).
        UnknownName: for an unknown integrator or model name.
    """
    steps = control_periods(duration, control_period)
    if not isinstance(system, Robot):
        if environment:
            raise InvalidArgument(f"environment: plant '{getattr(system, 'name', system)}' takes no wrench fields "
                                  "(robots do)")
        return _run_on_plant(system, q0, v0, duration, control_period, integrator, model, controller, wrenches,
                             record_every, progress, stop, start_time, checkpoint, backend, substeps, rtol, atol,
                             per_stage)
    robot = system
    if per_stage:
        raise InvalidArgument("per_stage: a robot's controller is held over each control period (per-stage control "
                              "is for plants on a vector space)")
    integrator = _integrator(integrator, robot.model, substeps, rtol, atol)
    if model is None or isinstance(model, str):
        model = make_model(model or "exact", robot)
    an_object("model", model, "a name of freefloat.MODELS or a model (freefloat.make_model)", methods=("acceleration",))
    if controller is not None:
        an_object("controller", controller, "None or a controller (torque(t, q, v) and reference(t))",
                  methods=("torque", "reference"))
    check_state(robot, q0, reals("v0", v0))
    record_every = min(whole_number("record_every", record_every), steps)  # more records as many rows
    if backend not in BACKENDS:
        raise InvalidArgument(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    shape = (robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))
    rows = Chunks(lambda n: Telemetry.allocate(n, *shape), CHUNK_ROWS, checkpoint)
    check_memory(rows, steps, record_every, duration, control_period)
    environment = tuple(environment)
    if backend != "python":
        reason = compiled.unsupported(model, integrator) or (
            f"the environment field {type(environment[0]).__name__} has no compiled twin" if environment else None)
        if reason is None:
            law, law_robot = compiled.law_and_robot(controller, robot)
            whole_chunks = (controller is None or law is not None) and stop is None
            loop = compiled.CompiledLoop(robot, integrator, control_period, start_time, record_every,
                                         law if whole_chunks else None,
                                         field_of(robot, wrenches) if whole_chunks else None,
                                         data=plant_data(robot, model), plant=model,
                                         law_robot=law_robot if whole_chunks else None)
            try:
                if whole_chunks:
                    return _run_compiled(loop, q0, v0, steps, control_period, start_time, rows, progress)
                loop.start(q0, v0)
                return _run_periods(loop, steps, control_period, controller, field_of(robot, wrenches), record_every,
                                    progress, stop, start_time, rows)
            finally:
                loop.release()  # kept for the next run on this robot's structure (compiled.py)
        if backend == "compiled":
            raise InvalidArgument(f"the compiled loop cannot run this: {reason}")
    engine = PythonPeriods(robot, integrator, model, control_period, start_time, environment)
    engine.start(q0, v0)
    return single_blas_thread(_run_periods)(engine, steps, control_period, controller, field_of(robot, wrenches),
                                            record_every, progress, stop, start_time, rows)


def _integrator(integrator: str | Integrator, space: pin.Model, substeps: int, rtol: float,
                atol: float) -> Integrator:
    """``integrator`` built on ``space`` when it is a name; refused settings for one already built."""
    if isinstance(integrator, str):
        return make_integrator(integrator, space, substeps, rtol, atol)
    an_object("integrator", integrator, "a name of freefloat.INTEGRATORS or an integrator (freefloat.make_integrator)",
              methods=("advance",))
    if (substeps, rtol, atol) != (1, 1e-10, 1e-12):
        raise InvalidArgument(f"substeps, rtol, atol: settings of an integrator given by name; '{integrator.name}' "
                              "is built already (pass its name, or build it with them)")
    return integrator


def _run_on_plant(plant: Plant, q0: np.ndarray, v0: np.ndarray, duration: float, control_period: float,
                  integrator: str | Integrator, model: object, controller: Controller | None,
                  wrenches: tuple[ExternalWrench, ...], record_every: int, progress: Callable[[int], None] | None,
                  stop: Callable[[float, np.ndarray, np.ndarray], bool] | None, start_time: float,
                  checkpoint: Callable[[PlantTelemetry], None] | None, backend: str, substeps: int, rtol: float,
                  atol: float, per_stage: bool) -> Result:
    """:func:`run` on a plant: the arguments a plant does not take refused by name, then
    :func:`run_plant`."""
    if not (hasattr(plant, "acceleration") and hasattr(plant, "space")):
        raise InvalidArgument(f"system: a Robot or a plant (freefloat.dynamics.plants) is simulated, got "
                              f"{type(plant).__name__} (a ParallelMechanism runs as CoupledChainPlant(mechanism), "
                              "or through freefloat.parallel.track)")
    if model is not None:
        raise InvalidArgument(f"model: plant '{plant.name}' carries its own dynamics; model is for robots")
    if wrenches:
        raise InvalidArgument(f"wrenches: plant '{plant.name}' takes no external wrenches (robots do)")
    if not isinstance(integrator, str):
        raise InvalidArgument(f"integrator: a plant's integrator is given by name (with substeps, rtol, atol), got "
                              f"{type(integrator).__name__}")
    return run_plant(plant, q0, v0, duration, control_period, integrator, controller, substeps, rtol, atol, per_stage,
                     record_every, progress, stop, start_time, checkpoint, backend)


def run_plant(
    plant: Plant,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    control_period: float,
    integrator: str = "rkmk4",
    controller: Controller | None = None,
    substeps: int = 1,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    per_stage: bool = False,
    record_every: int = 1,
    progress: Callable[[int], None] | None = None,
    stop: Callable[[float, np.ndarray, np.ndarray], bool] | None = None,
    start_time: float = 0.0,
    checkpoint: Callable[[PlantTelemetry], None] | None = None,
    backend: str = "auto",
) -> Result:
    """:func:`run` on a plant of :mod:`freefloat.dynamics.plants` (what ``run(plant, ...)`` calls):
    ``duration`` s in control periods of ``control_period`` s, the same loop as a robot's
    (zero-order hold, one status, checkpoints, progress, Ctrl-C), with any integrator of the
    registry. Internal: call :func:`run`.

    Args:
        plant: what is integrated.
        q0, v0: initial state (nq,), (nv,) in the plant's coordinates.
        integrator: a name of :data:`freefloat.dynamics.integrators.INTEGRATORS`; ``substeps``
            (fixed-step) or ``rtol``, ``atol`` (dopri5) its settings.
        controller: efforts ``torque(t, q, v)`` (n_efforts,) and ``reference(t)``, or None for
            zero efforts.
        per_stage: evaluate the controller at every integrator stage (continuous control)
            instead of holding its efforts over the period (plants on a vector space only).
        record_every, progress, stop, start_time, checkpoint: as in :func:`run`.
        backend: ``"compiled"`` (:mod:`freefloat.dynamics.compiled_chain`: a coupled chain with
            its compiled core and a controller with a compiled law, or none), ``"python"``
            (:class:`~.plant_periods.PlantPeriods`) or ``"auto"`` (compiled when it can).

    Raises:
        InvalidArgument: for a state of the wrong size or not finite, a duration that is not a
            whole number of periods, an unknown integrator or backend, or ``"compiled"`` for a
            run it cannot do (with the reason).
    """
    steps = control_periods(duration, control_period)
    space = plant.space
    q0, v0 = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
    if q0.shape != (space.nq,) or v0.shape != (space.nv,) or not (np.isfinite(q0).all() and np.isfinite(v0).all()):
        raise InvalidArgument(f"plant '{plant.name}': the initial state must be finite with shapes ({space.nq},) and "
                              f"({space.nv},), got {q0.shape} and {v0.shape}")
    record_every = min(whole_number("record_every", record_every), steps)
    if backend not in BACKENDS:
        raise InvalidArgument(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    first = controller.reference(start_time) if controller is not None else None
    shape = (space.nq, space.nv, plant.n_efforts, 0 if first is None else len(first))
    rows = Chunks(lambda n: PlantTelemetry.allocate(n, *shape), CHUNK_ROWS, checkpoint)
    check_memory(rows, steps, record_every, duration, control_period)
    if backend != "python":
        reason = compiled_chain.unsupported(plant, integrator, controller, stop)
        if reason is None:
            engine = compiled_chain.CompiledChainLoop(plant, controller, integrator, control_period, start_time,
                                                      substeps, rtol, atol, per_stage, record_every)
            return _run_compiled(engine, q0, v0, steps, control_period, start_time, rows, progress)
        if backend == "compiled":
            raise InvalidArgument(f"the compiled loop cannot run this: {reason}")
    law = controller.torque if (per_stage and controller is not None) else None
    engine = PlantPeriods(plant, integrator, control_period, start_time, substeps, rtol, atol, law)
    engine.start(q0, v0)
    return single_blas_thread(_run_periods)(engine, steps, control_period, controller, None, record_every, progress,
                                            stop, start_time, rows)


def plant_data(robot: Robot, model: DynamicsModel) -> Callable[[], pin.Data | None]:
    """A function giving the plant model's own ``pin.Data`` of ``robot.model``, or None: for the
    compiled loop's check, which runs once per model, so that the Data (built on first use, 25 ms
    at nv 134) is built only then."""
    return lambda: getattr(model, "data", None) if getattr(model, "model", None) is robot.model else None


def field_of(robot: Robot, wrenches: tuple[ExternalWrench, ...]) -> WrenchProfiles | None:
    """The wrenches as a field, or None when there are none."""
    return WrenchProfiles(robot, wrenches) if wrenches else None


class PythonPeriods:
    """The loop's control periods in this module's Python (numpy and Pinocchio's bindings): the
    readable reference that the compiled loop (:class:`~freefloat.dynamics.compiled.CompiledLoop`,
    the same interface) is tested against.

    Args:
        robot: the robot.
        integrator: advances the state over each period.
        model: gives the accelerations.
        control_period: zero-order-hold period, s.
        start_time: time of period 0, s.
        environment: wrench fields evaluated at every stage, at its own time
            (:class:`~.wrenches.WrenchField`; the integrator is handed a
            :class:`~freefloat.dynamics.integrators.TimeVarying` acceleration).
    """

    backend = "python"

    def __init__(self, robot: Robot, integrator: Integrator, model: DynamicsModel, control_period: float,
                 start_time: float = 0.0, environment: Sequence[WrenchField] = ()):
        self.robot, self.integrator, self.model = robot, integrator, model
        self.control_period, self.start_time = control_period, start_time
        self.recorder = Recorder(robot)
        self.tau_full = np.zeros(robot.model.nv)  # [0 on the base rows; joint torques] (nv,)
        self.tau = np.zeros(robot.n_joints)
        self.field: WrenchProfiles | None = None
        self.environment = tuple(environment)
        self.end_period = getattr(model, "end_period", None)
        self.periods_done, self.work = 0, 0.0
        self.q, self.v = robot.neutral(), np.zeros(robot.model.nv)
        self._f = TimeVarying(self._acceleration)

    def start(self, q: np.ndarray, v: np.ndarray) -> None:
        """Set the state at period 0."""
        self.q, self.v = np.array(q, dtype=float), np.array(v, dtype=float)

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The current ``(q, v)``."""
        return self.q, self.v

    def bind(self, chunk: Telemetry) -> None:
        """The chunk :meth:`record` writes into."""
        self.recorder.tel = chunk

    def hold(self, tau: np.ndarray) -> None:
        """Hold the joint torques ``tau`` (n_joints,) from the current period on."""
        self.tau = tau
        self.tau_full[self.robot.n_base:] = tau

    def set_wrenches(self, field: WrenchProfiles | None) -> None:
        """Apply the wrenches ``field`` has active (after ``field.activate(t)``), or none."""
        self.field = field

    def record(self, row: int, reference: np.ndarray | None = None) -> None:
        """Row ``row`` of the bound chunk at the current state, with the joint ``reference``."""
        t = self.start_time + self.periods_done * self.control_period
        self.recorder.record(row, t, self.q, self.v, self.tau, reference, self.work)

    def _acceleration(self, s: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Accelerations (nv,) at ``s`` s into the current period (the fields' time: the
        stage's own), under the held torques and the active profiles."""
        forces = None if self.field is None else self.field.forces(q)
        if self.environment:
            t = self.start_time + self.periods_done * self.control_period + s
            forces = field_forces(self.environment, t, q, v, forces)
        return self.model.acceleration(q, v, self.tau_full, forces)

    def step(self) -> None:
        """One control period.

        Raises:
            SimulationDiverged: when the state leaves :data:`MAX_SPEED` or :data:`MAX_POSITION`.
        """
        q, v, k = self.q, self.v, self.periods_done
        t_end = self.start_time + (k + 1) * self.control_period
        q_next, v_next = self.integrator.advance(self._f, q, v, self.control_period)
        if not np.abs(v_next).max() < MAX_SPEED:  # also false for NaN
            raise SimulationDiverged(f"state blew up at t = {t_end:.6g} s (step {k + 1}): "
                                     f"max |v| = {np.abs(v_next).max():.3g} (limit {MAX_SPEED:g})")
        if not np.abs(q_next).max() < MAX_POSITION:
            raise SimulationDiverged(f"configuration left the finite range at t = {t_end:.6g} s (step {k + 1}): "
                                     f"max |q| = {np.abs(q_next).max():.3g} (limit {MAX_POSITION:g})")
        self.work += float(self.tau @ pin.difference(self.robot.model, q, q_next)[self.robot.n_base:])
        if self.end_period is not None:
            self.end_period(q, v, self.control_period)
        self.q, self.v, self.periods_done = q_next, v_next, k + 1

    def evaluations(self) -> int:
        """Dynamics evaluations made by the integrator."""
        return self.integrator.evaluations()


def _run_compiled(loop: compiled.CompiledLoop, q0: np.ndarray, v0: np.ndarray, steps: int, control_period: float,
                  start_time: float, rows: Chunks, progress: Callable[[int], None] | None) -> Result:
    """:func:`run` through the compiled loop: Python is entered once per chunk or progress report
    (without ``progress``: at least every :data:`UNREPORTED_PERIODS`), where a stop request
    (:mod:`.stop_request`) or Ctrl-C interrupts the run."""
    loop.start(q0, v0)
    report_every = max(1, steps // 200) if progress is not None else UNREPORTED_PERIODS
    status, message = "completed", ""
    start = time.perf_counter()
    try:
        if progress is not None:
            progress(0)
        while loop.periods_done < steps:
            stop_request.check()  # a run on another thread is stopped here (Ctrl-C reaches the main one)
            chunk, row = rows.next_row()
            target = min(steps, (loop.periods_done // report_every + 1) * report_every)
            written, blow_up = loop.run(target, chunk, row)
            rows.commit(written)
            if blow_up is not None:
                raise OverflowError(blow_up)
            if progress is not None and (loop.periods_done % report_every == 0 or loop.periods_done == steps):
                progress(loop.periods_done)
    except ENDINGS as cause:
        status, message = ended_by(cause, start_time + loop.periods_done * control_period)
    else:
        chunk, row = rows.next_row()
        loop.bind(chunk)
        loop.record(row)
        rows.commit()
    wall = time.perf_counter() - start
    return Result(rows.collect(), status, message, loop.periods_done, wall, loop.evaluations(), "compiled")


def _run_periods(engine: PythonPeriods | compiled.CompiledLoop, steps: int, control_period: float,
                controller: Controller | None, field: WrenchProfiles | None, record_every: int,
                progress: Callable[[int], None] | None, stop: Callable[[float, np.ndarray, np.ndarray], bool] | None,
                start_time: float, rows: Chunks) -> Result:
    """:func:`run` one control period at a time: the controller, the wrench selection and the stop
    event here, each period's telemetry row and integration by ``engine`` (this module's Python,
    or the compiled loop); a stop request (:mod:`.stop_request`) or Ctrl-C interrupts it between periods."""
    reference = controller.reference if controller is not None else (lambda t: None)
    efforts = (engine.plant.n_efforts,) if isinstance(engine, PlantPeriods) else (engine.robot.n_joints,)
    report_every = max(1, steps // 200)
    status, message, k = "completed", "", 0
    bound: list[Telemetry] = []

    def record(t: float) -> None:  # the next row, into the chunk the engine writes
        chunk, row = rows.next_row()
        if not bound or chunk is not bound[0]:
            engine.bind(chunk)
            bound[:] = [chunk]
        engine.record(row, reference(t))
        rows.commit()

    start = time.perf_counter()
    try:
        if progress is not None:
            progress(0)
        for k in range(steps):
            stop_request.check()
            t = start_time + k * control_period
            if controller is not None:
                tau = controller.torque(t, *engine.state)
                if np.shape(tau) != efforts:
                    raise BadShape(f"controller: torque(t, q, v) gave {np.shape(tau)} at t = {t:.6g} s; the "
                                   f"{'plant' if isinstance(engine, PlantPeriods) else 'robot'} takes {efforts}")
                engine.hold(tau)
            if field is not None:
                engine.set_wrenches(field if field.activate(t) else None)
            if k % record_every == 0:
                record(t)
            engine.step()
            if progress is not None and ((k + 1) % report_every == 0 or k + 1 == steps):
                progress(k + 1)
            if stop is not None and stop(start_time + (k + 1) * control_period, *engine.state):
                status = "stopped"
                k += 1
                break
        else:
            k = steps
    except BadShape:  # the controller's mistake, not the run's: an error, not a status
        raise
    except ENDINGS as cause:
        status, message = ended_by(cause, start_time + k * control_period)
    else:
        record(start_time + k * control_period)
    wall = time.perf_counter() - start
    return Result(rows.collect(), status, message, k, wall, engine.evaluations(), engine.backend)


#: What ends a run early with a status rather than an error (:func:`ended_by`).
ENDINGS = (KeyboardInterrupt, SimulationDiverged, OverflowError, RuntimeError, ValueError)


def ended_by(cause: BaseException, t: float) -> tuple[str, str]:
    """The status and message of a run that ``cause``, one of :data:`ENDINGS`, ended in the period
    starting at ``t`` s: the one wording of every loop (:func:`run`, :func:`run_plant`, and each
    run of :func:`~.many_runs.run_many`, whose C++ threads report what ended their runs).

    ``"interrupted"`` by Ctrl-C or a signal (:func:`stopped_by`) at ``t``; ``"diverged"`` on a
    blow-up (:class:`~freefloat.errors.SimulationDiverged`, or ``OverflowError`` from the compiled
    loops: the message gives its time and quantity) or when Pinocchio or a law refuses the state
    (``RuntimeError``, ``ValueError``: their message after ``t``).
    """
    if isinstance(cause, KeyboardInterrupt):
        return "interrupted", f"{stopped_by(cause)} at t = {t:.6g} s"
    if isinstance(cause, (SimulationDiverged, OverflowError)):
        return "diverged", str(cause)
    return "diverged", f"at t = {t:.6g} s: {cause}"


def stopped_by(stop: KeyboardInterrupt) -> str:
    """What stopped a run: Ctrl-C ("interrupted by the user"), or the signal that freefloat's
    handlers turned into ``KeyboardInterrupt`` (its name as the argument, e.g. "stopped by SIGTERM")."""
    return f"stopped by {stop.args[0]}" if stop.args else "interrupted by the user"


def check_memory(rows: Chunks, steps: int, record_every: int, duration: float, control_period: float) -> None:
    """Refuse up front a run whose telemetry would not fit in memory: its rows are kept chunk by
    chunk and then joined, about twice their size at the end (``run(duration=1e9)`` grew by
    23 MB/s until the machine ran out).

    Raises:
        InvalidArgument: naming ``duration``, ``control_period`` and ``record_every`` with the
            estimate and what this machine allows (:func:`~freefloat.robot.urdf_checks.usable_memory`).
    """
    one = rows.allocate(1)
    need = 2.0 * (steps // record_every + 1) * sum(getattr(one, f.name).nbytes for f in fields(one))
    if need > (allowed := usable_memory()):
        raise InvalidArgument(f"duration {duration} s in control periods of {control_period} s, recording every "
                              f"{record_every}: {steps // record_every + 1} telemetry rows need about "
                              f"{need / 1e9:.3g} GB, more than {allowed / 1e9:.3g} GB that a run may take here; "
                              "shorten it or raise record_every")


def control_periods(duration: float, control_period: float) -> int:
    """Control periods in ``duration`` s.

    Raises:
        InvalidArgument: unless both are positive real numbers of at most
            :data:`~freefloat.arguments.MAX_MAGNITUDE` and ``duration`` is a whole number of
            periods.
    """
    duration = real_number("duration", duration, above=0.0)
    control_period = real_number("control_period", control_period, above=0.0)
    steps = int(round(duration / control_period))
    if steps < 1 or abs(steps * control_period - duration) > 1e-9 * duration:
        raise InvalidArgument(
            f"duration {duration} s must be a positive whole number of control periods ({control_period} s)"
        )
    return steps
