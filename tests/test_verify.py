"""``freefloat verify``: a clean report on a good robot, failures that are reported, bad files."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from freefloat import load_robot
from freefloat.app.cli import main
from freefloat.dynamics.gjm import model as gjm_model
from freefloat.dynamics.verify import (
    DERIVATIVE_TOLERANCE,
    FD_STEP,
    ROUNDING_ULPS,
    check_robot,
    column_error,
)
from freefloat.robot.loading import example_robot_data_share

from .conftest import REPO


@pytest.mark.slow
def test_verify_four_arm_robot_is_clean(tmp_path, capsys):
    """The four-arm robot passes every check; the JSON report says so check by check."""
    status = main(["verify", str(REPO / "urdf" / "four_arm_planar.urdf"), "--samples", "3", "--json", str(tmp_path / "v.json")])
    report = json.loads((tmp_path / "v.json").read_text())
    assert status == 0 and report["passed"] and "all checks pass" in capsys.readouterr().out
    names = {c["quantity"] for c in report["checks"]}
    assert {"H0", "H0m", "Hm", "Hstar", "Jstar", "momentum_origin", "dH0", "dH0m", "dHm", "H0dot"} <= names
    printed = next(c for c in report["checks"] if c["quantity"] == "momentum eq 182 as printed")
    assert printed["error"] > 1e-3 and printed["passed"]  # informational: shown, not failing


def test_verify_reports_a_wrong_matrix(monkeypatch):
    """A hand-built H0 off by 1e-6 is caught: the report fails on H0 and the quantities built on it."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    original = gjm_model.inertia_matrices

    def perturbed(*args):
        H0, H0m, Hm = original(*args)
        return H0 * (1.0 + 1e-6), H0m, Hm

    monkeypatch.setattr(gjm_model, "inertia_matrices", perturbed)
    report = check_robot(robot, samples=1)
    failed = {c.quantity for c in report.checks if not c.passed}
    assert not report.passed and {"H0", "J0", "Jstar"} <= failed and "Hm" not in failed


def test_verify_rejects_a_file_that_cannot_be_a_tree(tmp_path, capsys):
    """verify on a URDF with negative mass exits 2 naming the link."""
    bad = (REPO / "urdf" / "two_arm_planar.urdf").read_text().replace('<mass value="2"/>', '<mass value="-2"/>', 1)
    (tmp_path / "bad.urdf").write_text(bad)
    assert main(["verify", str(tmp_path / "bad.urdf")]) == 2
    err = capsys.readouterr().err
    assert "mass -2.0" in err and "link 'arm1_link1'" in err


def test_column_error_is_relative_for_a_large_column():
    """A column far above the differences' rounding floor is judged relative to its own size."""
    H = np.ones((4, 4))
    fd = np.full((4, 4), 0.5)
    assert column_error(fd * (1 + 1e-5), fd, H, FD_STEP) == pytest.approx(1e-5)


def test_column_error_of_a_tiny_column_is_judged_at_the_rounding_floor():
    """A column below the rounding floor passes when off by a tenth of that floor and fails when
    off by a thousand times it."""
    H = np.ones((4, 4))
    noise = ROUNDING_ULPS * np.finfo(float).eps / FD_STEP
    fd = np.full((4, 4), 1e-3 * noise)
    assert column_error(fd + 0.1 * noise, fd, H, FD_STEP) <= 0.1 * DERIVATIVE_TOLERANCE * (1 + 1e-12)
    assert column_error(fd + 1e3 * noise, fd, H, FD_STEP) > DERIVATIVE_TOLERANCE


@pytest.mark.slow
@pytest.mark.skipif(example_robot_data_share() is None, reason="example-robot-data is not installed")
def test_verify_passes_pr2_gripper_columns():
    """PR2's derivatives pass (the former 2nd-order differences with h = 1e-6 failed dH0 at 2.9e-4:
    its gripper columns are ~1e-4 of |H|, below their rounding)."""
    path = example_robot_data_share() / "example-robot-data/robots/pr2_description/urdf/pr2.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(path, visuals=False)
    report = check_robot(robot, samples=3)
    derivatives = {c.quantity: c.error for c in report.checks if c.quantity in ("dH0", "dH0m", "dHm")}
    assert report.passed and max(derivatives.values()) < 1e-7


def test_verify_reports_a_wrong_derivative(monkeypatch):
    """A hand-built dH0 off by 1e-5 relative fails the dH0 check and no other derivative."""
    from freefloat.dynamics import gjm

    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    original = gjm.derivatives

    def perturbed(*args):
        out = original(*args)
        out.dH0[...] *= 1.0 + 1e-5
        return out

    monkeypatch.setattr(gjm, "derivatives", perturbed)
    failed = {c.quantity for c in check_robot(robot, samples=1).checks if not c.passed}
    assert failed == {"dH0"}


def test_a_trillion_samples_are_refused_up_front(capsys):
    """verify --samples 10**12 exits 2 naming the bound instead of running for ever."""
    from freefloat.dynamics.verify import MAX_SAMPLES

    assert main(["verify", str(REPO / "urdf" / "four_arm_planar.urdf"), "--samples", str(10**12)]) == 2
    assert f"--samples must be from 1 to {MAX_SAMPLES}" in capsys.readouterr().err
