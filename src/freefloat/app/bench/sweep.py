"""Work against precision: each method's median wall time and its errors against the reference."""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import SimulationDiverged
from ...robot.conventions import momentum_about_origin
from .methods import Method, method_run, reference
from .scenes import TumblingScene


@dataclass(frozen=True)
class Point:
    """One measured method on one scene.

    Attributes:
        method: what ran.
        wall_time: median wall time of the repeated runs, s.
        state_error: ``|[log(q_ref^-1 q); v - v_ref]|`` at the end (Pinocchio's difference, 2-norm).
        momentum_error: ``|h(T) - h_ref(T)|``, h = [P; L about the inertial origin] (kg m/s, kg m^2/s).
        energy_error: ``|E(T) - E_ref(T)|``, kinetic energy, J.
    """

    method: Method
    wall_time: float
    state_error: float
    momentum_error: float
    energy_error: float


def invariants(model: pin.Model, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
    """Momentum ``[P; L about the origin]`` (6,) and kinetic energy (J) at ``(q, v)``."""
    data = model.createData()
    return momentum_about_origin(model, data, q, v), float(pin.computeKineticEnergy(model, data, q, v))


def errors(model: pin.Model, state: tuple[np.ndarray, np.ndarray],
           ref: tuple[np.ndarray, np.ndarray]) -> tuple[float, float, float]:
    """State, momentum and energy errors of ``state`` against ``ref`` (see :class:`Point`)."""
    (q, v), (q_ref, v_ref) = state, ref
    h, e = invariants(model, q, v)
    h_ref, e_ref = invariants(model, q_ref, v_ref)
    state_error = float(np.linalg.norm(np.concatenate([pin.difference(model, q_ref, q), v - v_ref])))
    return state_error, float(np.linalg.norm(h - h_ref)), abs(e - e_ref)


def measure(scene: TumblingScene, method: Method, ref: tuple[np.ndarray, np.ndarray], repeats: int) -> Point:
    """Run ``method`` ``repeats`` times; the median wall time and the errors of the last run.

    A run that diverges keeps its time and gets infinite errors.
    """
    run = method_run(scene, method)
    times, state = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        try:
            state = run()
        except (SimulationDiverged, ArithmeticError):
            state = None
        times.append(time.perf_counter() - start)
    if state is None or not (np.all(np.isfinite(state[0])) and np.all(np.isfinite(state[1]))):
        return Point(method, statistics.median(times), np.inf, np.inf, np.inf)
    return Point(method, statistics.median(times), *errors(scene.model, state, ref))


def sweep(scene: TumblingScene, points: list[Method], repeats: int = 3) -> tuple[list[Point], float]:
    """Every method of ``points`` measured on ``scene`` in this process, and the reference's time (s)."""
    start = time.perf_counter()
    ref = reference(scene)
    reference_time = time.perf_counter() - start
    return [measure(scene, method, ref, repeats) for method in points], reference_time
