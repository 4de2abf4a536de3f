"""``freefloat reproduce chattering``: the zero-order hold, not tanh(100 s), makes the 5R chatter."""

from __future__ import annotations

import csv
import json

import pytest

from freefloat.lab.reproduce import chattering_report


def test_tanh_chatters_when_held_and_not_when_continuous():
    """tanh(100 s), RK4 at 50 us: held over 0.1 ms, s changes sign at about the update rate; evaluated at
    every stage, a hundred times less often, with a smaller worst tracking error."""
    held = chattering_report.run_period("tanh", 1e-4, 5e-5, 0.22)
    continuous = chattering_report.run_period("tanh", None, 5e-5, 0.22)
    assert min(held["s_sign_changes_per_s"]) > 5000
    assert max(continuous["s_sign_changes_per_s"]) < 50
    assert max(continuous["error_after_0.2s_mm"]) < max(held["error_after_0.2s_mm"]) / 2


@pytest.mark.slow
def test_study_writes_its_table_and_figure(tmp_path, monkeypatch):
    """One held period and both switches: report, CSV (a row per run) and figure are written."""
    monkeypatch.setattr(chattering_report, "QUICK_PERIODS", (1e-3,))
    report = chattering_report.reproduce(tmp_path, quick=True)
    assert [(r["saturation"], r["period"]) for r in report["rows"]] == [("tanh", 1e-3), ("sign", 1e-3)]
    with (tmp_path / "chattering.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [float(r["s_sign_changes_per_s_0"]) for r in rows] == pytest.approx(
        [r["s_sign_changes_per_s"][0] for r in report["rows"]])
    assert json.loads((tmp_path / "report.json").read_text())["settings"]["step"] == 2e-5
    assert "| tanh | 1000 us |" in (tmp_path / "report.md").read_text()
    assert (tmp_path / "chattering.png").stat().st_size > 10_000
