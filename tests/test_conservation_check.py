"""The conservation oracle: a run that breaks a conservation law its scene promises is failed,
naming the quantity, its value and its bound; the built-in scenes of every kind pass."""

from __future__ import annotations

import json

import numpy as np
import pytest

from freefloat.app import runner
from freefloat.app.cli import main
from freefloat.app.conservation_check import TOLERANCE_FLOOR, checked, tolerance
from freefloat.app.scenes import load_scene

from .conftest import leak_momentum, scene_variant

#: A spurious torque (N m) about z: far below anything a scene applies, far above round-off.
SPURIOUS_TORQUE = 1e-3


@pytest.fixture
def spurious_torque(monkeypatch):
    """Every robot run leaks :data:`SPURIOUS_TORQUE` about z into its recorded momentum."""
    leak_momentum(monkeypatch, SPURIOUS_TORQUE)


def test_the_tolerance_follows_the_integrators_order_and_step():
    """``(h / 0.1 s)^p``, never below the floor: Euler at 1 ms 1e-2, RK4 at 1 ms the floor."""
    assert tolerance(1, 1e-3) == pytest.approx(1e-2)
    assert tolerance(2, 1e-3) == pytest.approx(1e-4)
    assert tolerance(4, 1e-3) == TOLERANCE_FLOOR
    assert tolerance(1, 1.0) == 0.5


def test_a_spurious_torque_fails_a_torque_free_run_naming_the_quantity(spurious_torque):
    """``tumbling`` with a leak of 1e-3 N m is failed: the message names momentum_drift_max,
    its value (the leak's impulse) and its bound."""
    outcome = runner.simulate("tumbling")
    drift = outcome.summary["momentum_drift_max"]
    assert drift == pytest.approx(SPURIOUS_TORQUE * outcome.summary["duration"], rel=1e-3)
    bound = next(c.bound for c in checked(outcome.summary) if c.quantity == "momentum_drift_max")
    assert outcome.status == "failed" and outcome.summary["status"] == "failed"
    assert f"momentum_drift_max {drift:.3g} exceeds its bound {bound:.3g}" in outcome.message


def test_the_command_line_exits_1_for_a_failed_run(tmp_path, spurious_torque, capsys):
    """``freefloat simulate`` of a run that breaks its balance exits 1, says it failed and why,
    and its summary.json says ``failed``."""
    status = main(["simulate", "tumbling", "--out", str(tmp_path / "out"), "--quiet", "--no-figures", "--no-html"])
    assert status == 1
    assert "run failed: conservation violated: momentum_drift_max" in capsys.readouterr().err
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "failed"


@pytest.mark.slow
def test_a_wheel_scene_whose_balance_forgets_the_wheels_is_failed(monkeypatch):
    """``satellite_wheels`` passes; with the wheels' stored momentum left out of its balance (as a
    plant that ignores the wheels would leave it) the run is failed naming
    wheel_momentum_balance_max, its value and its bound."""
    from freefloat.app.experiments import robot_run

    assert runner.simulate("satellite_wheels").status == "completed"
    original = robot_run.wheel_telemetry

    def forgetting(wheels, telemetry, *args):
        with monkeypatch.context() as patch:
            patch.setattr(type(wheels), "momenta", lambda self, v: np.zeros_like(self.speeds(v)))
            return original(wheels, telemetry, *args)

    monkeypatch.setattr(robot_run, "wheel_telemetry", forgetting)
    outcome = runner.simulate("satellite_wheels")
    value = outcome.summary["wheel_momentum_balance_max"]
    bound = next(c.bound for c in checked(outcome.summary) if c.quantity == "wheel_momentum_balance_max")
    assert outcome.status == "failed" and value > bound
    assert outcome.message.startswith(f"conservation violated: wheel_momentum_balance_max {value:.3g} exceeds its "
                                      f"bound {bound:.3g}")


@pytest.mark.parametrize("scene, quantity", [
    ("tumbling", "momentum_drift_max"),                     # torque-free
    ("detumble_impulse_baseline", "momentum_balance_max"),  # an external wrench
    ("capture_planar", "momentum_balance_error"),           # through a grasp
    ("satellite_hands_joined", "closure_drift_max"),        # a loop closure
    ("five_bar_free_base", "loop_closure_drift_max"),       # a mechanism on a free base
])
def test_a_built_in_scene_of_each_kind_passes_with_its_margin(tmp_path, scene, quantity):
    """The built-in scene completes, its quantity is checked, and the largest value over bound
    (``conservation_margin``) is below 1."""
    short = {"satellite_hands_joined": {"duration": 0.2}, "five_bar_free_base": {"duration": 0.2}}.get(scene, {})
    outcome = runner.simulate(load_scene(scene_variant(tmp_path / "s.toml", scene, simulation=short)))
    assert outcome.status == "completed", outcome.message
    margins = {c.quantity: c.margin for c in checked(outcome.summary)}
    assert quantity in margins and np.isfinite(margins[quantity])
    assert outcome.summary["conservation_margin"] == max(margins.values()) < 1.0
