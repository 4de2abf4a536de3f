"""The model-accuracy report's runs: the claims it prints hold on short runs."""

from __future__ import annotations

from freefloat.reproduce.models_report import REGIMES, attitude_study, tumbling_run

ANGULAR_ONLY = list(REGIMES)[1]


def test_tumbling_routhian_follows_exact_and_mono_state_does_not():
    """Torque-free with angular momentum only: the Routhian model tracks ABA, eq 127 drifts away."""
    routh = tumbling_run("momentum_routh", ANGULAR_ONLY, 0.05, seed=0)
    mono = tumbling_run("momentum_mono", ANGULAR_ONLY, 0.05, seed=0)
    assert routh["final_state_error"] < 1e-10
    assert mono["final_state_error"] > 1e-7


def test_attitude_study_shows_the_singularity_and_the_printed_eq_11():
    """Euler-angle error grows toward theta = 90 deg; eq 11 as printed is off by O(1)."""
    study = attitude_study()
    errors = [row["euler_max_error_rad"] for row in study["spins"]]
    assert errors == sorted(errors) and errors[-1] > 1e2 * errors[0]
    assert max(row["lie_max_error_rad"] for row in study["spins"]) < 1e-12
    assert study["eq11_printed_max_relative_error"] > 0.1
