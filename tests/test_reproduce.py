"""The model-accuracy report's runs: the claims it prints hold on short runs."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from freefloat.lab.reproduce.models_report import REGIMES, attitude_study, tumbling_run

ANGULAR_ONLY = list(REGIMES)[1]


def test_tumbling_routhian_follows_exact_and_mono_state_does_not():
    """Torque-free with angular momentum only: the Routhian model tracks ABA, eq 127 drifts away."""
    routh = tumbling_run("momentum_routh", ANGULAR_ONLY, 0.05, seed=0)
    mono = tumbling_run("momentum_mono", ANGULAR_ONLY, 0.05, seed=0)
    assert routh["final_state_error"] < 1e-10
    assert mono["final_state_error"] > 1e-7


@pytest.mark.slow
def test_attitude_study_shows_the_singularity_and_the_printed_eq_11():
    """Euler-angle error grows toward theta = 90 deg; eq 11 as printed is off by O(1)."""
    study = attitude_study()
    errors = [row["euler_max_error_rad"] for row in study["spins"]]
    assert errors == sorted(errors) and errors[-1] > 1e2 * errors[0]
    assert max(row["lie_max_error_rad"] for row in study["spins"]) < 1e-12
    assert study["eq11_printed_max_relative_error"] > 0.1


@pytest.mark.slow
def test_task_space_run_follows_the_joint_space_path(tmp_path):
    """Sec 5.2 (short run): the task-space run tracks the joint-space path and KJC is tiny."""
    from freefloat.lab.reproduce.task_space_report import reproduce

    report = reproduce(tmp_path, quick=True)
    assert max(report["table2"]["overall"]) < 1e-4          # deg-dominated pose error
    assert max(report["table3"]["x"] + report["table3"]["y"]) < 1e-6
    jsc, tsc = report["table5"]["JSC"], report["table5"]["TSC"]
    assert np.allclose(jsc["end"], tsc["end"], atol=1e-3)
    assert report["condition_study"]["plain_inversion_at_0_deg"].startswith("refused")


def test_corrected_phase_schedule_matches_exact_and_the_printed_one_does_not(tmp_path):
    """One model per capture phase: the corrected schedule stays on the exact path, the printed one leaves it."""
    from freefloat.lab.reproduce.phases_report import reproduce

    report = reproduce(tmp_path, quick=True)
    corrected, printed = report["schedules"]["corrected"], report["schedules"]["as printed"]
    assert max(corrected["state_error_at_phase_ends"]) < 1e-9
    assert printed["state_error_at_phase_ends"][1] > 1e-6


@pytest.mark.slow
def test_robustness_study_keeps_its_samples_and_resumes(tmp_path):
    """Each finished sample is journaled; a rerun into the same folder resumes instead of
    recomputing (issue 13 item 15)."""
    import json

    from freefloat.lab.reproduce.five_bar_report import reproduce_robustness

    first = reproduce_robustness(tmp_path, quick=True)
    lines = (tmp_path / "samples.jsonl").read_text().splitlines()
    assert len(lines) == 2 and first["settings"]["resumed"] == 0 and first["failed"] == 0
    again = reproduce_robustness(tmp_path, quick=True)
    assert again["settings"]["resumed"] == 2 and again["runs"] == json.loads(json.dumps(first["runs"]))


def test_printed_gains_reach_s_y_in_the_documents_time():
    """With eq 187's printed gains on the 15 % plant, s_y enters |s| < 0.02 at 0.007-0.0085 s
    (the document: about 0.008 s)."""
    from freefloat.lab.reproduce.five_bar_report import eq_187_gains, reaching_times
    from freefloat.parallel.closed_loop import track_five_bar
    from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, five_bar
    from freefloat.parallel.sliding_mode import PlatformControl, circle_reference

    control = PlatformControl(five_bar(FiveBarParameters()), circle_reference, 40.0, eq_187_gains())
    tel = track_five_bar(TRUE_PARAMETERS, control, 0.02, 1e-4).telemetry
    _, s = control.sliding_variables(tel.t, tel.q, tel.v)
    assert 0.007 < reaching_times(tel.t, s)[1] < 0.0085


def _fake_part(*args) -> dict:
    return {"args": [str(a) for a in args]}


def _recomputed(*args) -> dict:
    raise AssertionError(f"part recomputed: {args}")


@pytest.mark.slow
def test_models_study_journals_each_part_and_resumes(tmp_path, monkeypatch):
    """An interrupted models study keeps every finished part in its journal, and a rerun into the
    same folder takes them instead of recomputing (it wrote only at the end)."""
    from freefloat.lab.reproduce import JOURNALS, models_report

    monkeypatch.setattr(models_report, "figures", lambda report, out: None)
    monkeypatch.setattr(models_report, "markdown", lambda report: "report")
    monkeypatch.setattr(models_report, "accuracy", _fake_part)
    monkeypatch.setattr(models_report, "grid_cell", _fake_part)
    monkeypatch.setattr(models_report, "tumbling_run", _fake_part)

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(models_report, "attitude_study", interrupted)
    with pytest.raises(KeyboardInterrupt):
        models_report.reproduce(tmp_path, quick=True, workers=1)
    journaled = (tmp_path / models_report.JOURNAL).read_text().splitlines()
    assert models_report.JOURNAL in JOURNALS and len(journaled) > 3 and not (tmp_path / "report.json").exists()
    for name in ("accuracy", "grid_cell", "tumbling_run"):
        monkeypatch.setattr(models_report, name, _recomputed)
    monkeypatch.setattr(models_report, "attitude_study", lambda: {"rows": []})
    report = models_report.reproduce(tmp_path, quick=True, workers=1)
    assert len(report["grid"]) + len(report["tumbling"]) + 1 == len(journaled)
    assert report["attitude"] == {"rows": []} and (tmp_path / "report.json").is_file()


@pytest.mark.slow
def test_models_study_workers_print_no_warnings(tmp_path):
    """The study's pool workers keep the robot's load-time notes to themselves, as the study does
    in the command's process (each worker printed them with their source lines)."""
    done = subprocess.run([sys.executable, "-m", "freefloat", "reproduce", "models", "--quick", "--workers", "2",
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr and "warning" not in done.stderr


@pytest.mark.slow
def test_robustness_stopped_by_sigterm_prints_no_dask_log(tmp_path):
    """SIGTERM while the local Dask cluster runs samples: the interrupt's message, exit 1, and no
    traceback or log line from the workers (cancelled tasks, lost heartbeats)."""
    out = tmp_path / "out"
    command = [sys.executable, "-m", "freefloat", "reproduce", "robustness", "--runs", "400", "--workers", "2",
               "--out", str(out)]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and process.poll() is None and not (
                (out / "samples.jsonl").is_file() and (out / "samples.jsonl").stat().st_size > 0):
            time.sleep(0.2)
        assert process.poll() is None, "the study ended before a sample was journaled"
        process.send_signal(signal.SIGTERM)
        _, stderr = process.communicate(timeout=120)
    assert process.returncode == 1, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr and "distributed." not in stderr, stderr


def test_robustness_quick_keeps_the_runs_asked_for(tmp_path, monkeypatch):
    """--quick shortens the default sample count, never an explicit --runs: quick with runs 7 runs 7."""
    import contextlib

    from freefloat.lab.reproduce.five_bar_report import reproduce_robustness
    from freefloat.parallel import sweeps

    asked = []

    def fake_monte_carlo(dask_client, gains, runs, **kwargs):
        asked.append(runs)
        return [{"sample": i, "status": "ok", "error_mm": [0.0, 0.0], "parameters": {}} for i in range(runs)]

    monkeypatch.setattr(sweeps, "client", lambda scheduler: contextlib.nullcontext())
    monkeypatch.setattr(sweeps, "design_gains_distributed", lambda *a, **k: type("G", (), {"n": np.zeros(1), "T": np.zeros(1)}))
    monkeypatch.setattr(sweeps, "monte_carlo", fake_monte_carlo)
    assert reproduce_robustness(tmp_path / "a", quick=True, runs=7)["settings"]["runs"] == 7
    assert reproduce_robustness(tmp_path / "b", quick=True)["settings"]["runs"] == 2 and asked == [7, 2]


@pytest.mark.parametrize("workers, forced", [(0, False), (None, False), (None, True)])
def test_reproduce_checks_its_workers_as_batch_does(tmp_path, monkeypatch, capsys, workers, forced):
    """``reproduce --workers`` below 1 or beyond the cores is refused (exit 2, naming the option
    and --force-workers), not silently changed; with --force-workers the count reaches the study."""
    from freefloat.app.batch.executors import local_limit
    from freefloat.app.cli import main
    from freefloat.lab.reproduce import folders

    asked = local_limit() + 1 if workers is None else workers
    seen = []

    def record(name, out, overwrite, quick, options):
        seen.append(options)
        raise KeyboardInterrupt  # stopped there, before any study runs

    monkeypatch.setattr(folders, "run_study", record)
    argv = ["reproduce", "jerk", "--workers", str(asked), "--out", str(tmp_path / "out"), *(["--force-workers"] if forced else [])]
    code = main(argv)
    if forced:
        assert seen and seen[0]["workers"] == asked
    else:
        assert code == 2 and not seen and "--workers" in capsys.readouterr().err
