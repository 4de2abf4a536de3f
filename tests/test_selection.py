"""Choosing the cheapest model under a tolerance (freefloat.dynamics.models.selection)."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics.models import MODELS
from freefloat.dynamics.models.selection import (
    ALWAYS,
    ZERO_MOMENTUM,
    Candidate,
    Pilot,
    choose,
    regime_models,
    state_error,
)
from freefloat.paths import URDF_DIR

from .conftest import random_state


@pytest.fixture(scope="module")
def two_arm():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)


def test_zero_momentum_admits_every_model_that_is_exact_there():
    """At zero momentum the candidates are the exact models and every zero-momentum model."""
    names = regime_models(np.zeros(6))
    assert set(names) == {*ALWAYS, "standard_full_hdot", "momentum_routh", *ZERO_MOMENTUM} and set(names) <= set(MODELS)


def test_angular_momentum_alone_drops_the_zero_momentum_models():
    """With P = 0 and L != 0 only the models exact at zero linear momentum remain beside the exact ones."""
    assert set(regime_models(np.array([0, 0, 0, 0, 0, 0.3]))) == {*ALWAYS, "standard_full_hdot", "momentum_routh"}


def test_unconserved_momentum_admits_only_the_exact_models():
    """With gravity or wrenches (momentum not conserved) only the exact models are candidates."""
    assert regime_models(None) == ALWAYS


def test_state_error_is_the_largest_configuration_or_velocity_difference(two_arm):
    """A joint offset of 2e-3 rad and a rate offset of 5e-4 rad/s give an error of 2e-3."""
    q, v = random_state(two_arm, np.random.default_rng(0))
    q2, v2 = q.copy(), v.copy()
    q2[-1] += 2e-3
    v2[-2] += 5e-4
    rows = lambda x: np.stack([x, x])
    assert state_error(two_arm.model, rows(q), rows(v), rows(q2), rows(v2)) == pytest.approx(2e-3, rel=1e-9)


def test_state_error_of_a_run_that_stopped_early_is_infinite(two_arm):
    """A pilot with fewer rows than the reference (it diverged) never passes."""
    q, v = random_state(two_arm, np.random.default_rng(1))
    assert state_error(two_arm.model, np.stack([q, q]), np.stack([v, v]), q[None], v[None]) == np.inf


def fake(name, cost, offset, calls, wall=1.0):
    """A candidate whose pilot returns the reference rows plus ``offset`` on one joint, counting its runs."""
    def pilot():
        calls.append(name)
        q = np.zeros((3, 4))
        q[:, 2] = 1.0
        q[:, 0] += offset
        return Pilot(wall, q, np.zeros((3, 3)))
    return Candidate(name, "none", cost, pilot)


def planar_point():
    """A Pinocchio model with one planar joint (q = [x, y, cos, sin]) for the fake pilots."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelPlanar(), pin.SE3.Identity(), "base")
    return model


def test_the_cheapest_candidate_under_the_tolerance_is_chosen():
    """A cheaper candidate with a large error is passed over for the next cheapest within tolerance."""
    calls: list[str] = []
    reference = fake("exact", 1.0, 0.0, calls, wall=2.0)
    choice = choose(reference, [fake("wrong", 0.1, 1e-3, calls), fake("close", 0.5, 1e-9, calls),
                                fake("dearer", 2.0, 0.0, calls)], planar_point(), 1e-6, 100.0)
    assert (choice.model, choice.speedup) == ("close", 2.0)
    assert calls == ["exact", "wrong"] * 2 + ["exact", "close"] * 2
    assert choice.predicted_error == pytest.approx(1e-7)


def test_no_pilot_runs_when_nothing_is_cheaper_than_the_reference():
    """When every candidate costs more per call than the exact plant, the exact plant is chosen without a pilot."""
    calls: list[str] = []
    choice = choose(fake("exact", 1.0, 0.0, calls), [fake("dearer", 2.0, 0.0, calls)], planar_point(), 1e-6, 100.0)
    assert choice.model == "exact" and calls == [] and choice.trials[0].accepted
