"""docs/first_hour.md section 2 against a real run of the default job: what the command prints
(warning, progress bar, writing stages, result, headline numbers, files), the files of the output
folder and what the page says about the figures."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from freefloat.app import figure_set
from freefloat.app.progress_bar import LoopBar
from freefloat.app.scenes import DEFAULT_SCENE, find_scene

from .conftest import REPO

PAGE = REPO / "docs" / "first_hour.md"
#: Below this a drift is round-off: the run's and the page's need not share a digit.
ROUND_OFF = 1e-10
#: Relative agreement of the other printed numbers (the summary prints 4 significant digits or more).
DIGITS = 1e-3


def _section() -> str:
    """Section 2 of the page, "The default job"."""
    text = PAGE.read_text()
    return text[text.index("## 2. The default job"):text.index("## 3.")]


def _printed() -> list[str]:
    """The lines of the section's output block (what the page says the command printed)."""
    (block,) = re.findall(r"^```text\n(.*?)^```", _section(), re.DOTALL | re.MULTILINE)[:1]
    return block.splitlines()


def _table() -> list[str]:
    """The names in the first column of the section's table of the output folder."""
    return [name for row in re.findall(r"^\| (.*?) \|", _section(), re.MULTILINE)
            for name in re.findall(r"`([^`]+)`", row)]


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> tuple[list[str], Path]:
    """``freefloat simulate`` in a fresh process from an empty folder, as the page runs it: its
    output lines (standard error, then standard output; the progress bar's last state) and its
    output folder."""
    where = tmp_path_factory.mktemp("first_hour")
    done = subprocess.run([sys.executable, "-m", "freefloat", "simulate"], cwd=where, capture_output=True, text=True,
                          timeout=600, check=True)
    lines = [line.split("\r")[-1] for line in (done.stderr + done.stdout).splitlines()]
    (folder,) = (where / "runs").iterdir()
    return lines, folder


def _starting(lines: list[str], prefix: str) -> list[str]:
    return [line for line in lines if line.startswith(prefix)]


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)]


@pytest.mark.slow
def test_the_page_prints_the_run_s_warning_bar_and_stages(run):
    """The warning lines as the run prints them, a progress bar over the 5000 periods (the run
    shows it when its loop outlasts LoopBar.DELAY, as the text says), and the writing stages in
    the run's order."""
    lines, _ = run
    printed = _printed()
    said = ("freefloat: warning:", "freefloat: note:", "  Pinocchio")
    warning = [line for line in lines if line.startswith(said)]
    assert [line for line in printed if line.startswith(said)] == warning
    (bar,) = re.findall(rf"`({DEFAULT_SCENE}: 100%.*?)`", _section())  # a busy machine's, quoted in the text
    assert "5000/5000" in bar and f"outlasts {LoopBar.DELAY} s" in " ".join(_section().split())
    shown = _starting(lines, f"{DEFAULT_SCENE}:")  # none when the loop ends within LoopBar.DELAY (an idle machine)
    assert all("5000/5000" in line for line in _starting(shown, f"{DEFAULT_SCENE}: 100%"))
    assert not shown or _starting(shown, f"{DEFAULT_SCENE}: 100%")
    stage = re.compile(r"^(writing .*) \.\.\. [\d.]+ s$")
    assert [stage.match(line).group(1) for line in printed if stage.match(line)] == \
        [stage.match(line).group(1) for line in lines if stage.match(line)]


def test_the_page_prints_the_run_s_result_and_headline_numbers(run):
    """The status and steps, each headline key in the run's order with the run's numbers (drifts
    both at round-off), and the files written."""
    lines, folder = run
    printed = _printed()
    (done,) = _starting(printed, "completed: 5000 steps in ")
    assert done.split(" -> ")[1].startswith(f"runs/{DEFAULT_SCENE}-")
    assert _starting(lines, "completed: 5000 steps in ")
    assert _starting(printed, "  wrote: ") == _starting(lines, "  wrote: ")
    headline = re.compile(r"^  (\w+): (.*)$")
    page = {m.group(1): m.group(2) for m in map(headline.match, printed) if m and m.group(1) != "wrote"}
    ran = {m.group(1): m.group(2) for m in map(headline.match, lines) if m and m.group(1) != "wrote"}
    assert list(page) == list(ran)
    for key in page:
        for shown, actual in zip(_numbers(page[key]), _numbers(ran[key]), strict=True):
            if max(abs(shown), abs(actual)) < ROUND_OFF:
                continue
            assert shown == pytest.approx(actual, rel=DIGITS), key


def test_the_page_lists_every_file_of_the_folder(run):
    """The table names every file the run wrote (figures by stem, as PNG) and no other."""
    _, folder = run
    files = {p.name for p in folder.iterdir() if not p.name.startswith(".")}
    named = {f"{name}.png" if "." not in name else name for name in _table()}
    assert named == files


def test_the_page_says_which_figures_and_formats_the_default_job_draws(run):
    """The figures the page names in the table are the default scene's set less those it leaves
    out, and the page says they are written as PNG only, as the scene asks."""
    _, folder = run
    scene = find_scene(DEFAULT_SCENE)
    not_drawn = set(json.loads((folder / "summary.json").read_text()).get("figures_not_drawn", {}))
    assert {name for name in _table() if "." not in name} == set(figure_set.drawn(scene)) - not_drawn
    assert scene.output.figure_formats == ("png",)
    assert "Each figure is written as PNG" in _section() and "PNG to look at, PDF to print" not in _section()


def test_the_page_s_sizes_and_drifts_hold(run):
    """The page's size (1.4 MB: "1.4 MB for the default job") to its digit, the CoM and momentum
    drifts at round-off (the table's "here at round-off")."""
    _, folder = run
    (size,) = re.findall(r"\(([\d.]+) MB for\s+the default job", PAGE.read_text())
    assert (folder / "trajectory.html").stat().st_size / 1e6 == pytest.approx(float(size), abs=0.05)
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["com_drift_max"] < ROUND_OFF and summary["momentum_drift_max"] < ROUND_OFF
