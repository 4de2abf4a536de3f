"""Batches of runs: the same numbers serially, on threads, on a pool and on Dask; failures kept as
rows; an interrupted batch keeps its finished rows; the folder's table and record; bad flags named."""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import json
import signal
import subprocess
import sys
import time

import pytest

from freefloat import FreefloatError
from freefloat.app.batch import Band, Workers, run_batch
from freefloat.app.batch.driver import PARTIAL
from freefloat.app.batch.one_run import TIMINGS, run_one
from freefloat.app.batch.variations import run_seeds
from freefloat.app.cli import main
from freefloat.app.scenes import load_scene

from .conftest import scene_variant


def short(tmp_path, builtin: str = "four_arm_joint_space", duration: float = 0.05):
    """A built-in scene cut to ``duration`` s."""
    return load_scene(scene_variant(tmp_path / f"{builtin}.toml", builtin, simulation={"duration": duration}))


def results(rows: list[dict]) -> list[dict]:
    """Rows without their timings."""
    return [{k: v for k, v in row.items() if k not in TIMINGS} for row in rows]


@pytest.mark.slow
def test_serial_pool_and_dask_give_identical_rows(tmp_path):
    """The same seeds give bit-identical rows one after another, on a 2-process pool and on a
    local Dask cluster of 2 worker processes."""
    pytest.importorskip("dask.distributed")
    scene = short(tmp_path)
    bands = [Band("joint_rate", 2.0), Band("mass", 0.1)]
    serial, pool, dask = (run_batch(scene, tmp_path / name, 4, bands, seed=5, workers=workers).rows
                          for name, workers in [("serial", Workers()), ("pool", Workers(2)),
                                                ("dask", Workers(2, dask=True))])
    assert [r["status"] for r in serial] == ["completed"] * 4
    assert results(serial) == results(pool) == results(dask)
    assert len({r["tracking_rms_overall"] for r in serial}) == 4


def test_threads_give_the_serial_rows_and_load_the_robot_once(tmp_path):
    """The same seeds on 2 threads of this process give bit-identical rows to serial runs (the
    compiled loop and the plant masses varied), and the threads share one loaded robot."""
    from freefloat.app.batch import one_run

    scene = short(tmp_path, "tumbling", 0.2)
    bands = [Band("joint_rate", 2.0), Band("mass", 0.1)]
    one_run.ROBOTS.clear()
    threads = run_batch(scene, tmp_path / "threads", 6, bands, seed=3, workers=Workers(threads=2))
    assert len(one_run.ROBOTS) == 1  # the first thread's load, reused by the other thread's runs
    serial = run_batch(scene, tmp_path / "serial", 6, bands, seed=3)
    assert [r["status"] for r in serial.rows] == ["completed"] * 6
    assert results(threads.rows) == results(serial.rows) and threads.summary["workers"] == "threads of 2"
    assert len({r["momentum_drift_max"] for r in serial.rows}) == 6


def test_a_batch_on_threads_leaves_the_blas_threads_as_it_found_them(tmp_path):
    """After a batch on 2 threads, BLAS has the threads it had before (restored from a run's
    thread, OpenBLAS kept one)."""
    from threadpoolctl import threadpool_info

    def blas_threads() -> list[int]:
        return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]

    before = blas_threads()
    run_batch(short(tmp_path, "tumbling", 0.05), tmp_path / "out", 4, [Band("joint_rate", 1.0)],
              workers=Workers(threads=2))
    assert blas_threads() == before


@pytest.mark.slow
def test_dask_workers_of_two_threads_give_the_serial_rows(tmp_path):
    """A local Dask cluster of one worker of 2 threads runs the runs at once and gives the serial rows."""
    pytest.importorskip("dask.distributed")
    scene = short(tmp_path, "tumbling", 0.1)
    bands = [Band("joint_rate", 2.0)]
    dask = run_batch(scene, tmp_path / "dask", 4, bands, seed=2, workers=Workers(1, dask=True, threads=2))
    serial = run_batch(scene, tmp_path / "serial", 4, bands, seed=2)
    assert results(dask.rows) == results(serial.rows)
    assert dask.summary["workers"] == "dask local cluster of 1 of 2 threads each"


@pytest.mark.slow
def test_a_pool_batch_never_forks(tmp_path, monkeypatch):
    """Pool workers are new interpreters: the runs complete with os.fork made to fail (a fork of
    this threaded process can deadlock, and Python 3.12 warns at each)."""
    import os

    def no_fork():
        raise AssertionError("os.fork called")

    monkeypatch.setattr(os, "fork", no_fork)
    done = run_batch(short(tmp_path), tmp_path / "out", 2, [Band("joint_rate", 2.0)], seed=1, workers=Workers(2))
    assert [r["status"] for r in done.rows] == ["completed", "completed"]


@pytest.mark.slow
def test_a_failing_run_is_recorded_and_the_batch_goes_on(tmp_path):
    """Starts where the 5R cannot be assembled fail with the reason in their rows, on a pool; the
    other runs complete."""
    done = run_batch(short(tmp_path, "five_bar_computed_torque", 0.01), tmp_path / "out", 6, [Band("platform", 0.2)],
                     seed=0, workers=Workers(2))
    statuses = [r["status"] for r in done.rows]
    assert set(statuses) == {"completed", "failed"} and [r["run"] for r in done.rows] == list(range(6))
    assert all("cannot" in r["message"] or "point" in r["message"] for r in done.rows if r["status"] == "failed")
    assert done.summary["by_status"] == {s: statuses.count(s) for s in set(statuses)} and not done.completed


@pytest.mark.slow
def test_a_pool_worker_that_dies_fails_the_runs_left_and_the_batch_ends(tmp_path):
    """Worker processes killed mid-batch (as a crash would end them) break the pool: every run
    left is a failed row naming the lost worker, and the batch ends instead of hanging."""
    psutil = pytest.importorskip("psutil")

    def kill_the_workers(row: dict) -> None:
        for child in psutil.Process().children(recursive=True):
            with contextlib.suppress(psutil.NoSuchProcess):  # one already ending (another test's cluster)
                if not any("resource_tracker" in part for part in child.cmdline()):
                    # multiprocessing's resource tracker outlives a crashed worker; killed, its
                    # successor printed a KeyError traceback for every semaphore released later
                    child.kill()

    done = run_batch(short(tmp_path, "tumbling", 1.0), tmp_path / "out", 6, [Band("base_rate", 1.0)],
                     workers=Workers(2), progress=kill_the_workers)
    assert [r["run"] for r in done.rows] == list(range(6))
    lost = [r for r in done.rows if r["status"] == "failed"]
    assert lost and all(r["message"].startswith("worker process lost") for r in lost)
    assert {r["status"] for r in done.rows} <= {"completed", "failed"}


def test_the_folder_holds_the_table_the_record_and_the_scene(tmp_path):
    """runs.csv and runs.json hold the same rows; summary.json the seed, bands, workers, counts,
    scene and versions; scene.toml the scene as it ran; no partial file is left."""
    scene = short(tmp_path, "tumbling")
    done = run_batch(scene, tmp_path / "out", 3, [Band("base_rate", 2.0)], seed=9)
    out = tmp_path / "out"
    table = list(csv.DictReader((out / "runs.csv").open()))
    rows = json.loads((out / "runs.json").read_text())
    assert rows == json.loads(json.dumps(done.rows)) and len(table) == 3
    assert [float(r["initial.base_angular_velocity[1]"]) for r in table] == [
        r["initial.base_angular_velocity[1]"] for r in rows]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["seed"] == 9 and summary["vary"] == {"base_rate": 2.0} and summary["workers"] == "serial"
    assert [int(r["seed"]) for r in table] == run_seeds(9, 3)  # each run's own seed (every row had 9)
    assert summary["by_status"] == {"completed": 3} and summary["scene"]["name"] == "tumbling"
    assert "pin" in summary["versions"]
    as_run = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False, html=False))
    assert load_scene(out / "scene.toml") == dataclasses.replace(as_run, source=out / "scene.toml")
    assert not (out / PARTIAL).exists()


def test_a_folder_in_use_or_not_empty_is_refused_before_any_run(tmp_path):
    """An output folder holding other files is refused naming it, and nothing is run."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "mine.txt").write_text("keep")
    with pytest.raises(FreefloatError, match="output folder .* holds files freefloat did not write"):
        run_batch(short(tmp_path), tmp_path / "out", 2, [])
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["mine.txt"]


@pytest.mark.slow
@pytest.mark.parametrize("where", [["--workers", "1"], ["--workers", "2"], ["--threads", "2"]])
def test_sigterm_keeps_the_finished_rows(tmp_path, where):
    """SIGTERM to a running batch (serial, pool or threads) exits 1 and writes every finished
    row, the batch marked interrupted and the runs left counted as not run."""
    scene = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"duration": 0.2})
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "freefloat", "batch", str(scene), "--runs", "400", *where,
                             "--quiet", "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.monotonic() + 120
    while not (out / PARTIAL).is_file() or len((out / PARTIAL).read_text().splitlines()) < 2:
        assert time.monotonic() < deadline and proc.poll() is None, "the batch never finished a run"
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    summary = json.loads((out / "summary.json").read_text())
    rows = json.loads((out / "runs.json").read_text())
    assert proc.returncode == 1 and summary["status"] == "interrupted", err
    assert 2 <= len(rows) == summary["finished"] < 400 and summary["not_run"] == 400 - len(rows)
    assert all(r["status"] == "completed" for r in rows) and not (out / PARTIAL).exists()


@pytest.mark.parametrize("args, message", [
    (["--runs", "0"], "--runs must be from 1 to 100000, got 0"),
    (["--vary", "wobble=1"], "--vary 'wobble=1': unknown key 'wobble'"),
    (["--vary", "mass=2"], "--vary 'mass=2'"),
    (["--workers", "0"], "--workers must be an integer >= 1, got 0"),
    (["--threads", "0"], "--threads must be from 1 to 256, got 0"),
    (["--threads", "300"], "--threads must be from 1 to 256, got 300"),
    (["--threads", "2", "--workers", "2"], "--threads 2 with --workers 2: choose"),
    (["--dask", "--threads", "2", "--scheduler", "tcp://127.0.0.1:1"], "--threads sets the threads of a local Dask"),
    (["--dask", "--scheduler", "tcp://127.0.0.1:1"], "--scheduler 'tcp://127.0.0.1:1': no Dask scheduler answers"),
    (["--scheduler", "nonsense"], "--scheduler 'nonsense' is not a Dask address"),
    (["--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers sets the size of a local cluster"),
])
def test_bad_flags_are_named_and_exit_2(tmp_path, capsys, args, message):
    """Bad counts, bands, workers and scheduler addresses exit 2 with a message naming the flag,
    before any run."""
    if "--scheduler" in args:
        pytest.importorskip("dask.distributed")
    scene = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"duration": 0.01})
    status = main(["batch", str(scene), "--quiet", "--out", str(tmp_path / "out"), *args])
    assert status == 2 and message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_the_help_lists_every_vary_key(capsys):
    """freefloat batch --help prints (its text has percent signs) and names each key."""
    from freefloat.app.batch import VARIES

    with pytest.raises(SystemExit) as stop:
        main(["batch", "--help"])
    printed = " ".join(capsys.readouterr().out.split())
    assert stop.value.code == 0 and all(f"{key}:" in printed for key in VARIES)


def test_the_command_runs_a_batch_and_exits_0(tmp_path, capsys):
    """freefloat batch prints the counts, the rate and the spread of the headline keys."""
    scene = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"duration": 0.02})
    status = main(["batch", str(scene), "--runs", "2", "--vary", "base_rate=1", "--quiet", "--out",
                   str(tmp_path / "out")])
    printed = capsys.readouterr().out
    assert status == 0 and "completed: 2 of 2 runs completed (2 completed)" in printed and "runs/s (serial)" in printed
    assert "momentum_drift_max: min" in printed


def test_a_batch_without_vary_warns_that_its_runs_are_alike(tmp_path, capsys):
    """Without --vary every run starts alike: the command says so (the runs still go)."""
    scene = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"duration": 0.01})
    assert main(["batch", str(scene), "--runs", "2", "--quiet", "--out", str(tmp_path / "out")]) == 0
    assert "no --vary: the 2 runs start alike" in capsys.readouterr().err


def test_a_scene_left_to_choose_its_plant_runs_in_a_batch_as_in_simulate(tmp_path):
    """The tumbling scene without its model line (model = "auto", the default): every run of a
    batch chooses its plant by the same pilot as freefloat simulate (a registry model, recorded in
    its row) and completes; they all failed."""
    import tomllib

    from freefloat.app.scenes import builtin_scenes
    from freefloat.dynamics.models import MODELS

    from .conftest import toml_text

    raw = tomllib.loads(builtin_scenes()["tumbling"].read_text())
    del raw["simulation"]["model"]
    raw["simulation"]["duration"] = 0.01
    path = tmp_path / "tumbling.toml"
    path.write_text(toml_text(raw))
    scene = load_scene(path)
    assert scene.simulation.model == "auto"
    done = run_batch(scene, tmp_path / "out", 2, [Band("base_rate", 1.0)], seed=1)
    assert [r["status"] for r in done.rows] == ["completed"] * 2, [r["message"] for r in done.rows]
    assert done.summary["status"] == "completed"
    assert all(r["model_choice.model"] in MODELS for r in done.rows), done.rows[0]


def test_a_batch_with_failed_runs_reports_failed_with_the_count_completed(tmp_path, capsys):
    """Starts where the 5R cannot be assembled: the summary's status is "failed", not "completed",
    and the command's line counts the runs that completed."""
    scene = scene_variant(tmp_path / "m.toml", "five_bar_computed_torque", simulation={"duration": 0.01})
    status = main(["batch", str(scene), "--runs", "6", "--vary", "platform=0.2", "--seed", "0", "--quiet",
                   "--out", str(tmp_path / "out")])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    completed = summary["by_status"].get("completed", 0)
    assert status == 1 and summary["status"] == "failed" and 0 < completed < 6
    assert capsys.readouterr().out.startswith(f"failed: {completed} of 6 runs completed (")


def test_a_batch_onto_a_full_disk_exits_2_naming_the_file(tmp_path, monkeypatch, capsys):
    """When the disk refuses a journaled row, the batch stops with exit 2 naming the file
    (it exited 0)."""
    import errno
    import os

    real = os.write

    def full(fd, data):
        if os.path.basename(os.readlink(f"/proc/self/fd/{fd}")) == PARTIAL:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(fd, data)

    monkeypatch.setattr(os, "write", full)
    scene = short(tmp_path)
    assert main(["batch", str(scene.source), "--runs", "2", "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert f"{PARTIAL}': No space left on device" in capsys.readouterr().err


def test_threads_stop_the_runs_left_when_a_row_cannot_be_kept(tmp_path, monkeypatch):
    """When keeping a row fails (a full disk), the thread executor raises that error at once:
    the runs not started are never run and the running ones stop (it ran every run first)."""
    from freefloat.app.batch import executors
    from freefloat.app.batch.variations import plan_runs
    from freefloat.app.runner import prepare

    scene = short(tmp_path, "tumbling", 1.0)
    plans = plan_runs(scene, prepare(scene), [Band("mass", 0.1)], 40, 0)  # one plant per run: run by run
    started = []
    monkeypatch.setattr(executors, "run_one", lambda plan: started.append(plan.index) or run_one(plan))

    def full(row: dict) -> None:
        raise OSError("No space left on device")

    with pytest.raises(OSError, match="No space left"):
        executors.run_threads(plans, 2, full)
    assert len(started) < 10


@pytest.mark.parametrize("runs, workers, sizes", [
    (24, 2, [3] * 8),  # 4 tasks a worker
    (1000, 2, [8] * 125),  # at most a compiled group a task
    (5, 2, [1] * 5),
    (9, 1, [2] * 4 + [1]),
])
def test_pool_and_dask_tasks_hold_consecutive_runs(runs, workers, sizes):
    """Tasks of a pool or Dask batch: every run once, in order, at most a compiled group per task
    and at least four tasks per worker when there are runs enough."""
    from freefloat.app.batch.executors import task_groups

    plans = list(range(runs))
    groups = task_groups(plans, workers)  # type: ignore[arg-type]  # any items group alike
    assert [len(g) for g in groups] == sizes and [p for g in groups for p in g] == plans


def test_more_local_workers_than_the_machine_takes_are_refused_before_any_start():
    """Workers beyond the cores (at least 4) are refused naming --workers and the cores; a
    scheduler's workers are not capped."""
    from freefloat.app.batch.executors import local_limit

    with pytest.raises(FreefloatError, match=rf"count 200 is more processes .* cores and takes up to {local_limit()} .*force=True"):
        Workers(200)
    Workers(local_limit())
    Workers(200, dask=True, scheduler="tcp://nowhere:8786")


def test_forced_workers_beyond_the_cores_are_honoured():
    """``force=True`` (``--force-workers``) keeps a count above the cap; counts below 1 stay refused."""
    from freefloat.app.batch.executors import local_limit

    assert Workers(local_limit() + 3, force=True).count == local_limit() + 3
    with pytest.raises(FreefloatError, match="count must be an integer >= 1"):
        Workers(0, force=True)


@pytest.mark.parametrize("command", [["batch", "tumbling"], ["atlas", "workspace", "four_arm_planar"]])
def test_the_command_line_caps_workers_unless_forced(tmp_path, monkeypatch, capsys, command):
    """``--workers`` above the cap exits 2 naming the cap and ``--force-workers``; with
    ``--force-workers`` the count reaches the command as asked (stopped there, before any process)."""
    from freefloat.app import batch
    from freefloat.app.atlas import engine
    from freefloat.app.batch.executors import local_limit
    from freefloat.app.cli import main

    asked = local_limit() + 1
    seen = []

    def record(*args, **kwargs):
        seen.append(next(a for a in (*args, *kwargs.values()) if isinstance(a, Workers)))
        raise KeyboardInterrupt

    monkeypatch.setattr(batch, "run_batch", record)
    monkeypatch.setattr(engine, "run_atlas", record)
    argv = [*command, "--workers", str(asked), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"--workers {asked} is more processes" in err and f"takes up to {local_limit()}" in err
    assert "--force-workers" in err
    assert main([*argv, "--force-workers"]) == 1 and seen[0].count == asked
