"""Fuzz class of signals at checkpoints (issue 24): Ctrl-C, SIGTERM, SIGHUP or SIGKILL sent to
``freefloat simulate`` just as a telemetry checkpoint is being saved or has just been saved (or
to ``batch`` and ``reproduce models`` as a journal line lands). Afterwards every file is whole
with no telemetry row lost or repeated (``corrupted`` otherwise), stderr holds no traceback, and
a rerun into the folder (``--overwrite``, or reproduce's resume) completes (``not-resumable``).
"""

from __future__ import annotations

import random
import signal
import time
from dataclasses import dataclass
from pathlib import Path

from .conftest import cli_process, scene_variant
from .folder_checks import folder_problems
from .fuzzing import TIME_BOUND, Failure, cli

SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL]
PERIOD = 0.001  # the tumbling scene's control period, s


@dataclass
class SignalCase:
    """A command and the checkpoint (or journal line) at which a signal arrives."""

    seed: int
    command: str  # simulate, batch or reproduce
    signum: int
    at: int  # which checkpoint or journal line
    saving: bool  # simulate: while the part is saved (its temporary file exists) or once it is
    delay: float  # s after that
    kind: str = "signals"

    @property
    def mutation(self) -> str:
        when = ("while saving" if self.saving else "after") if self.command == "simulate" else "after line"
        return f"{self.command}: {signal.Signals(self.signum).name} {when} {self.at} +{self.delay * 1e3:.1f} ms"

    def run(self, folder: Path) -> tuple[str, str]:
        """Start the command, signal it at the trigger, check the folder, rerun."""
        folder.mkdir(parents=True, exist_ok=True)
        out = folder / "out"
        args = self._args(folder, out)
        proc = cli_process(*args)
        sent = self._signal_at_trigger(proc, out)
        try:
            _, err = proc.communicate(timeout=2 * TIME_BOUND)
        except Exception:  # noqa: BLE001 - a process (or a child holding its pipes) that never ends
            proc.kill()
            return "hang", f"no exit {2 * TIME_BOUND:g} s after the signal"
        if "Traceback" in err:
            return "traceback", err.strip()[-300:]
        if proc.returncode not in (0, 1, -signal.SIGKILL, -self.signum):
            return "traceback", f"exit {proc.returncode}: {err.strip()[-200:]}"
        problems = folder_problems(out, PERIOD if self.command == "simulate" else None)
        if problems:
            return "corrupted", "; ".join(problems)[:300]
        try:
            status, err = cli([*args, "--overwrite"] if self.command != "reproduce" else args)
        except Failure as failure:
            return failure.outcome, failure.detail
        problems = folder_problems(out, PERIOD if self.command == "simulate" else None)
        if status != 0 or problems:
            return "not-resumable", f"rerun exit {status}: {(err.strip()[-200:] or '; '.join(problems))}"
        return ("stopped", "") if sent else ("completed", "the command ended before the trigger")

    def _args(self, folder: Path, out: Path) -> list[str]:
        if self.command == "reproduce":
            return ["reproduce", "models", "--quick", "--workers", "1", "--out", str(out)]
        duration = 6.0 if self.command == "simulate" else 0.2
        scene = scene_variant(folder / "s.toml", "tumbling", simulation={"duration": duration},
                              output={"figures": False, "html": False})
        if self.command == "simulate":
            return ["simulate", str(scene), "--quiet", "--out", str(out)]
        return ["batch", str(scene), "--runs", "12", "--vary", "base_rate=5", "--workers", "1", "--quiet",
                "--out", str(out)]

    def _signal_at_trigger(self, proc, out: Path) -> bool:
        """Wait for the trigger, then send the signal ``delay`` s later; whether it was sent."""
        deadline = time.monotonic() + TIME_BOUND
        while proc.poll() is None and time.monotonic() < deadline:
            if self._triggered(out):
                time.sleep(self.delay)
                if proc.poll() is None:
                    proc.send_signal(self.signum)
                    return True
                return False
            time.sleep(0.0005)
        return False

    def _triggered(self, out: Path) -> bool:
        if self.command == "simulate":
            name = f"part-{self.at:05d}.npz"
            return (out / "telemetry-parts" / (f".{name}.partial" if self.saving else name)).exists()
        journal = out / ("runs-partial.jsonl" if self.command == "batch" else "parts.jsonl")
        try:
            return journal.read_bytes().count(b"\n") >= self.at
        except OSError:
            return False


def signal_case(seed: int) -> SignalCase:
    """A signal (:data:`SIGNALS`) at a checkpoint of simulate (70 %), or at a journal line of
    batch or reproduce models."""
    rng = random.Random(seed)
    command = rng.choices(["simulate", "batch", "reproduce"], [7, 2, 1])[0]
    at = rng.randint(0, 4) if command == "simulate" else rng.randint(1, 8)
    return SignalCase(seed, command, rng.choice(SIGNALS), at, rng.random() < 0.5, rng.choice([0.0, rng.uniform(0, 0.005)]))
