"""Faults at random instants (issue 24): Ctrl-C, SIGTERM or SIGKILL sent at a moment
hypothesis chooses (derandomized, a few examples each) to ``freefloat simulate``, ``batch``,
``bench`` and ``reproduce``. After each, every file left in the output folder is whole and
loadable, telemetry time goes up by one control period per row (no row lost or written twice),
every name there is in freefloat's record, and a rerun into the folder (``--overwrite``, or the
resume of reproduce) completes.

The instant is a fraction of the command's undisturbed wall time from freefloat's first line
(before it, a signal is the interpreter's own), measured once per command so that a loaded
machine moves the instants with it: start-up, the loop and its checkpoints, the writing and the
drawings are all hit.
"""

from __future__ import annotations

import functools
import random
import shutil
import signal
import tempfile
import time
import warnings
from pathlib import Path

import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from freefloat.app.cli import main
from freefloat.app.run_folder import LOCK

from .conftest import cli_process, scene_variant
from .folder_checks import FAULTS, folder_problems, signal_at, wait_for_handlers

#: Few examples, the same every run: the whole module stays under about 90 s on 2 cores.
EXAMPLES = {"simulate": 4, "batch": 3, "bench": 3, "reproduce": 3}
PERIOD = 0.001  # the tumbling scene's control period, s: one telemetry row each


def _faulted(args: list[str], span: float, fraction: float, signum: int, finished: str) -> None:
    """Run ``freefloat ARGS`` as a foreground process, send ``signum`` at ``fraction`` of ``span``
    seconds, and check how it ended: a catchable signal with exit 0 (it came too late to stop
    anything) or 1, and never a traceback; killed by the signal itself only after the command
    printed its last line, containing ``finished`` (the interpreter was exiting), or by SIGKILL."""
    proc = cli_process(*args)
    wait_for_handlers(proc)
    sent = signal_at(proc, fraction * span, signum)
    out, err = proc.communicate(timeout=120)  # also the pipes: a leftover child holds them
    name = signal.Signals(signum).name
    assert "Traceback" not in err, f"{name} at {fraction:.2f} of {span:.1f} s:\n{err}"
    allowed = {0, 1} | ({-signum} if sent and (signum == signal.SIGKILL or finished in out) else set())
    assert proc.returncode in allowed, f"exit {proc.returncode} after {name} at {fraction:.2f}; stderr:\n{err}"


def _rerun(args: list[str]) -> int:
    """The command again, in this process (its imports already paid), warnings silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return main(args)


@functools.cache
def _span(args: tuple[str, ...]) -> float:
    """Wall time of ``freefloat ARGS --out (a new folder)`` undisturbed from freefloat's first
    line to its exit, s (once per command); the run must complete and leave a sound folder."""
    out = Path(tempfile.mkdtemp()) / "out"
    proc = cli_process(*args, "--out", str(out))
    wait_for_handlers(proc)
    started = time.monotonic()
    _, err = proc.communicate(timeout=300)
    span = time.monotonic() - started
    assert proc.returncode == 0, f"the undisturbed run failed (exit {proc.returncode}):\n{err}"
    problems = folder_problems(out, PERIOD if args[0] == "simulate" else None)
    shutil.rmtree(out.parent)
    assert not problems, problems
    return span


@pytest.fixture(scope="module")
def scenes(tmp_path_factory) -> dict[str, Path]:
    """The tumbling scene lengthened for simulate (10 s: 10 checkpoints, then the figures) and
    shortened for batch (1 s per run)."""
    root = tmp_path_factory.mktemp("scenes")
    return {"simulate": scene_variant(root / "long.toml", "tumbling", simulation={"duration": 10.0},
                                      output={"figures": True, "html": False}),
            "batch": scene_variant(root / "short.toml", "tumbling", simulation={"duration": 1.0})}


faults = st.sampled_from(FAULTS)
#: A uniform fraction of the command's span, from a drawn seed (hypothesis' own floats crowd at the
#: ends of a range, and a few examples then all fall at the start or the very end).
instants = st.integers(0, 2**32 - 1).map(lambda seed: random.Random(seed).random())


def _example(n: int):
    """``n`` examples, the same each run, reported as found (shrinking would rerun the command
    for minutes)."""
    return settings(max_examples=n, deadline=None, derandomize=True, database=None,
                    phases=(Phase.explicit, Phase.generate))


@pytest.mark.slow
@_example(EXAMPLES["simulate"])
@given(signum=faults, fraction=instants)
def test_simulate_survives_a_fault_at_any_instant(tmp_path_factory, scenes, signum, fraction):
    """A run stopped at any instant leaves whole files and telemetry without a lost or repeated
    row; simulate --overwrite then completes into the same folder (without figures: the point is
    what it clears)."""
    root = tmp_path_factory.mktemp("simulate")
    args = ["simulate", str(scenes["simulate"]), "--quiet"]
    span = _span(tuple(args))
    out = root / "out"
    _faulted([*args, "--out", str(out)], span, fraction, signum, finished="wrote: ")
    assert not folder_problems(out, PERIOD), folder_problems(out, PERIOD)
    assert _rerun([*args, "--out", str(out), "--overwrite", "--no-figures"]) == 0
    assert not folder_problems(out, PERIOD), folder_problems(out, PERIOD)
    assert (out / "telemetry.npz").is_file() and not (out / "telemetry-parts").exists()


@pytest.mark.slow
@_example(EXAMPLES["batch"])
@given(signum=faults, fraction=instants)
def test_batch_survives_a_fault_at_any_instant(tmp_path_factory, scenes, signum, fraction):
    """A batch stopped at any instant leaves whole tables and journal; batch --overwrite then
    completes into the same folder."""
    root = tmp_path_factory.mktemp("batch")
    args = ["batch", str(scenes["batch"]), "--runs", "40", "--vary", "base_rate=5", "--workers", "1", "--quiet"]
    span = _span(tuple(args))
    out = root / "out"
    _faulted([*args, "--out", str(out)], span, fraction, signum, finished="runs completed")
    assert not folder_problems(out), folder_problems(out)
    assert _rerun([*args, "--out", str(out), "--overwrite"]) == 0
    assert not folder_problems(out) and not (out / "runs-partial.jsonl").exists()


@pytest.mark.slow
@_example(EXAMPLES["bench"])
@given(signum=faults, fraction=instants)
def test_bench_survives_a_fault_at_any_instant(tmp_path_factory, signum, fraction):
    """A quick bench stopped at any instant leaves whole report files and journal; a second
    bench into that folder is refused (bench has no --overwrite) without touching them."""
    pytest.importorskip("mujoco", reason="freefloat bench needs MuJoCo: pip install -e '.[bench]'")
    root = tmp_path_factory.mktemp("bench")
    args = ["bench", "dual_arm", "detumbling", "--quick"]
    span = _span(tuple(args))
    out = root / "out"
    _faulted([*args, "--out", str(out)], span, fraction, signum, finished="written to ")
    assert not folder_problems(out), folder_problems(out)
    if out.exists() and any(p.name != LOCK for p in out.iterdir()):
        before = _contents(out)
        assert _rerun([*args, "--out", str(out)]) == 2
        assert _contents(out) == before
    assert _rerun([*args, "--out", str(root / "again")]) == 0


def _contents(folder: Path) -> dict[Path, bytes]:
    """Every file under ``folder`` but the lock (which a refused run may remove: freefloat's own)."""
    return {p: p.read_bytes() for p in folder.rglob("*") if p.is_file() and p.name != LOCK}


@pytest.mark.slow
@_example(EXAMPLES["reproduce"])
@given(signum=faults, fraction=instants)
def test_reproduce_survives_a_fault_at_any_instant(tmp_path_factory, signum, fraction):
    """A quick models study stopped at any instant leaves whole files and journal, every one
    recorded; the same command then resumes and completes."""
    root = tmp_path_factory.mktemp("reproduce")
    args = ["reproduce", "models", "--quick", "--workers", "1"]
    span = _span(tuple(args))
    out = root / "out"
    _faulted([*args, "--out", str(out)], span, fraction, signum, finished=f"wrote {out} in ")
    assert not folder_problems(out), folder_problems(out)
    assert _rerun([*args, "--out", str(out)]) == 0
    assert not folder_problems(out), folder_problems(out)
    assert {"report.json", "report.md", "parts.jsonl"} <= {p.name for p in out.iterdir()}


def _cut_json(out: Path) -> None:
    (out / "summary.json").write_text((out / "summary.json").read_text()[:50])


def _row_twice(out: Path) -> None:
    from freefloat.dynamics.telemetry import Telemetry

    tel = Telemetry.load(out / "telemetry.npz")
    Telemetry.concatenate([tel, tel.truncated(3)]).save(out / "telemetry.npz")


def _stray(out: Path) -> None:
    (out / "stray.png").write_bytes(b"\x89PNG")


@pytest.mark.parametrize("damage, found", [(_cut_json, "summary.json: JSONDecodeError"),
                                           (_row_twice, "time does not increase"),
                                           (_stray, "stray.png: not in .freefloat-files")])
def test_the_folder_check_finds_what_a_fault_could_leave(tmp_path, damage, found):
    """The check the fault tests rely on reports a file cut short, telemetry rows written twice
    and a file outside freefloat's record, in a folder that was sound (it can fail)."""
    out = tmp_path / "out"
    short = scene_variant(tmp_path / "s.toml", "tumbling", simulation={"duration": 0.05},
                          output={"figures": False, "html": False})
    assert _rerun(["simulate", str(short), "--quiet", "--out", str(out)]) == 0
    assert not folder_problems(out, PERIOD)
    damage(out)
    assert any(found in problem for problem in folder_problems(out, PERIOD)), folder_problems(out, PERIOD)
