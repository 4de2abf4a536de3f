"""What a fault may leave in an output folder, checked file by file: every file complete and
loadable, every telemetry row present once and in order, every name in freefloat's ownership
record (so that ``--overwrite`` can clear it). Shared by tests/test_faults.py and the fuzz
harness (tests/fuzzing.py).
"""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import subprocess
import time
import tomllib
from pathlib import Path

import numpy as np

from freefloat.app.run_folder import LOCK, PARTS, RECORD, RECORD_NEW
from freefloat.dynamics.telemetry import Arrays, MechanismTelemetry, PlantTelemetry, Telemetry
from freefloat.errors import TelemetryFileError

#: The kinds of telemetry a run folder may hold, tried in turn.
KINDS: tuple[type[Arrays], ...] = (Telemetry, PlantTelemetry, MechanismTelemetry)
#: How each kind of file ends when it is whole.
ENDINGS = {".png": b"IEND\xaeB`\x82", ".pdf": b"%%EOF"}


def folder_problems(folder: Path, period: float | None = None, ignore: set[str] = frozenset()) -> list[str]:
    """What is wrong in ``folder`` after a run or a fault (empty when nothing is): a file that
    does not load or is cut short, telemetry whose time does not strictly increase (or, with
    ``period``, is not ``k * period`` for every row ``k``: a row lost or repeated), a name
    freefloat's record does not list. Names in ``ignore`` (at the top of the folder: a user's
    files) are left out."""
    folder = Path(folder)
    if not folder.exists():
        return []
    problems = [p for p in _unrecorded(folder) if p.split(":")[0] not in ignore]
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        if relative.parts[0] in ignore or path.is_symlink():
            continue  # a user's, or a link freefloat never writes
        if path.is_dir() or path.name in (LOCK, RECORD) or any(p.startswith(".") for p in relative.parts):
            continue  # freefloat's temporary names: recorded (checked above), never taken as results
        try:
            problem = _file_problem(path, period)
        except Exception as exc:  # noqa: BLE001 - any failure to load is what is looked for
            problem = f"{type(exc).__name__}: {exc}"
        if problem:
            problems.append(f"{relative}: {problem}")
    parts = folder / PARTS
    if PARTS not in ignore and parts.is_dir() and not parts.is_symlink() and list(parts.glob("part-*.npz")):
        try:
            whole = (folder / "telemetry.npz").is_file()  # then the parts may be half removed
            problem = _time_problem(_load(parts, parts_folder=True).t, None if whole else period)
        except Exception as exc:  # noqa: BLE001
            problem = f"{type(exc).__name__}: {exc}"
        if problem:
            problems.append(f"{PARTS}/: {problem}")
    return problems


def _unrecorded(folder: Path) -> list[str]:
    """The names at the top of ``folder`` that the ownership record does not list."""
    record = folder / RECORD
    listed = set()
    if record.is_file() and not record.is_symlink():
        text = record.read_text()
        if text and not text.endswith("\n"):
            return [f"{RECORD}: its last line is cut"]
        listed = {line.split("/")[0] for line in text.splitlines() if line and not line.startswith("#")}
    return [f"{p.name}: not in {RECORD}" for p in sorted(folder.iterdir())
            if p.name not in (LOCK, RECORD, RECORD_NEW) and p.name not in listed]


def _file_problem(path: Path, period: float | None) -> str:
    """What is wrong with one result file ('' when it is whole)."""
    suffix = path.suffix
    if suffix == ".npz":
        if path.name == "atlas.npz" or path.parent.name == "chunks":  # an atlas's arrays, no telemetry
            with np.load(path) as data:
                return "" if data.files else "no arrays"
        if path.parent.name == PARTS:
            _load(path)  # the parts' time is checked together
            return ""
        return _time_problem(_load(path).t, period if path.name == "telemetry.npz" else None)
    data = path.read_bytes()
    if suffix in ENDINGS:
        return "" if data.rstrip().endswith(ENDINGS[suffix]) else f"cut short ({len(data)} bytes)"
    text = data.decode("utf-8")
    if suffix == ".json":
        json.loads(text, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(f"non-strict constant {c}")))
    elif suffix == ".jsonl":
        if text and not text.endswith("\n"):
            return "its last line is cut"
        for line in text.splitlines():
            json.loads(line)
    elif suffix == ".csv":
        rows = list(csv.reader(io.StringIO(text)))
        if any(len(row) != len(rows[0]) for row in rows):
            return "rows of different lengths"
    elif suffix == ".toml":
        tomllib.loads(text)
    elif suffix == ".html":
        return "" if "</html>" in text[-200:] else "cut short (no </html>)"
    return ""


def _load(path: Path, parts_folder: bool = False) -> Arrays:
    """The telemetry in ``path`` (a file, or a folder of parts), of whichever kind it is."""
    for kind in KINDS:
        try:
            return kind.load_parts(path) if parts_folder else kind.load(path)
        except TelemetryFileError as exc:
            if "lacks" not in str(exc):
                raise
    raise TelemetryFileError(f"'{path}' is no kind of telemetry freefloat writes")


def _time_problem(t: np.ndarray, period: float | None) -> str:
    """'' when ``t`` strictly increases (and is ``k * period`` for row ``k``, when given)."""
    if len(t) > 1 and not np.all(np.diff(t) > 0):
        k = int(np.argmin(np.diff(t) > 0))
        return f"time does not increase: t[{k}] = {t[k]:.6g} -> t[{k + 1}] = {t[k + 1]:.6g} ({len(t)} rows)"
    if period is not None and len(t) and not np.allclose(t, period * np.arange(len(t)), rtol=0, atol=1e-9):
        k = int(np.argmax(~np.isclose(t, period * np.arange(len(t)), rtol=0, atol=1e-9)))
        return f"row {k} is at t = {t[k]:.6g}, not {k * period:.6g}: a row lost or repeated"
    return ""


def wait_for_handlers(proc: subprocess.Popen, timeout: float = 120.0) -> None:
    """Wait until ``proc`` catches SIGTERM (read from ``/proc/PID/status``): freefloat's first
    line has run (``python -m freefloat`` defers the stop signals before anything else). A
    signal before that is the interpreter's own business (exit -SIGNUM, nothing written)."""
    deadline = time.monotonic() + timeout
    bit = 1 << (signal.SIGTERM - 1)
    while proc.poll() is None:
        try:
            status = Path(f"/proc/{proc.pid}/status").read_text()
        except OSError:
            return
        caught = next((line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), "0")
        if int(caught, 16) & bit:
            return
        if time.monotonic() > deadline:
            raise TimeoutError(f"process {proc.pid} never took over SIGTERM")
        time.sleep(0.002)


def signal_at(proc: subprocess.Popen, delay: float, signum: int) -> bool:
    """Send ``signum`` to ``proc`` ``delay`` seconds after now, unless it ended before; whether it
    was sent."""
    time.sleep(delay)
    if proc.poll() is not None:
        return False
    os.kill(proc.pid, signum)
    return True


#: Signals a fault test sends: Ctrl-C, a polite stop (SIGHUP takes the same way, see
#: test_runner.py) and a kill.
FAULTS = (signal.SIGINT, signal.SIGTERM, signal.SIGKILL)
