"""The cheapest dynamics model whose error stays under a tolerance: the parts that know no scene.

A scene with ``simulation.model = "auto"`` (:mod:`freefloat.app.experiments.model_choice`) ranks
candidate plants by their measured cost per acceleration, runs the ones cheaper than the exact
model over a short pilot beside it, and keeps the cheapest whose error stays under the tolerance
once extrapolated to the whole run.

State error of a run against the exact one, over their common rows:

.. math:: e = \\max_k \\max(\\|\\ominus(q^{ex}_k, q_k)\\|_\\infty, \\|v_k - v^{ex}_k\\|_\\infty),

with ``\\ominus`` Pinocchio's ``difference`` of full configurations (rad or m; base part in the
base-link frame) and ``v`` in rad/s or m/s. A model error that is a constant acceleration error
grows as ``t^2`` in ``q`` and ``t`` in ``v``, so the pilot's error over ``T_p`` s is extrapolated to
a run of ``T`` s as ``e (T / T_p)^2``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from .base import DynamicsModel

#: Registry models that match the exact dynamics in every regime, with zero linear momentum, and
#: with zero momentum (docs/models.md; pinned by tests/test_models.py on both sides).
ALWAYS = ("exact", "standard_corrected")
ZERO_LINEAR_MOMENTUM = ("standard_full_hdot", "momentum_routh")
ZERO_MOMENTUM = ("reduced", "momentum_mono", "momentum_multi")
#: A momentum component at most this large (kg m/s, kg m^2/s) counts as zero.
ZERO = 1e-12


def regime_models(momentum: np.ndarray | None) -> tuple[str, ...]:
    """The registry models that match the exact dynamics for a run that conserves ``momentum``
    (``[P; L]``, (6,), about the inertial origin); None: the momentum is not conserved (gravity or
    external wrenches), where only the exact models do (``standard_corrected`` matches ABA with the
    same gravity and wrenches to 1e-13: docs/models.md, tests/test_models.py)."""
    if momentum is None:
        return ALWAYS
    names = ALWAYS
    if np.abs(momentum[:3]).max() <= ZERO:
        names += ZERO_LINEAR_MOMENTUM
        if np.abs(momentum[3:]).max() <= ZERO:
            names += ZERO_MOMENTUM
    return names


def seconds_per_call(models: Sequence[DynamicsModel], states: Sequence[tuple[np.ndarray, np.ndarray]],
                     calls: int = 50, repeats: int = 3) -> list[float]:
    """Cost of one ``acceleration`` of each model at its state ``(q, v)`` with zero torques, s:
    the best of ``repeats`` rounds of ``calls`` calls, the models taking turns in each round."""
    best = [np.inf] * len(models)
    for _ in range(repeats):
        for i, (model, (q, v)) in enumerate(zip(models, states)):
            tau = np.zeros(len(v))
            start = time.perf_counter()
            for _ in range(calls):
                model.acceleration(q, v, tau)
            best[i] = min(best[i], (time.perf_counter() - start) / calls)
    return best


def state_error(model: pin.Model, q_ref: np.ndarray, v_ref: np.ndarray, q: np.ndarray, v: np.ndarray) -> float:
    """The state error ``e`` of the module docstring between rows ``q`` (N, nq), ``v`` (N, nv) and
    the exact rows ``q_ref``, ``v_ref``; their first ``min`` rows are compared, and a run that
    stopped early or has non-finite rows has error infinity."""
    rows = min(len(q), len(q_ref))
    if rows < len(q_ref) or not (np.isfinite(q).all() and np.isfinite(v).all()):
        return float("inf")
    dq = max((np.abs(pin.difference(model, a, b)).max() for a, b in zip(q_ref[:rows], q[:rows])), default=0.0)
    return float(max(dq, np.abs(v[:rows] - v_ref[:rows]).max(initial=0.0)))


class Pilot(NamedTuple):
    """A pilot run: wall time of its loop (s) and its rows ``q`` (N, nq), ``v`` (N, nv) of the
    full robot."""

    wall_time_s: float
    q: np.ndarray
    v: np.ndarray


class Candidate(NamedTuple):
    """A plant to try: registry model name, lock setting (``"none"``, ``"auto"``), its cost per
    acceleration (s) and a function running its pilot."""

    model: str
    lock: str
    seconds_per_call: float
    pilot: Callable[[], Pilot]


@dataclass
class Trial:
    """What the choice measured of one candidate (pilot fields None when it was not run)."""

    model: str
    lock: str
    seconds_per_call: float
    pilot_wall_time_s: float | None = None
    error: float | None = None
    predicted_error: float | None = None
    accepted: bool = False


@dataclass
class Choice:
    """The chosen plant and how it was chosen.

    Attributes:
        model, lock: the chosen model name and lock setting.
        tolerance: largest accepted predicted state error (rad or m, rad/s or m/s).
        growth: the factor ``(T / T_p)^2`` from the pilot's error to the run's.
        speedup: reference pilot wall time over the chosen one's (1 when the reference is chosen).
        predicted_error: the chosen plant's predicted error over the run (0 for the reference).
        trials: every candidate, cheapest first per call, reference first.
    """

    model: str
    lock: str
    tolerance: float
    growth: float
    speedup: float = 1.0
    predicted_error: float = 0.0
    trials: list[Trial] = field(default_factory=list)

    def as_dict(self) -> dict:
        """Plain types for a JSON summary."""
        return asdict(self)


def choose(reference: Candidate, candidates: Sequence[Candidate], model: pin.Model, tolerance: float,
           growth: float, repeats: int = 2) -> Choice:
    """The cheapest candidate whose predicted error stays under ``tolerance``.

    Candidates cheaper per call than ``reference`` (the exact plant) are tried cheapest first:
    each runs its pilot ``repeats`` times taking turns with the reference's (wall time: the best
    of each), its error against the reference's pilot is multiplied by ``growth``, and the first
    whose prediction is at most ``tolerance`` and whose pilot ran faster than the reference's is
    chosen. No pilot runs when no candidate is cheaper; when none passes, the reference is chosen.

    Args:
        model: the full robot's Pinocchio model (for the configuration difference).
    """
    choice = Choice(reference.model, reference.lock, tolerance, growth,
                    trials=[Trial(reference.model, reference.lock, reference.seconds_per_call, accepted=True)])
    ranked = sorted(candidates, key=lambda c: c.seconds_per_call)
    choice.trials += [Trial(c.model, c.lock, c.seconds_per_call) for c in ranked]
    for candidate, trial in zip(ranked, choice.trials[1:]):
        if candidate.seconds_per_call >= reference.seconds_per_call:
            break
        runs = [(reference.pilot(), candidate.pilot()) for _ in range(repeats)]
        exact, pilot = runs[0]
        exact_wall = min(r.wall_time_s for r, _ in runs)
        choice.trials[0].pilot_wall_time_s = min(exact_wall, choice.trials[0].pilot_wall_time_s or np.inf)
        trial.pilot_wall_time_s = min(p.wall_time_s for _, p in runs)
        trial.error = state_error(model, exact.q, exact.v, pilot.q, pilot.v)
        trial.predicted_error = trial.error * growth
        if trial.predicted_error <= tolerance and trial.pilot_wall_time_s < exact_wall:
            trial.accepted, choice.trials[0].accepted = True, False
            choice.model, choice.lock = candidate.model, candidate.lock
            choice.speedup = exact_wall / trial.pilot_wall_time_s
            choice.predicted_error = trial.predicted_error
            break
    return choice


__all__ = [
    "ALWAYS",
    "ZERO_LINEAR_MOMENTUM",
    "ZERO_MOMENTUM",
    "Candidate",
    "Choice",
    "Pilot",
    "Trial",
    "choose",
    "regime_models",
    "seconds_per_call",
    "state_error",
]
