"""``freefloat reproduce stability``: every case bisected, written as JSON, CSV, Markdown and a figure."""

from __future__ import annotations

import csv
import json

import pytest

from freefloat.lab.reproduce import stability_report
from freefloat.lab.reproduce.stability_cases import Case


class Threshold(Case):
    """A case stable below ``limit`` s whose runs blow up from ``blow`` s on."""

    def __init__(self, limit: float, blow: float = float("inf")):
        self.limit, self.blow = limit, blow

    def measure(self, h: float) -> dict:
        return {"status": "completed" if h < self.blow else "diverged", "steps": 1, "h": h}

    def passes(self, m: dict) -> bool:
        return m["h"] < self.limit


def fake_cases(quick: bool):
    return [({"group": "tumbling", "scene": "four_arm", "value": 3.0, "integrator": "rkmk4"}, Threshold(0.01, 0.1), (1e-4, 1.0)),
            ({"group": "tumbling", "scene": "four_arm", "value": 30.0, "integrator": "rkmk4"}, Threshold(0.001, 0.001), (1e-4, 1.0)),
            ({"group": "closed chain", "scene": "five_bar_computed_torque", "value": 0.0, "integrator": "rk4"},
             Threshold(10.0), (1e-4, 1.0))]


@pytest.mark.slow
def test_study_reports_each_bracket_and_open_ones(tmp_path, monkeypatch):
    """Limits 0.01 and 0.001 s and blow-ups from 0.1 and 0.001 s are bracketed; a case stable up to
    the top is written as '> high'."""
    monkeypatch.setattr(stability_report, "cases", fake_cases)
    report = stability_report.reproduce(tmp_path, quick=True)
    first, second, chain = report["rows"]
    assert first["stable_step"] < 0.01 <= first["unstable_step"] and second["stable_step"] < 0.001 <= second["unstable_step"]
    assert first["completes_step"] < 0.1 <= first["blows_up_step"] <= 0.1 * 1.1
    assert (second["completes_step"], second["blows_up_step"]) == (second["stable_step"], second["unstable_step"])
    assert chain["stable_step"] == chain["completes_step"] == 1.0 and chain["blows_up_step"] is None
    assert first["at_stable"]["h"] == first["stable_step"]
    table = (tmp_path / "report.md").read_text()
    assert "| closed chain | five_bar_computed_torque | 0 | rk4 | 1 | > 1 | 1 | > 1 |" in table
    with (tmp_path / "stability.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [r["unstable_step"] for r in rows][2] == ""
    assert float(rows[0]["stable_step"]) == first["stable_step"]
    assert json.loads((tmp_path / "report.json").read_text())["settings"]["drift_bound"] == 0.01
    assert (tmp_path / "stability.png").stat().st_size > 10_000


def test_quick_study_covers_every_group_and_the_robot_integrators():
    """--quick keeps tumbling on both robots, one detumbling scene and every closed-chain variant."""
    labels = [labels for labels, _, _ in stability_report.cases(quick=True)]
    assert {(x["group"], x["scene"]) for x in labels} >= {("tumbling", "four_arm"), ("tumbling", "dual_arm"),
                                                         ("detumbling", "detumble_impulse_both_arms")}
    chains = {(x["scene"], x["value"], x["integrator"]) for x in labels if x["group"] == "closed chain"}
    assert len(chains) == 8
