"""The output folder of one run: created and checked before the run starts, locked against other
runs, written file by file under temporary names, and checkpointed as telemetry comes in."""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
from pathlib import Path
from typing import Iterator

from ..dynamics.telemetry import Arrays
from ..errors import FreefloatError

#: Subfolder where telemetry is saved chunk by chunk while a run goes; removed once
#: ``telemetry.npz`` is written. A run killed outright (SIGKILL, power loss) leaves it behind:
#: ``Telemetry.load_parts(folder / PARTS)`` reads every checkpointed row.
PARTS = "telemetry-parts"
LOCK = ".freefloat.lock"


class RunFolder:
    """An output folder held by one run.

    Opening it creates the folder, takes an exclusive lock (a second run into the same folder is
    refused at once) and checks that it is empty; with ``overwrite`` a previous run's folder
    (one with a ``summary.json``) is cleared instead.

    Raises:
        FreefloatError: naming the folder when it is a file, sits under one, cannot be written,
            is in use by another run, or is not empty (and ``overwrite`` is not given, or it does
            not hold a freefloat run).
    """

    def __init__(self, path: Path, overwrite: bool = False):
        self.path = Path(path)
        self._parts = 0
        try:
            self.path.mkdir(parents=True, exist_ok=True)
            self._lock = open(self.path / LOCK, "w")
        except OSError as exc:
            raise FreefloatError(f"output folder '{self.path}' cannot be written: {exc.strerror or exc}") from exc
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self._lock.close()
            raise FreefloatError(f"output folder '{self.path}' is in use by another freefloat run") from None
        try:
            self._clear(overwrite)
            self.write_text(".freefloat-write-check", "")
            (self.path / ".freefloat-write-check").unlink()
        except BaseException:
            self.close()
            raise

    def _clear(self, overwrite: bool) -> None:
        held = [p for p in self.path.iterdir() if p.name != LOCK]
        if not held:
            return
        if not overwrite:
            raise FreefloatError(f"output folder '{self.path}' is not empty; choose another --out, or pass "
                                 "--overwrite to replace the run in it")
        if not (self.path / "summary.json").is_file() and not (self.path / PARTS).is_dir():
            raise FreefloatError(f"output folder '{self.path}' holds files but no freefloat run (no summary.json); "
                                 "not clearing it")
        for p in held:
            shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()

    def close(self) -> None:
        """Release the lock."""
        with contextlib.suppress(OSError):
            (self.path / LOCK).unlink()
        self._lock.close()

    def __enter__(self) -> RunFolder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def atomic(self, name: str) -> Iterator[Path]:
        """A temporary path to write ``name`` to; renamed into place when the block ends
        normally, removed otherwise, so no half-written file ever carries the name.

        Raises:
            FreefloatError: naming the file when the disk refuses it (full, read-only).
        """
        partial = self.path / f".{name}.partial"
        try:
            yield partial
            os.replace(partial, self.path / name)
        except OSError as exc:
            raise FreefloatError(f"could not write '{self.path / name}': {exc.strerror or exc}") from exc
        finally:
            with contextlib.suppress(OSError):
                partial.unlink()

    def write_text(self, name: str, text: str) -> Path:
        """Write ``name`` atomically; returns its path."""
        with self.atomic(name) as partial:
            partial.write_text(text)
        return self.path / name

    def save(self, name: str, arrays: Arrays, **metadata: object) -> Path:
        """Save telemetry as ``name`` (.npz, atomically, see ``Arrays.save``); returns its path.

        Raises:
            FreefloatError: naming the file when the disk refuses it.
        """
        try:
            arrays.save(self.path / name, **metadata)
        except OSError as exc:
            raise FreefloatError(f"could not write '{self.path / name}': {exc.strerror or exc}") from exc
        return self.path / name

    def checkpoint(self, chunk: Arrays) -> None:
        """Save the next chunk of a running run's telemetry under :data:`PARTS`."""
        (self.path / PARTS).mkdir(exist_ok=True)
        self.save(f"{PARTS}/part-{self._parts:05d}.npz", chunk)
        self._parts += 1

    def drop_checkpoints(self) -> None:
        """Remove the checkpoints once the whole telemetry is written."""
        shutil.rmtree(self.path / PARTS, ignore_errors=True)
