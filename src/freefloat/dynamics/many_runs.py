"""Many runs of one robot scene in one compiled call, on C++ threads (``_sim.Batch``).

Runs that differ only in their initial state, under computed torque in the quintic that starts
from it, and in the plant's masses and inertias (the controller keeping its own robot) need no
Python between their periods. :func:`start_runs` hands their states, as arrays, to ``threads``
C++ threads, each driving a compiled loop of its own (:class:`~freefloat.dynamics.compiled.CompiledLoop`,
with its own Pinocchio ``Data``) through the runs it takes in turn; every run writes its
telemetry rows into a slot of one block of rows.
They run without Python's lock while this thread does other work (prepares the next runs,
summarises the finished ones); :meth:`ManyRuns.finish` then hands each run, as it finishes, to
its caller. A stop request (:mod:`.stop_request`) or Ctrl-C ends every run within
:data:`SLICE_PERIODS` periods; the finished runs are kept, the others end ``"interrupted"``.

Each run gives the numbers of :func:`~freefloat.dynamics.simulation.run` with the same inputs,
bit for bit (tested), on any number of threads.

In lockstep (:func:`lockstep_refusal`: a fixed-step integrator on the exact tree, which the
dynamics kernel takes), each thread drives a group of :data:`~.kernel.LANES` loops instead of one:
every period, each lane's law, wrenches and telemetry row are its own loop's, and every stage of
the integration evaluates the lanes' dynamics at once in the kernel's SIMD lanes
(``cpp/sim/lockstep.hpp``); a lane takes the next run as soon as its own ends (a run that stops
early leaves its lane to the next). Each run still equals its own run bit for bit (tested): the
kernel gives a state in a lane the numbers it gives it alone.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Sequence
from dataclasses import fields
from typing import Any

import numpy as np
import pinocchio as pin

from ..arguments import whole_number
from ..errors import InvalidArgument
from ..robot.robot import Robot
from ..robot.state import check_state
from ..robot.urdf_checks import usable_memory
from . import _sim, compiled, stop_request
from .integrators import INTEGRATORS, Integrator
from .kernel import LANES
from .kernel import isa as kernel_isa
from .kernel import refusal as kernel_refusal
from .models import DynamicsModel
from .simulation import Controller, Result, control_periods, ended_by, field_of, plant_data
from .telemetry import Telemetry
from .wrenches import ExternalWrench

__all__ = ["SLICE_PERIODS", "ManyRuns", "lockstep_refusal", "run_many", "start_runs"]

#: Periods a run does between two looks at the stop request (``Batch::kSlice`` in cpp/sim/batch.hpp).
SLICE_PERIODS = 1000
#: Longest wait for a run to finish before this thread looks at Ctrl-C and the stop request, s.
WAIT = 0.05
#: Most C++ threads one call starts (each has a compiled loop of its own; more than the cores
#: only take turns).
MAX_THREADS = 256

OnResult = Callable[[int, Result], None]


class ManyRuns:
    """Runs started by :func:`start_runs`, running on their threads until :meth:`finish`.

    Attributes:
        interrupted: the runs were stopped (:meth:`stop`, Ctrl-C or a stop request).
    """

    def __init__(self, loops: list[compiled.CompiledLoop], batch: Any, runs: int, block: Telemetry,
                 rows_per_run: int, steps: int, control_period: float, keep: bool, bodies_set: bool):
        self._loops, self._batch, self._runs, self._block, self._bodies_set = loops, batch, runs, block, bodies_set
        self._rows_per_run, self._steps, self._period, self._keep = rows_per_run, steps, control_period, keep
        self.interrupted = False
        self._cause = KeyboardInterrupt()  # Ctrl-C, unless stop() is given the signal's

    def stop(self, cause: KeyboardInterrupt | None = None) -> None:
        """Stop the runs within :data:`SLICE_PERIODS` periods (no run starts); :meth:`finish` gives
        those that finished. ``cause``, the interrupt carrying a signal's name, names it in the
        interrupted runs' messages (:func:`~.simulation.ended_by`)."""
        self.interrupted = True
        self._cause = cause or self._cause
        self._batch.stop()

    def finish(self, on_result: OnResult | None = None) -> list[Result | None]:
        """Wait for every run, giving ``on_result(index, result)`` each as it finishes (in this
        thread; the telemetry is its run's alone). Ctrl-C or a stop request stops the runs: those
        cut short end ``"interrupted"``, those not started stay None. An error of ``on_result``
        stops the runs and propagates.

        Returns:
            the results by run index (None for a run that never started); without ``keep``
            (:func:`start_runs`), an empty list: the results went to ``on_result`` only.
        """
        results: list[Result | None] = [None] * (self._runs if self._keep else 0)
        runs = self._batch

        def give(done: tuple) -> None:
            index, slot, rows, periods, evaluations, wall, blow_up, failure = done
            first = slot * self._rows_per_run
            telemetry = self._block.window(first, first + rows)
            if not self._keep:
                telemetry = telemetry.copied()
                runs.release(slot)
            # what ended the run, as simulation.run would have met it: the loop's blow-up, an error
            # the C++ thread caught (its text), or the stop
            cause = (OverflowError(blow_up) if blow_up is not None else RuntimeError(failure) if failure is not None
                     else None if periods == self._steps else self._cause)
            status, message = ("completed", "") if cause is None else ended_by(cause, periods * self._period)
            result = Result(telemetry, status, message, periods, wall, evaluations, "compiled")
            if self._keep:
                results[index] = result
            if on_result is not None:
                on_result(index, result)

        try:
            try:
                while True:
                    ended = runs.wait(WAIT)
                    for done in runs.take():
                        give(done)
                    if ended:
                        break
                    stop_request.check()  # raises KeyboardInterrupt as Ctrl-C does
            except KeyboardInterrupt as stop:
                self.stop(stop)
                _wait_out(runs)
                for done in runs.take():
                    give(done)
        except BaseException:
            runs.stop()
            _wait_out(runs)
            raise
        finally:
            for loop in self._loops:
                loop.release(numbers_changed=self._bodies_set)
        return results


def _wait_out(runs: Any) -> None:
    """Wait until the stopped runs' threads end (a second Ctrl-C does not cut it short: they are stopping)."""
    while True:
        try:
            if runs.wait(WAIT):
                return
        except KeyboardInterrupt:
            continue


def lockstep_refusal(robot: Robot, integrator: Integrator, model: DynamicsModel) -> str | None:
    """Why runs of ``robot`` with this integrator and plant cannot run in lockstep, or None when they
    can: the integrator must have a fixed step, the plant be the exact tree (no loop closures), and
    the dynamics kernel take the tree (:data:`~.compiled.TREE_ABA` ``"kernel"``)."""
    spec = INTEGRATORS.get(getattr(integrator, "name", None), None)
    if spec is None or spec.adaptive:
        return f"integrator '{getattr(integrator, 'name', integrator)}' has no fixed step"
    if getattr(model, "name", None) != "exact":
        return f"the plant model is '{getattr(model, 'name', model)}', not the exact tree"
    if compiled.TREE_ABA != "kernel":
        return f"compiled.TREE_ABA is '{compiled.TREE_ABA}'"
    return kernel_refusal(robot.model)


def start_runs(robot: Robot, q0: np.ndarray, v0: np.ndarray, duration: float, control_period: float,
               integrator: Integrator, model: DynamicsModel, controllers: Sequence[Controller] | None = None,
               wrenches: tuple[ExternalWrench, ...] = (), record_every: int = 1, threads: int = 1,
               keep: bool = True, plants: Sequence[pin.Model] | None = None,
               lockstep: bool | None = None) -> ManyRuns:
    """Start one run per row of ``q0``, ``v0`` on ``threads`` C++ threads; they run on while this
    thread goes on, until :meth:`ManyRuns.finish`.

    Args:
        robot: the robot.
        q0, v0: initial Pinocchio states, one run per row (runs, nq), (runs, nv).
        duration, control_period, integrator, model, wrenches, record_every: as in
            :func:`~freefloat.dynamics.simulation.run`, the same for every run (the plant
            ``model`` must be one the compiled loop runs, the integrator a compiled one).
        controllers: None (torque-free), or one computed-torque controller per run on a quintic
            (``ComputedTorque``), all with the same duration and gains.
        threads: C++ threads (at most one per run).
        keep: keep every run's telemetry in one block for the returned results; otherwise each
            run's rows are copied out for ``on_result`` and their slot reused (memory for
            ``2 threads`` runs, whatever their number).
        plants: one Pinocchio model per run, ``robot.model`` with other bodies (masses, CoMs,
            rotational inertias; joints, placements, armature and gravity the same), each run's
            plant; None: ``robot.model`` for every run. The controllers keep their own robot (one
            for every run): their law computes on its model, whatever the plant's bodies.
        lockstep: run :data:`~.kernel.LANES` runs at a time per thread in lockstep (see the module
            docstring); None (default): wherever :func:`lockstep_refusal` allows, the kernel
            evaluates with AVX2 (its baseline lanes cost more than single states) and there are at
            least two runs per thread.

    Raises:
        InvalidArgument: naming the run for a state of the wrong size or not finite, the reason the
            compiled loop cannot run the plant or integrator, a controller without a compiled
            quintic or with other gains or duration than the first run's, controllers whose robots
            have other numbers than the first run's, ``plants`` differing from ``robot.model`` in
            more than bodies, ``threads`` below 1 or above :data:`MAX_THREADS`, telemetry that
            would not fit in memory, or ``lockstep=True`` where :func:`lockstep_refusal` says why not.
    """
    steps = control_periods(duration, control_period)
    q0, v0 = np.atleast_2d(np.asarray(q0, dtype=float)), np.atleast_2d(np.asarray(v0, dtype=float))
    if q0.ndim != 2 or v0.ndim != 2 or len(q0) != len(v0) or len(q0) == 0:
        raise InvalidArgument(f"q0 and v0 must hold one state per run, as (runs, nq) and (runs, nv) arrays; got shapes "
                              f"{q0.shape} and {v0.shape}")
    record_every = min(whole_number("record_every", record_every), steps)
    threads = whole_number("threads", threads)
    if threads > MAX_THREADS:
        raise InvalidArgument(f"threads must be at most {MAX_THREADS} (this machine has {os.cpu_count()} cores), "
                              f"got {threads}")
    reason = compiled.unsupported(model, integrator)
    if reason is not None:
        raise InvalidArgument(f"many runs in one call take the compiled loop, which cannot run this: {reason}")
    threads = min(threads, len(q0))
    rows_per_run = (steps - 1) // record_every + 2  # one row every record_every periods, and the last
    lanes = _lanes(lockstep, robot, integrator, model, len(q0), threads)
    slots = len(q0) if keep else min(len(q0), 2 * threads * lanes)
    _check_memory(robot, slots * rows_per_run, len(q0), duration, record_every, keep)
    for i, (q, v) in enumerate(zip(q0, v0)):
        try:
            check_state(robot, q, v)
        except InvalidArgument as exc:
            raise InvalidArgument(f"run {i}: {exc}") from None
    law, start, delta = _quintics(controllers, len(q0), robot)
    bodies = None if plants is None else _bodies(robot, plants, len(q0))
    law_robot = _law_robot(controllers, robot, plants is not None)
    block = Telemetry.allocate(slots * rows_per_run, robot.model.nq, robot.model.nv, robot.n_joints,
                               len(robot.end_effectors))
    field = field_of(robot, wrenches)
    loops: list[compiled.CompiledLoop] = []
    arrays = compiled.model_arrays(robot)
    try:
        for _ in range(threads * lanes):
            loops.append(compiled.CompiledLoop(robot, integrator, control_period, 0.0, record_every, law, field,
                                               data=plant_data(robot, model), plant=model, law_robot=law_robot,
                                               arrays=arrays))
        batch = _sim.Batch([loop.sim for loop in loops], q0, v0, steps, start, delta, bodies,
                           compiled.chunk_arrays(block), rows_per_run, slots, lanes)
    except BaseException:
        for loop in loops:
            loop.release()
        raise
    return ManyRuns(loops, batch, len(q0), block, rows_per_run, steps, control_period, keep, bodies is not None)


def run_many(robot: Robot, q0: np.ndarray, v0: np.ndarray, duration: float, control_period: float,
             integrator: Integrator, model: DynamicsModel, controllers: Sequence[Controller] | None = None,
             wrenches: tuple[ExternalWrench, ...] = (), record_every: int = 1, threads: int = 1,
             on_result: OnResult | None = None, keep: bool = True,
             plants: Sequence[pin.Model] | None = None, lockstep: bool | None = None) -> list[Result | None]:
    """:func:`start_runs` then :meth:`ManyRuns.finish`: the runs' results by index (see both)."""
    return start_runs(robot, q0, v0, duration, control_period, integrator, model, controllers, wrenches,
                      record_every, threads, keep, plants, lockstep).finish(on_result)


def _lanes(lockstep: bool | None, robot: Robot, integrator: Integrator, model: DynamicsModel, runs: int,
           threads: int) -> int:
    """Loops per thread: :data:`~.kernel.LANES` in lockstep (``lockstep``, see :func:`start_runs`),
    else 1; :class:`InvalidArgument` for ``lockstep=True`` where it cannot be."""
    if lockstep is False or (lockstep is None and (runs < 2 * threads or kernel_isa() != "avx2")):
        return 1
    reason = lockstep_refusal(robot, integrator, model)
    if reason is not None and lockstep:
        raise InvalidArgument(f"these runs cannot run in lockstep: {reason}")
    return 1 if reason is not None else LANES


def _check_memory(robot: Robot, rows: int, runs: int, duration: float, record_every: int, keep: bool) -> None:
    """Refuse up front a block of ``rows`` telemetry rows that would not fit in memory."""
    one = Telemetry.allocate(1, robot.model.nq, robot.model.nv, robot.n_joints, len(robot.end_effectors))
    need = rows * sum(getattr(one, f.name).nbytes for f in fields(one))
    if need > (allowed := usable_memory()):
        raise InvalidArgument(f"{runs} runs of {duration} s recording every {record_every} periods: their telemetry "
                              f"needs about {need / 1e9:.3g} GB{' (keep=True holds every run)' if keep else ''}, more "
                              f"than {allowed / 1e9:.3g} GB that runs may take here; fewer runs, keep=False, or a "
                              "larger record_every")


def _bodies(robot: Robot, plants: Sequence[pin.Model], runs: int) -> np.ndarray:
    """Each run's plant bodies (runs, njoints - 1, 13), joints 1.. in order: mass (kg), CoM in the
    joint frame (3, m), rotational inertia about the CoM in joint-frame axes (3, 3 row-major,
    kg m^2)."""
    if len(plants) != runs:
        raise InvalidArgument(f"plants: one per run expected ({runs}), got {len(plants)}")
    for i, plant in enumerate(plants):
        if not compiled.same_numbers(plant, robot.model, bodies=False):
            raise InvalidArgument(f"run {i}: its plant differs from the robot's model in more than its bodies' masses "
                                  "and inertias (joints, placements, armature or gravity)")
    return np.array([[np.r_[body.mass, body.lever, body.inertia.ravel()] for body in plant.inertias[1:]]
                     for plant in plants], dtype=float)


def _law_robot(controllers: Sequence[Controller] | None, robot: Robot, plants_vary: bool) -> Robot | None:
    """The robot the runs' compiled law computes on when it is not the loop's plant (see
    :func:`~freefloat.dynamics.compiled.law_robot`): the controllers' own, one for every run, when
    its numbers differ from ``robot``'s or the runs' plants vary."""
    if controllers is None:
        return None
    own = [getattr(c, "robot", None) for c in controllers]
    if not plants_vary and all(compiled.law_robot(c, robot) is None for c in controllers):
        return None
    for i, other in enumerate(own):
        if other is None or not (other is own[0] or compiled.same_numbers(other.model, own[0].model)):
            raise InvalidArgument(f"run {i}: its controller's robot has other numbers than run 0's controller's; runs "
                                  "in one call share the model their law computes on")
    return own[0]


#: The law kind runs in one call may have (``_sim.Batch`` varies its ``start`` and ``delta`` per run).
BATCH_LAW = "quintic_computed_torque"


def _quintics(controllers: Sequence[Controller] | None, runs: int,
              robot: Robot) -> tuple[compiled.CompiledLaw | None, np.ndarray | None, np.ndarray | None]:
    """The first run's compiled law, and every run's quintic start and delta (runs, n), or Nones:
    every run's law is the first's with its own ``start`` and ``delta`` (``dataclasses.replace``)."""
    if controllers is None:
        return None, None, None
    if len(controllers) != runs:
        raise InvalidArgument(f"controllers: one per run expected ({runs}), got {len(controllers)}")
    laws = [compiled.law_of(c, robot) for c in controllers]
    first = laws[0]
    for i, law in enumerate(laws):
        if getattr(law, "kind", None) != BATCH_LAW:
            raise InvalidArgument(f"run {i}: its controller has no compiled quintic (a computed torque on a quintic, "
                                  "on a robot of this one's joints and frames, runs in one call; others run one "
                                  "by one with simulation.run)")
        if not _same_law(dataclasses.replace(law, start=first.start, delta=first.delta), first):
            raise InvalidArgument(f"run {i}: its quintic's duration and gains (kp, kd) differ from run 0's; runs in "
                                  "one call share them")
    return first, np.array([law.start for law in laws], dtype=float), np.array([law.delta for law in laws], dtype=float)


def _same_law(a: Any, b: Any) -> bool:
    """Whether two law records have equal fields (arrays compared element-wise)."""
    return all(np.array_equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
