"""``freefloat bench --quick`` writes its folder: JSON, CSV, one chart per scene and a summary."""

from __future__ import annotations

import csv
import json
import os
import signal
import time

import pytest

from freefloat.app.cli import main
from freefloat.app.run_folder import RECORD
from freefloat.lab.bench.options import SMOKE
from freefloat.lab.bench.race.summary import BANDS
from freefloat.lab.bench.scenes.free_floating import free_floating_scene

from .conftest import cli_process


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """``freefloat bench dual_arm --quick`` into a temporary folder."""
    out = tmp_path_factory.mktemp("bench") / "out"
    return main(["bench", "dual_arm", "--quick", "--out", str(out)]), out


@pytest.mark.slow
def test_quick_bench_writes_every_file(quick_run):
    """Exit 0 and bench.json, bench.csv, dual_arm.png and summary.txt are written."""
    status, out = quick_run
    assert status == 0
    assert {p.name for p in out.iterdir() if p.name != RECORD} == {"bench.json", "bench.csv", "dual_arm.png",
                                                                  "summary.txt"}


@pytest.mark.slow
def test_csv_and_json_hold_the_same_points(quick_run):
    """Every JSON point is a CSV row, with a positive time and a finite error."""
    _, out = quick_run
    report = json.loads((out / "bench.json").read_text())
    rows = list(csv.DictReader((out / "bench.csv").open()))
    points = report["scenes"]["dual_arm"]["points"]
    assert len(rows) == len(points) == len(free_floating_scene("dual_arm", quick=True).methods())
    assert all(float(r["wall_time_s"]) > 0.0 and float(r["state_error"]) >= 0.0 for r in rows)


@pytest.mark.slow
def test_the_report_records_the_mujoco_that_ran(quick_run):
    """bench.json records the version of the MuJoCo imported, also where only mujoco-core (the
    bench extra) is installed and the meta package ``mujoco`` is not."""
    mujoco = pytest.importorskip("mujoco")
    _, out = quick_run
    assert json.loads((out / "bench.json").read_text())["versions"]["mujoco"] == mujoco.__version__


@pytest.mark.slow
def test_summary_has_one_line_per_band(quick_run):
    """The summary names, per accuracy band, the cheapest method of each package; a --quick run's
    says first, and on each line, that it is a smoke test."""
    _, out = quick_run
    smoke, *lines = (out / "summary.txt").read_text().splitlines()
    assert smoke == SMOKE and len(lines) == len(BANDS)
    assert all(line.startswith("dual_arm error <= ") and line.endswith("(smoke test)") for line in lines)


@pytest.mark.slow
def test_a_quick_bench_is_marked_a_smoke_test(quick_run):
    """--quick: bench.json says it is a smoke test, and so does the chart, in a band above it."""
    import matplotlib.pyplot as plt

    _, out = quick_run
    assert json.loads((out / "bench.json").read_text())["smoke_test"] == SMOKE
    chart = plt.imread(out / "dual_arm.png")
    assert chart[2, chart.shape[1] // 2, 0] > 0.6 > chart[2, chart.shape[1] // 2, 1]  # the red band on top


def test_unknown_scene_exits_2_naming_it(tmp_path, capsys):
    """An unknown scene is refused before anything runs, the message listing the valid ones."""
    assert main(["bench", "nope", "--quick", "--out", str(tmp_path / "o")]) == 2
    assert "unknown bench scene 'nope'; valid: four_arm, dual_arm, controlled, detumbling, five_bar, rsu_ppap" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_non_empty_folder_is_refused(tmp_path, capsys):
    """A folder that already holds files is refused (exit 2), its files left alone."""
    (tmp_path / "keep.txt").write_text("x")
    assert main(["bench", "dual_arm", "--quick", "--out", str(tmp_path)]) == 2
    assert "did not write (keep.txt)" in capsys.readouterr().err
    assert {p.name for p in tmp_path.iterdir()} == {"keep.txt"}


@pytest.mark.slow
def test_controlled_quick_bench_compares_both_controllers(tmp_path):
    """``freefloat bench controlled --quick`` measures freefloat's compiled loop and MuJoCo with
    both controllers, and its summary names a cheapest method per band."""
    import warnings

    out = tmp_path / "c"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["bench", "controlled", "--quick", "--out", str(out)]) == 0
    rows = list(csv.DictReader((out / "bench.csv").open()))
    labels = {(r["package"], r["integrator"], r["loop"]) for r in rows}
    assert {("mujoco", "RK4", "python"), ("mujoco", "RK4", "native"), ("freefloat", "rkmk4", "compiled")} <= labels
    assert (out / "controlled.png").stat().st_size > 0
    assert len((out / "summary.txt").read_text().splitlines()) == 1 + len(BANDS)  # the smoke note, a line per band


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_bench_keeps_the_points_measured(tmp_path, signum):
    """Ctrl-C or SIGTERM during a sweep: exit 1, and bench.json (status "interrupted") and
    bench.csv hold every point measured before it."""
    out = tmp_path / "b"
    proc = cli_process("bench", "four_arm", "--out", str(out))
    deadline = time.monotonic() + 120
    while "four_arm: measuring" not in proc.stdout.readline():
        assert time.monotonic() < deadline and proc.poll() is None, "the bench never started"
    time.sleep(2.0)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, err
    report = json.loads((out / "bench.json").read_text())
    rows = list(csv.DictReader((out / "bench.csv").open()))
    assert report["status"].startswith(f"interrupted ({signal.Signals(signum).name}) after ")
    assert 1 <= len(rows) == len(report["scenes"]["four_arm"]["points"]) < len(free_floating_scene("four_arm").methods())


@pytest.mark.slow
def test_a_killed_bench_keeps_every_point_measured(tmp_path):
    """SIGKILL mid-bench leaves each point measured so far in the journal, one JSON row each (it
    kept none)."""
    import time

    from freefloat.lab.bench.race.report import JOURNAL

    from .conftest import cli_process

    out = tmp_path / "out"
    proc = cli_process("bench", "dual_arm", "--repeats", "1", "--out", str(out))
    deadline = time.monotonic() + 240
    while not (out / JOURNAL).is_file() or not (out / JOURNAL).read_text().count("\n") >= 2:
        assert time.monotonic() < deadline and proc.poll() is None, "no point journaled"
        time.sleep(0.2)
    proc.kill()
    proc.communicate(timeout=60)
    rows = [json.loads(line) for line in (out / JOURNAL).read_text().splitlines()]
    assert len(rows) >= 2 and all(r["scene"] == "dual_arm" and r["wall_time_s"] > 0 for r in rows)


@pytest.mark.slow
def test_a_signal_while_a_chart_is_drawn_waits_for_the_drawing(tmp_path, monkeypatch):
    """SIGINT arriving in the middle of a chart's drawing stops the bench after that drawing: the
    report says interrupted and the chart is whole (a drawing cut half-way failed the final one)."""
    from matplotlib.lines import Line2D

    draw = Line2D.draw
    events = []

    def draw_and_interrupt(self, renderer):
        if not events:
            events.append("sent")
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)  # the handler runs here, inside the drawing
            events.append("drawing went on")
        return draw(self, renderer)

    monkeypatch.setattr(Line2D, "draw", draw_and_interrupt)
    out = tmp_path / "out"
    main(["bench", "dual_arm", "--quick", "--out", str(out)])
    report = json.loads((out / "bench.json").read_text())
    assert events == ["sent", "drawing went on"] and report["status"].startswith("interrupted (SIGINT)")
    assert (out / "dual_arm.png").stat().st_size > 0
