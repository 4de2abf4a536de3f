"""One run of a batch, as a worker process or thread runs it: prepare the varied scene, swap in the varied
plant, run the loop, and reduce the outcome to one flat row.

A worker loads and checks the scene's robot once (:func:`~freefloat.robot.loading.remembered_loads`
over :data:`ROBOTS`, kept as long as the process) and runs every run on one compiled loop per
robot structure (:mod:`freefloat.dynamics.compiled` keeps it), reset between runs: only the
varied state and masses change from one run to the next. Threads of one process may run
:func:`run_one` at once: what it sets process-wide (the BLAS limit, the warning filters) is
:class:`~freefloat.dynamics.threads.Shared` among them, and the loaded robots are remembered per
process (:data:`ROBOTS`), each thread getting its own copy of the model."""

from __future__ import annotations

import contextlib
import dataclasses
import time
import warnings
from collections.abc import Iterator
from typing import Any

import pinocchio as pin

from ...dynamics.integrators import make_integrator
from ...dynamics.models import make_model
from ...dynamics.threads import Shared, single_blas_thread
from ...robot.loading import remembered_loads
from ..experiments import Outcome, experiment_for
from ..experiments.robot_run import RobotSetup
from ..runner import fail_if_not_finite, fail_if_unbalanced, note_model_choice, resolved_setup
from .variations import RunPlan

#: Row keys that vary from one execution of the same run to the next (not results).
TIMINGS = ("wall_time_s", "sim_wall_time_s")
#: The robots this process has loaded for batch runs (see :func:`remembered_loads`), shared by its
#: threads (two threads loading the same robot at once may both load it; either copy is kept).
ROBOTS: dict = {}


def forget_robots() -> None:
    """Forget the robots this process loaded for batch runs (:data:`ROBOTS`): the next run loads
    and checks its robot again."""
    ROBOTS.clear()


@contextlib.contextmanager
def _ignoring_warnings() -> Iterator[None]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


#: Warnings ignored while any thread prepares a run (the batch showed the scene's warnings once):
#: the filters are process-wide, so the first thread in sets them and the last out restores them.
QUIET = Shared(_ignoring_warnings)


@single_blas_thread
def run_one(plan: RunPlan) -> dict[str, Any]:
    """Run ``plan`` and return its row: ``run``, ``seed``, ``status`` and ``message``, the drawn
    values, the outcome's summary flattened (``base_displacement[0]``,
    ``tracking_rms_per_arm.arm1_ee``) and ``wall_time_s`` (preparation and loop, s).

    A run that raises is a row with ``status = "failed"`` and the error as its message; it never
    raises but for ``KeyboardInterrupt`` outside the loop (inside, the loop returns what it
    computed with ``status = "interrupted"``)."""
    start = time.perf_counter()
    row = new_row(plan)
    try:
        setup = prepared(plan)
        fill_row(row, experiment_for(plan.scene).run(setup, None, None), setup)
    except Exception as exc:  # the run's own failure, recorded in its row
        row["message"] = f"{type(exc).__name__}: {exc}"
    row["wall_time_s"] = time.perf_counter() - start
    return row


def new_row(plan: RunPlan) -> dict[str, Any]:
    """The row of ``plan`` before its run: ``run``, ``seed``, ``status`` failed, no message, the drawn values."""
    return {"run": plan.index, "seed": plan.seed, "status": "failed", "message": "", **plan.varied}


def prepared(plan: RunPlan) -> Any:
    """The setup of ``plan``'s run: its scene resolved (the robot loaded once per process,
    ``model = "auto"`` chosen as in ``freefloat simulate``), with the varied plant masses.

    Raises:
        FreefloatError: naming what the varied scene gets wrong.
    """
    with QUIET, remembered_loads(ROBOTS):
        setup = resolved_setup(plan.scene)
    if plan.masses:
        with_plant_masses(setup, plan.masses)
    return setup


def fill_row(row: dict[str, Any], outcome: Outcome, setup: Any) -> None:
    """``row`` with the outcome's summary flattened, its status and message (non-finite
    results make it ``diverged``, a broken conservation law ``failed``) and the plant choice of ``setup``."""
    outcome = fail_if_unbalanced(fail_if_not_finite(note_model_choice(outcome, setup)), setup.scene)
    row.update(flatten(outcome.summary))
    row.update(status=outcome.status, message=outcome.message)


def with_plant_masses(setup: RobotSetup, factors: dict[str, float]) -> None:
    """Replace the plant of ``setup`` by the robot with each body's mass and rotational inertia
    (about its CoM) scaled by ``factors[joint name]`` (CoMs unchanged). The controller keeps the
    nominal robot; the loop, its telemetry and the summary (momentum, energy) use the plant."""
    model = pin.Model(setup.robot.model)
    for j, name in enumerate(model.names):
        if name in factors:
            body = model.inertias[j]
            model.inertias[j] = pin.Inertia(body.mass * factors[name], body.lever, body.inertia * factors[name])
    sim = setup.scene.simulation
    setup.robot = dataclasses.replace(setup.robot, model=model)
    setup.model = make_model(setup.model.name, setup.robot)  # the plant the scene resolved to
    setup.integrator = make_integrator(sim.integrator, model, sim.substeps, sim.rtol, sim.atol,
                                       project_momentum=sim.project_momentum)


def flatten(summary: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Scalars of ``summary`` by flat name: tables as ``key.sub``, lists as ``key[i]``."""
    out: dict[str, Any] = {}
    for key, value in summary.items():
        name = f"{prefix}.{key}" if prefix and not key.startswith("[") else f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, name))
        elif isinstance(value, (list, tuple)):
            out.update(flatten({f"[{i}]": v for i, v in enumerate(value)}, name))
        else:
            out[name] = value.item() if hasattr(value, "item") else value
    return out
