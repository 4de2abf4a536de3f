"""A mechanism's closed loop on the one engine (freefloat.parallel.closed_loop): the law held over
a control period or evaluated at every stage, compiled and Python loops equal, holding longer
costs first-order accuracy, and a plant that comes apart keeps its samples."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from freefloat.errors import FreefloatError
from freefloat.parallel.closed_loop import steps_per_period, track
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.sliding_mode import PlatformControl, circle_reference, printed_gains

START = np.array([0.07, 0.17])
EQ_187 = printed_gains(np.array([75.3, 108.0]), np.array([[1.25, 0.92], [1.68, 1.65]]),
                       {(0, 0): np.array([37.0, 54.1]), (1, 0): np.array([22.7, 35.5]), (1, 1): np.array([17.5, 28.5])})


@pytest.fixture(scope="module")
def plant_q0():
    plant = five_bar(TRUE_PARAMETERS)
    return plant, plant.assemble(START, elbow_guess(TRUE_PARAMETERS, START))


def computed_torque() -> PlatformControl:
    return PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0)


@pytest.mark.slow
@pytest.mark.parametrize("period", [1e-4, None], ids=["held over 10 steps", "per stage"])
@pytest.mark.parametrize("saturation", ["tanh", "sign"])
def test_compiled_loop_equals_the_python_loop(plant_q0, period, saturation):
    """Sliding mode (eq 187's gains) held over 10 steps or evaluated per RK4 stage: the compiled
    loop (plant, RKMK4 and law in C++) and the Python loop on the numpy reference agree to 1e-12."""
    plant, q0 = plant_q0
    control = PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0, EQ_187, saturation)
    numpy_control = PlatformControl(control.model.reference(), circle_reference, 40.0, EQ_187, saturation)
    compiled = track(plant, control, q0, 0.01, 1e-5, period, backend="compiled")
    python = track(plant.reference(), numpy_control, q0, 0.01, 1e-5, period, backend="python")
    assert (compiled.backend, python.backend) == ("compiled", "python")
    np.testing.assert_allclose(compiled.telemetry.q, python.telemetry.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(compiled.telemetry.efforts, python.telemetry.efforts, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(compiled.telemetry.reference, python.telemetry.reference, rtol=0, atol=1e-15)


@dataclass
class StageSpy:
    """A control law of zero effort that records the times it is asked at."""

    times: list

    def reference(self, t: float) -> None:
        return None

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        self.times.append(t)
        return np.zeros(2)


def test_continuous_law_is_asked_at_every_rk4_stage_time(plant_q0):
    """Two steps of 1 ms: besides the loop's call at each step's start (the efforts recorded),
    the law is evaluated at the stages 0, 0.5, 0.5, 1 and 1, 1.5, 1.5, 2 ms."""
    plant, q0 = plant_q0
    spy = StageSpy([])
    run = track(plant, spy, q0, 2e-3, 1e-3, None)
    expected = np.array([0, 0, 0.5, 0.5, 1, 1, 1, 1.5, 1.5, 2]) * 1e-3
    np.testing.assert_allclose(spy.times, expected, atol=1e-15)
    assert run.status == "completed" and len(run.telemetry.t) == 3


def test_holding_longer_departs_from_the_continuous_law_to_first_order(plant_q0):
    """Computed torque: the gap to the continuous law shrinks about tenfold for a tenfold shorter hold."""
    plant, q0 = plant_q0
    control = computed_torque()
    base = track(plant, control, q0, 0.02, 1e-5, None).telemetry.q
    gap = [np.abs(track(plant, control, q0, 0.02, 1e-5, period).telemetry.q - base).max() for period in (1e-3, 1e-4)]
    assert 5.0 < gap[0] / gap[1] < 20.0


def test_a_period_that_is_not_a_whole_number_of_steps_is_refused():
    """0.15 ms over 0.1 ms steps is refused, naming both."""
    with pytest.raises(FreefloatError, match=r"0.00015 s .* \(0.0001 s\)"):
        steps_per_period(1.5e-4, 1e-4)


class Kick(StageSpy):
    """A law that gives absurd efforts: the plant comes apart."""

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return np.full(2, 1e9)


@pytest.mark.parametrize("backend", ["python", "compiled"])
def test_a_plant_that_comes_apart_stops_early_keeping_its_samples(plant_q0, backend):
    """The run stops as diverged, says why and when, and keeps every sample up to there."""
    plant, q0 = plant_q0
    run = track(plant, Kick([]), q0, 0.1, 1e-3, 1e-3, backend="python" if backend == "python" else "auto")
    assert run.status == "diverged" and ("came apart" in run.message or "singular" in run.message), run.message
    assert 1 <= len(run.telemetry.t) < 101 and np.isfinite(run.telemetry.q).all()


@pytest.mark.slow
@pytest.mark.parametrize("integrator", ["euler", "rkmk4", "rk4_naive", "rkmk6", "rkmk8", "dopri5"])
def test_every_compiled_integrator_steps_the_chain_as_the_python_one(plant_q0, integrator):
    """Computed torque held over 1 ms, 2 substeps a period (dopri5 at rtol 1e-9): the compiled
    loop's state after 20 ms equals the Python loop's on the numpy reference to 1e-10."""
    from freefloat.dynamics.plants import CoupledChainPlant
    from freefloat.dynamics.simulation import run_plant

    plant, q0 = plant_q0
    control = computed_torque()
    numpy_control = PlatformControl(control.model.reference(), circle_reference, 40.0)
    runs = [run_plant(CoupledChainPlant(mechanism, 100.0), q0, np.zeros(6), 0.02, 1e-3, integrator, law, substeps=2,
                      rtol=1e-9, atol=1e-11, backend=backend)
            for mechanism, law, backend in ((plant, control, "compiled"), (plant.reference(), numpy_control, "python"))]
    assert [r.backend for r in runs] == ["compiled", "python"] and runs[0].evaluations == runs[1].evaluations
    np.testing.assert_allclose(runs[0].telemetry.q, runs[1].telemetry.q, rtol=0, atol=1e-10)
