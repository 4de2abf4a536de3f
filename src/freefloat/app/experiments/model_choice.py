"""``simulation.model = "auto"``: the cheapest plant whose state error stays under the scene's
``simulation.tolerance``, chosen by a pilot run (:mod:`freefloat.dynamics.models.selection`).

The candidates are the registry models that match the exact dynamics in the scene's momentum
regime at the start (every model when the momentum is conserved and zero, the exact ones with
gravity or wrenches), each with the scene's lock setting and with ``lock = "auto"`` (the joints the
scene never moves locked). Their costs per acceleration are measured side by side at the initial
state; those cheaper than the exact model on the scene's lock setting run the first
:data:`PILOT_SHARE` of the scene (at least :data:`PILOT_PERIODS` control periods) beside it, cheapest
first (each pilot run twice, taking turns with the exact one's, for its best wall time), and
the first whose pilot error times ``(T / T_p)^2`` stays under the tolerance and whose pilot ran
faster is chosen. Capture scenes always simulate the exact plant (their loop does not
take a plant model), and so does a run no longer than its pilot (at most :data:`PILOT_PERIODS`
control periods: piloting would cost more than the run).
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

from ...dynamics.models import make_model
from ...dynamics.models.selection import Candidate, Pilot, choose, regime_models, seconds_per_call
from ...errors import FreefloatError
from ...robot.conventions import momentum_about_origin
from ..scenes import Scene
from . import experiment_for
from .robot_run import RobotSetup, control_steps

#: Share of the scene's duration the pilot simulates, and the fewest and most control periods it
#: takes (the most: a long run's pilot stays short; its error is extrapolated over the run anyway).
PILOT_SHARE = 0.02
PILOT_PERIODS = 20
PILOT_MAX_PERIODS = 1000


def with_plant(scene: Scene, model: str, lock: str, duration: float | None = None) -> Scene:
    """``scene`` with the plant ``model`` and ``lock`` setting (and ``duration`` s, recording every
    period, without figures or page, for a pilot)."""
    sim = dataclasses.replace(scene.simulation, model=model, lock=lock)
    if duration is None:
        return dataclasses.replace(scene, simulation=sim)
    return dataclasses.replace(scene, simulation=dataclasses.replace(sim, duration=duration, record_every=1),
                               output=dataclasses.replace(scene.output, figures=False, html=False))


def pilot_periods(scene: Scene) -> int:
    """Control periods of the pilot: :data:`PILOT_SHARE` of the scene's, at least
    :data:`PILOT_PERIODS`, at most :data:`PILOT_MAX_PERIODS` and all."""
    periods = control_steps(scene)
    return min(periods, PILOT_MAX_PERIODS, max(PILOT_PERIODS, round(PILOT_SHARE * periods)))


def resolve(scene: Scene, models: tuple[str, ...] | None = None) -> tuple[Scene, dict[str, Any] | None]:
    """``scene`` with a concrete plant, and the record of the choice (None when the scene names
    its model).

    Args:
        models: the candidate models (default: :func:`~freefloat.dynamics.models.selection.regime_models`
            of the scene's initial momentum); the exact model is the reference either way.
    """
    sim = scene.simulation
    if sim.model != "auto":
        return scene, None
    if scene.kind in ("capture", "capture_identification", "two_hand_capture") or scene.closures or scene.wheels:
        return with_plant(scene, "exact", sim.lock), {"model": "exact", "lock": sim.lock,
                                                      "reason": "capture scenes, closed loops and reaction wheels "
                                                                "simulate the exact plant"}
    if pilot_periods(scene) >= control_steps(scene):
        return with_plant(scene, "exact", sim.lock), {"model": "exact", "lock": sim.lock,
                                                      "reason": "the run is no longer than a pilot run"}
    experiment = experiment_for(scene)
    setups = {lock: experiment.prepare(with_plant(scene, "exact", lock)) for lock in dict.fromkeys((sim.lock, "auto"))}
    if "auto" in setups and sim.lock != "auto" and _locked(setups["auto"]) == _locked(setups[sim.lock]):
        del setups["auto"]  # nothing more to lock
    full = setups[sim.lock]
    if models is None:
        conserved = not (scene.environment or any(scene.robot.gravity))
        momentum = momentum_about_origin(full.robot.model, full.robot.model.createData(), full.q0, full.v0)
        models = regime_models(momentum if conserved else None)
    pairs, plants = [], []
    for lock, setup in setups.items():
        for name in dict.fromkeys(("exact", *models)):
            try:
                plants.append(make_model(name, setup.plant))
            except (FreefloatError, ValueError, RuntimeError):  # e.g. a GJM model of an arm with every joint locked
                continue
            pairs.append((name, lock))
    costs = seconds_per_call(plants, [setups[lock].plant_state() for _, lock in pairs])
    duration = pilot_periods(scene) * sim.control_period

    prepared: dict[tuple[str, str], Any] = {}

    def pilot(name: str, lock: str) -> Pilot:
        """One pilot run, on a fresh copy of the pilot's setup (controllers keep state)."""
        if (name, lock) not in prepared:
            prepared[name, lock] = experiment.prepare(with_plant(scene, name, lock, duration))
        outcome = experiment.run(copy.deepcopy(prepared[name, lock]))
        if outcome.status == "interrupted":  # Ctrl-C or SIGTERM: the user stops the whole run
            raise KeyboardInterrupt(outcome.message)
        return Pilot(outcome.wall_time_s, outcome.telemetry.q, outcome.telemetry.v)

    candidates = [Candidate(name, lock, cost, lambda name=name, lock=lock: pilot(name, lock))
                  for (name, lock), cost in zip(pairs, costs)]
    choice = choose(candidates[0], candidates[1:], full.robot.model, sim.tolerance, (sim.duration / duration) ** 2)
    record = choice.as_dict()
    record.update(pilot_duration=duration, error_norm="max over rows of |q - q_exact|_inf (pin.difference, rad or m) "
                                                      "and |v - v_exact|_inf (rad/s or m/s)")
    return with_plant(scene, choice.model, choice.lock), record


def _locked(setup: RobotSetup) -> tuple[str, ...]:
    """Names of the joints ``setup`` locks."""
    return () if setup.lock is None else setup.lock.names


def describe(record: dict[str, Any]) -> str:
    """One line for the command line: the chosen plant, its speed-up and predicted error."""
    lock = " with the still joints locked" if record["lock"] == "auto" else ""
    if "reason" in record:
        return f"{record['model']}{lock} ({record['reason']})"
    if record["trials"][0]["accepted"]:
        others = len(record["trials"]) - 1
        tried = sum(t["pilot_wall_time_s"] is not None for t in record["trials"][1:])
        if not tried:
            why = f"none of the {others} other plants is cheaper per call here" if others else "no other plant applies"
            return f"{record['model']}{lock}: {why} (none piloted)"
        return (f"{record['model']}{lock}: no plant cheaper per call kept the predicted state error under "
                f"{record['tolerance']:.2g} ({tried} piloted over the first {record['pilot_duration']:.3g} s)")
    return (f"{record['model']}{lock}: {record['speedup']:.2f}x the exact plant's speed in a "
            f"{record['pilot_duration']:.3g} s pilot, predicted state error {record['predicted_error']:.2g} "
            f"(tolerance {record['tolerance']:.2g})")


__all__ = ["PILOT_MAX_PERIODS", "PILOT_PERIODS", "PILOT_SHARE", "describe", "pilot_periods", "resolve", "with_plant"]
