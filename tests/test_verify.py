"""``freefloat verify``: a clean report on a good robot, failures that are reported, bad files."""

from __future__ import annotations

import json

from freefloat import load_robot
from freefloat.app.cli import main
from freefloat.dynamics.gjm import model as gjm_model
from freefloat.dynamics.verify import check_robot

from .conftest import REPO


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
