"""A batch's runs many at a time in one compiled call (:mod:`freefloat.dynamics.many_runs`), on
C++ threads, where they can share one: runs of a ``joint_space`` scene on the exact plant (its
loop closures included) with a compiled integrator, torque-free or under computed torque on its
quintic, that vary their initial state and the plant's masses (the controller keeping the
nominal robot: its compiled law computes on that robot's model).

The runs go in groups of :data:`GROUP_PER_THREAD` per thread. While one group runs without
Python's lock, this thread prepares the next one (each run's scene resolved as
:func:`~.one_run.run_one` resolves it) and starts it, then summarises the first group's runs as
they finish. A run whose setup cannot share the group's loop (another plant chosen by
``model = "auto"``, say) runs on its own, as :func:`~.one_run.run_one`. Every row is the one
:func:`~.one_run.run_one` gives for the same plan (tested), but for its wall times, also where the
runs go in lockstep (:data:`LOCKSTEP`).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...dynamics import compiled
from ...dynamics.many_runs import BATCH_LAW, ManyRuns, start_runs
from ...dynamics.result import Result
from ..experiments import joint_space
from ..experiments.robot_run import RobotSetup
from .one_run import fill_row, new_row, prepared, run_one
from .variations import RunPlan

OnRow = Callable[[dict[str, Any]], None]

#: Runs per thread in one call; the next group is prepared while one runs.
GROUP_PER_THREAD = 8
#: The runs of a call in lockstep (:func:`~freefloat.dynamics.many_runs.start_runs`' ``lockstep``):
#: None, wherever it applies.
LOCKSTEP: bool | None = None


def shares_loop(plan: RunPlan, setup: Any) -> bool:
    """Whether ``plan``'s run (prepared as ``setup``) can run in one call with others."""
    return (plan.scene.kind == "joint_space" and isinstance(setup, RobotSetup)
            and setup.lock is None and setup.wheels is None and not setup.environment
            and setup.scene.simulation.backend != "python"
            and compiled.unsupported(setup.model, setup.integrator) is None
            and (setup.controller is None
                 or getattr(compiled.law_of(setup.controller, setup.plant), "kind", None) == BATCH_LAW))


def can_run(plans: list[RunPlan]) -> bool:
    """Whether the batch's first run shares a loop (then its others are expected to)."""
    try:
        return shares_loop(plans[0], prepared(plans[0]))
    except Exception:  # its row will say why
        return False


@dataclass
class _Group:
    """Runs started in one call: their plans, setups, preparation times (s) and the call."""

    plans: list[RunPlan]
    setups: list[RobotSetup]
    preparation: list[float]
    runs: ManyRuns | None


def run_in_groups(plans: list[RunPlan], threads: int, on_row: OnRow) -> None:
    """Run ``plans`` in groups of one compiled call each on ``threads`` threads, giving each row
    to ``on_row`` as its run finishes. Ctrl-C (or SIGTERM turned into it) stops the running
    groups' runs within :data:`~freefloat.dynamics.many_runs.SLICE_PERIODS` periods, gives the
    finished rows and propagates (the interrupted runs are not rows)."""
    size = GROUP_PER_THREAD * threads
    live: list[_Group] = []  # started, not finished: at most the one running and the next
    try:
        for first in range(0, len(plans), size):
            live.append(_start(plans[first:first + size], threads, on_row))
            if len(live) == 2:
                _finish(live.pop(0), on_row)
        while live:
            _finish(live.pop(0), on_row)
    except BaseException:
        for group in live:
            if group.runs is not None:
                group.runs.stop()
        for group in live:  # their finished rows (a failing on_row fails again: the first error propagates)
            with contextlib.suppress(Exception):
                _finish(group, on_row, raise_interrupt=False)
        raise


def _start(plans: list[RunPlan], threads: int, on_row: OnRow) -> _Group:
    """Prepare ``plans``; start those that share the first one's loop, run the others here."""
    group = _Group([], [], [], None)
    for plan in plans:
        start = time.perf_counter()
        try:
            setup = prepared(plan)
        except Exception:
            _run_alone(plan, on_row)  # its failure, as a row
            continue
        if shares_loop(plan, setup) and (not group.setups or _same_loop(group.setups[0], setup)):
            group.plans.append(plan)
            group.setups.append(setup)
            group.preparation.append(time.perf_counter() - start)
        else:
            _run_alone(plan, on_row)
    if group.setups:
        first, sim = group.setups[0], group.setups[0].scene.simulation
        states = [s.plant_state() for s in group.setups]
        controllers = None if first.controller is None else [s.controller for s in group.setups]
        plants = [s.plant.model for s in group.setups] if any(p.masses for p in group.plans) else None
        group.runs = start_runs(first.plant, np.array([q for q, _ in states]), np.array([v for _, v in states]),
                                sim.duration, sim.control_period, first.integrator, first.model, controllers,
                                first.wrenches, sim.record_every, threads, keep=False, plants=plants,
                                lockstep=LOCKSTEP)
    return group


def _run_alone(plan: RunPlan, on_row: OnRow) -> None:
    """``plan``'s run on its own (:func:`~.one_run.run_one`); ``KeyboardInterrupt`` if it was interrupted."""
    row = run_one(plan)
    if row["status"] == "interrupted":
        raise KeyboardInterrupt
    on_row(row)


def _same_loop(first: RobotSetup, setup: RobotSetup) -> bool:
    """Whether ``setup`` runs on ``first``'s loop: the same plant model, integrator and law kind."""
    return (setup.model.name == first.model.name and setup.integrator.name == first.integrator.name
            and (setup.controller is None) == (first.controller is None))


def _finish(group: _Group, on_row: OnRow, raise_interrupt: bool = True) -> None:
    """The group's rows as its runs finish; ``KeyboardInterrupt`` after them when some run was cut short."""
    if group.runs is None:
        return
    cut: list[int] = []

    def row_of(index: int, result: Result) -> None:
        if result.status == "interrupted":
            cut.append(index)
            return
        start = time.perf_counter()
        row, setup = new_row(group.plans[index]), group.setups[index]
        try:
            fill_row(row, joint_space.outcome_of(setup, result), setup)
        except Exception as exc:  # the run's own failure, recorded in its row
            row["message"] = f"{type(exc).__name__}: {exc}"
        row["wall_time_s"] = group.preparation[index] + result.wall_time_s + time.perf_counter() - start
        on_row(row)

    group.runs.finish(row_of)
    if raise_interrupt and (cut or group.runs.interrupted):
        raise KeyboardInterrupt
