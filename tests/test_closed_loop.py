"""The 5R's closed loop with the control period apart from the step: held efforts agree with the
existing step-held loop, the continuous law sees every RK4 stage's time, and holding longer
costs first-order accuracy."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from freefloat.errors import FreefloatError
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.held_control import steps_per_period, track_held
from freefloat.parallel.sliding_mode import (
    PlatformControl,
    PlatformController,
    circle_reference,
    track,
)

START = np.array([0.07, 0.17])


@pytest.fixture(scope="module")
def plant_q0():
    plant = five_bar(TRUE_PARAMETERS)
    return plant, plant.assemble(START, elbow_guess(TRUE_PARAMETERS, START))


def computed_torque() -> PlatformControl:
    return PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0)


def test_holding_over_one_step_is_the_step_held_loop(plant_q0):
    """With the period equal to the step, the errors are those of sliding_mode.track (mechanism.simulate)."""
    plant, q0 = plant_q0
    held = track_held(plant, computed_torque(), q0, 0.02, 1e-3, 1e-3)
    _, _, efforts, log = track(TRUE_PARAMETERS, PlatformController(FiveBarParameters(), circle_reference, 40.0), 0.02, 1e-3)
    np.testing.assert_allclose(held.e[:-1], np.array([row[1] for row in log]), atol=1e-13)
    np.testing.assert_allclose(held.efforts, efforts, rtol=1e-10, atol=1e-10)
    assert held.completed


@dataclass
class StageSpy:
    """A control law of zero effort that records the times it is asked at."""

    lam: float = 1.0
    times: list | None = None

    def reference(self, t: float):
        return np.zeros(2), np.zeros(2), np.zeros(2)

    def efforts(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        self.times.append(t)
        return np.zeros(2)


def test_continuous_law_is_asked_at_every_rk4_stage_time(plant_q0):
    """Two steps of 1 ms: the law is evaluated at 0, 0.5, 0.5, 1, 1, 1.5, 1.5, 2 ms."""
    plant, q0 = plant_q0
    spy = StageSpy(times=[])
    run = track_held(plant, spy, q0, 2e-3, 1e-3, None)
    np.testing.assert_allclose(spy.times, np.array([0, 0.5, 0.5, 1, 1, 1.5, 1.5, 2]) * 1e-3, atol=1e-15)
    np.testing.assert_allclose(run.update_t, [0.0, 1e-3], atol=1e-15)


def test_holding_longer_departs_from_the_continuous_law_to_first_order(plant_q0):
    """Computed torque: the gap to the continuous law shrinks about tenfold for a tenfold shorter hold."""
    plant, q0 = plant_q0
    control = computed_torque()
    base = track_held(plant, control, q0, 0.02, 1e-5, None).e
    gap = [np.abs(track_held(plant, control, q0, 0.02, 1e-5, period).e - base).max() for period in (1e-3, 1e-4)]
    assert 5.0 < gap[0] / gap[1] < 20.0


def test_a_period_that_is_not_a_whole_number_of_steps_is_refused():
    """0.15 ms over 0.1 ms steps is refused, naming both."""
    with pytest.raises(FreefloatError, match=r"0.00015 s .* \(0.0001 s\)"):
        steps_per_period(1.5e-4, 1e-4)


@dataclass
class Kick(StageSpy):
    """A law that gives absurd efforts: the plant comes apart."""

    def efforts(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return np.full(2, 1e9)


def test_a_plant_that_comes_apart_stops_early_keeping_its_samples(plant_q0):
    """The run stops, says so, and keeps every sample up to there."""
    plant, q0 = plant_q0
    run = track_held(plant, Kick(), q0, 0.1, 1e-3, 1e-3)
    assert not run.completed
    assert 1 <= len(run.t) < 101 and len(run.e) == len(run.s) == len(run.t)
