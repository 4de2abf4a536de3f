"""The runner: one life cycle for every experiment kind, from scene to written folder."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from freefloat import FreefloatError
from freefloat.app import runner
from freefloat.app.scenes import load_scene
from freefloat.dynamics.simulation import run
from freefloat.dynamics.telemetry import Telemetry

from .conftest import cli_process, scene_variant


def test_simulate_writes_exactly_what_the_bare_loop_computes(tmp_path):
    """The pipeline adds nothing to the numbers: its telemetry equals dynamics.simulation.run on
    the prepared setup, bit for bit."""
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05},
                                     output={"figures": False, "html": False}))
    done = runner.simulate(scene, out=tmp_path / "out")
    setup = runner.prepare(scene)
    bare = run(setup.robot, setup.q0, setup.v0, 0.05, scene.simulation.control_period, setup.integrator,
               setup.model, setup.controller)
    written = Telemetry.load(tmp_path / "out" / "telemetry.npz")
    for name in ("t", "q", "v", "tau", "momentum", "energy"):
        assert np.array_equal(getattr(written, name), getattr(bare.telemetry, name)), name
    assert done.status == json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "completed"


def test_an_unwritable_folder_is_refused_before_the_run(tmp_path):
    """An output folder under a file fails at once, naming the folder, with nothing simulated."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space"))
    started = time.perf_counter()
    with pytest.raises(FreefloatError, match="output folder .*file/out.* cannot be written"):
        runner.simulate(scene, out=blocker / "out")
    assert time.perf_counter() - started < 5.0


def test_a_python_call_into_a_used_folder_names_python_arguments(tmp_path):
    """simulate into a folder of someone's files is refused naming ``out=``, not the command
    line's ``--out``, before anything is simulated."""
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    with pytest.raises(FreefloatError, match=r"choose another out= \(a new or empty folder\)") as refused:
        runner.simulate("tumbling", out=tmp_path / "mine")
    assert "--" not in str(refused.value) and (tmp_path / "mine" / "notes.txt").read_text() == "mine"


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_sigint_sigterm_and_sighup_keep_what_was_computed(tmp_path, signum):
    """A run stopped by Ctrl-C (SIGINT), SIGTERM or SIGHUP exits 1 and writes its samples."""
    proc, out = _start(tmp_path, 500.0)
    time.sleep(0.5)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    assert (out / "summary.json").is_file(), f"exit {proc.returncode}, no summary.json; stderr:\n{err}"
    summary = json.loads((out / "summary.json").read_text())
    assert proc.returncode == 1 and summary["status"] == "interrupted", f"exit {proc.returncode}; stderr:\n{err}"
    assert 1 < len(Telemetry.load(out / "telemetry.npz").t) < 500_001


def _start(tmp_path, duration: float) -> tuple[subprocess.Popen, os.PathLike]:
    """``python -m freefloat simulate`` on a long default-scene variant, once its loop runs."""
    scene = scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": duration},
                          output={"figures": False, "html": False})
    out = tmp_path / "out"
    proc = cli_process("simulate", str(scene), "--out", str(out))
    deadline = time.monotonic() + 60
    while "step" not in proc.stderr.readline():  # the progress bar (text mode reads up to each \r)
        assert time.monotonic() < deadline and proc.poll() is None, "the run never started"
    return proc, out


@pytest.mark.slow
def test_a_killed_run_leaves_loadable_checkpoints(tmp_path):
    """SIGKILL mid-run leaves the telemetry checkpointed so far, readable and in order."""
    from freefloat.app.run_folder import PARTS
    from freefloat.dynamics.simulation import CHUNK_ROWS

    proc, out = _start(tmp_path, 500.0)
    deadline = time.monotonic() + 120
    while not list((out / PARTS).glob("part-00001.npz")):
        assert time.monotonic() < deadline, "no checkpoint written"
        time.sleep(0.1)
    proc.kill()
    proc.communicate(timeout=60)
    kept = Telemetry.load_parts(out / PARTS)
    assert len(kept.t) >= 2 * CHUNK_ROWS and np.all(np.diff(kept.t) > 0)
    assert not (out / "telemetry.npz").exists()


def test_non_finite_results_are_a_failure_with_strict_json(tmp_path):
    """A run whose summary holds inf or NaN is 'diverged', and its summary.json is strict JSON
    (null, never NaN). (A base at 1e308 m, which made the CoM infinite, is now refused by the
    scene schema; the check stays for whatever else overflows.)"""
    from freefloat.app.outputs import write_run
    from freefloat.app.run_folder import RunFolder

    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.01},
                                     output={"figures": False, "html": False}))
    outcome = runner.simulate(scene)
    outcome.summary["com_drift_max"] = float("inf")
    outcome.summary["energy_drift_max"] = float("nan")
    runner.fail_if_not_finite(outcome)
    assert outcome.status == "diverged" and outcome.message == "non-finite results: com_drift_max, energy_drift_max"
    with RunFolder(tmp_path / "out") as folder:
        write_run(folder, scene, outcome)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(),
                         parse_constant=lambda c: pytest.fail(f"non-strict JSON constant {c}"))
    assert summary["status"] == "diverged" and summary["com_drift_max"] is None


def test_an_interrupt_while_writing_skips_the_drawings_but_keeps_the_data(tmp_path):
    """A second interrupt while the folder is written skips figures and page, never the
    telemetry and summary."""
    from freefloat.app.outputs import write_run
    from freefloat.app.run_folder import RunFolder

    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.01}))
    outcome = runner.simulate(scene)
    with RunFolder(tmp_path / "out") as folder:
        written, skipped = write_run(folder, scene, outcome, interrupted=lambda: True)
    assert skipped == ["figures", "trajectory.html"]
    assert {p.name for p in written} == {"telemetry.npz", "scene.toml", "summary.json"}


def test_a_drawing_that_fails_costs_nothing_else(tmp_path):
    """A figure writer that raises is listed as skipped with its reason; telemetry, summary and
    the page are still written."""
    from freefloat.app.outputs import write_run
    from freefloat.app.run_folder import RunFolder

    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.01}))
    outcome = runner.simulate(scene)

    def broken(folder):
        raise ValueError("planted")

    outcome.figures = broken
    with RunFolder(tmp_path / "out") as folder:
        written, skipped = write_run(folder, scene, outcome)
    assert skipped == ["figures (failed: ValueError: planted)"]
    assert {p.name for p in written} == {"telemetry.npz", "scene.toml", "summary.json", "trajectory.html"}


def test_an_interrupt_during_the_model_pilot_stops_the_run(tmp_path, monkeypatch):
    """Ctrl-C or SIGTERM while model = "auto" pilots its plants stops the run at its first report:
    status 'interrupted', the summary and the few rows written, nothing simulated to the end."""
    from freefloat.app.experiments import model_choice

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(model_choice, "choose", interrupted)
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space",
                                     simulation={"duration": 5.0, "model": "auto"},
                                     output={"figures": False, "html": False}))
    result = runner.simulate(scene, out=tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert result.status == summary["status"] == "interrupted"
    assert 0 < len(Telemetry.load(tmp_path / "out" / "telemetry.npz").t) < 5001


@pytest.mark.slow
@pytest.mark.parametrize("gap", [0.0, 0.05, 0.3])
def test_a_second_ctrl_c_keeps_the_telemetry_and_summary(tmp_path, gap):
    """Ctrl-C twice in a row (``gap`` s apart) stops the run once and still writes its
    telemetry and summary, with exit 1 and no traceback (it raised KeyboardInterrupt while
    the figure library was imported)."""
    proc, out = _start(tmp_path, 500.0)
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    time.sleep(gap)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1 and "Traceback" not in err, f"exit {proc.returncode}; stderr:\n{err}"
    assert json.loads((out / "summary.json").read_text())["status"] == "interrupted"
    t = Telemetry.load(out / "telemetry.npz").t
    assert len(t) > 1 and np.all(np.diff(t) > 0)


@pytest.mark.slow
def test_writing_stages_come_after_the_simulation_in_order(tmp_path):
    """simulate reports every simulated step before its first writing stage, then the stages in
    the order they write (data, page, then the figures the helper drew meanwhile): a progress bar
    can close when the writing starts."""
    events: list[tuple[str, object]] = []
    scene = load_scene(scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05}))
    runner.simulate(scene, out=tmp_path / "out", progress=lambda k: events.append(("step", k)),
                    stage=lambda name: events.append(("stage", name)))
    first_stage = next(i for i, (kind, _) in enumerate(events) if kind == "stage")
    assert events[first_stage - 1] == ("step", 50) and all(kind == "stage" for kind, _ in events[first_stage:])
    assert [name for _, name in events[first_stage:]] == ["data", "trajectory.html", "figures_meanwhile"]


@pytest.mark.slow
def test_simulate_closes_its_bar_before_writing_and_times_each_stage(tmp_path):
    """The command's bar ends at the last step, then one line per writing stage with its time."""
    path = scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05})
    done = subprocess.run([sys.executable, "-m", "freefloat", "simulate", str(path), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.startswith("writing ")]
    assert [line.split(" ...")[0] for line in lines] == [
        "writing telemetry.npz, summary.json, scene.toml", "writing the page trajectory.html",
        "writing figures, drawn meanwhile"]
    assert all(re.fullmatch(r".* \.\.\. \d+\.\d\d s", line) for line in lines)


def test_simulate_takes_a_path_and_writes_only_into_out(tmp_path, monkeypatch):
    """The Python entry takes a scene file's path (or a built-in name); without ``out`` it writes
    nothing (folder None), with ``out`` it writes there the summary it returns."""
    path = scene_variant(tmp_path / "short.toml", "four_arm_joint_space", simulation={"duration": 0.02},
                         output={"figures": False, "html": False})
    monkeypatch.chdir(tmp_path)
    alone = runner.simulate(str(path))
    assert alone.folder is None and alone.written == [] and sorted(p.name for p in tmp_path.iterdir()) == ["short.toml"]
    done = runner.simulate(str(path), out="written")
    assert done.folder == Path("written") and [p.name for p in done.written] == ["telemetry.npz", "scene.toml",
                                                                                  "summary.json"]
    assert json.loads((done.folder / "summary.json").read_text())["steps"] == done.summary["steps"] == 20
    assert alone.summary["tracking_rms_overall"] == done.summary["tracking_rms_overall"]


@pytest.mark.slow
def test_an_interrupt_while_writing_exits_1_with_the_data_whole(tmp_path):
    """SIGTERM while the page is written (the helper drawing the figures): exit 1 saying so (it
    was 0, as if all were written), telemetry and summary whole, the figures listed as skipped."""
    path = scene_variant(tmp_path / "s.toml", "four_arm_joint_space", simulation={"duration": 0.05})
    process = cli_process("simulate", str(path), "--out", str(tmp_path / "out"))
    for line in process.stderr:
        if line.startswith("writing telemetry.npz"):  # its line ends as the page starts
            process.send_signal(signal.SIGTERM)
            break
    out, err = process.communicate(timeout=120)
    assert process.returncode == 1, err
    assert "interrupted while writing" in err and "skipped:" in out and "figures" in out.split("skipped:")[1]
    assert len(Telemetry.load(tmp_path / "out" / "telemetry.npz").t) == 51


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["capture_planar", "five_bar_sliding_mode"])
def test_a_run_that_draws_nothing_imports_no_drawing_library(tmp_path, scene):
    """A scene run without figures or page (a capture, a mechanism) imports neither matplotlib nor
    meshcat: their import is a fixed cost only a drawing run pays."""
    code = ("import sys, warnings\nwarnings.simplefilter('ignore')\nimport freefloat\n"
            f"freefloat.simulate({scene!r})\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'matplotlib', 'meshcat', 'IPython'}))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize("scene, out", [(None, None), ({}, None), (3, None), ("four_arm_joint_space", 3)])
def test_simulate_refuses_a_scene_or_folder_of_the_wrong_kind(scene, out):
    """simulate with None, a dict or a number for the scene (or a number for out) is refused
    naming the argument, not a TypeError from pathlib."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=f"'{'scene' if out is None else 'out'}' takes "):
        runner.simulate(scene, out=out)
