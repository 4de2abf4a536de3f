"""The output folder of one run: created and checked before the run starts, locked against other
runs, written file by file under temporary names, and checkpointed as telemetry comes in.

Every name freefloat creates in the folder is first written to its ownership record,
:data:`RECORD`; ``--overwrite`` removes exactly the names in that record and nothing else, and a
run never replaces a file the record does not name. freefloat's own files (the lock, the record,
the temporary files) are opened without following symbolic links."""

from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import os
import secrets
import shutil
import warnings
from collections.abc import Iterator
from pathlib import Path, PurePosixPath

from ..dynamics.telemetry import Arrays
from ..errors import LISTED, FreefloatError, RunFolderError, few, spelled

#: Subfolder where telemetry is saved chunk by chunk while a run goes; removed once
#: ``telemetry.npz`` is written. A run killed outright (SIGKILL, power loss) leaves it behind:
#: ``Telemetry.load_parts(folder / PARTS)`` reads every checkpointed row.
PARTS = "telemetry-parts"
LOCK = ".freefloat.lock"
#: The ownership record: one name (relative to the folder, ``/``-separated) per line, of every
#: file or folder freefloat created there; a folder's name ends with ``/``.
RECORD = ".freefloat-files"
#: The record rewritten, before it is renamed over :data:`RECORD` (see :meth:`RunFolder.close`).
RECORD_NEW = ".freefloat-files.new"
_HEADER = ("# freefloat: the files its runs wrote in this folder; overwriting (--overwrite, overwrite=True) removes "
           "these and nothing else\n")
#: Name prefix of :meth:`RunFolder.private_dir` folders.
_PRIVATE = ".drawing-"
#: Opening flags of freefloat's own files: never through a symbolic link, not inherited.
_NOFOLLOW = os.O_NOFOLLOW | os.O_CLOEXEC


def _another_folder() -> str:
    """The remedy for a folder holding files freefloat did not write, naming the argument as the
    caller gave it (:func:`~freefloat.errors.spelled`)."""
    return f"choose another {spelled('out=', '--out')} (a new or empty folder)"


def open_own(path: Path, flags: int, mode: int = 0o644) -> int:
    """``os.open(path, flags)`` that refuses a symbolic link at ``path`` (a file descriptor).

    Raises:
        RunFolderError: naming ``path`` when it is a symbolic link (or cannot be opened).
    """
    try:
        return os.open(path, flags | _NOFOLLOW, mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP or os.path.islink(path):
            raise RunFolderError(f"'{path}' is a symbolic link; freefloat does not follow links for its own "
                                 "files (remove it)") from None
        raise RunFolderError(f"'{path}' cannot be written: {exc.strerror or exc}") from exc


class RunFolder:
    """An output folder held by one run.

    Opening it creates the folder, takes an exclusive lock (a second run into the same folder is
    refused at once) and checks that it is empty; with ``overwrite`` the files a previous run
    recorded in :data:`RECORD` are removed instead, and every other file is kept.

    Args:
        keep_foreign: with ``overwrite``, keep files freefloat did not write (otherwise refuse
            the folder when it holds any: for a command that writes into it directly).
        resume: without ``overwrite``, take a folder that holds only freefloat's files as it is
            (a command that continues from its journal), instead of refusing it.

    Raises:
        RunFolderError: naming the folder when it is a file, sits under one, cannot be written,
            is in use by another run, or is not empty (and ``overwrite`` is not given, or it holds
            no record of freefloat's files); naming the lock when it is a symbolic link.
    """

    def __init__(self, path: Path, overwrite: bool = False, keep_foreign: bool = True, resume: bool = False):
        self.path = Path(path)
        self._last_part: tuple[Arrays | None, int] = (None, -1)
        self._mine: set[str] = set()
        self._taken = False
        self._made = not os.path.lexists(self.path)  # removed again by close() if it stays empty
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RunFolderError(f"output folder '{self.path}' cannot be written: {exc.strerror or exc}") from exc
        self._lock = open_own(self.path / LOCK, os.O_RDWR | os.O_CREAT)
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(self._lock)
            raise RunFolderError(f"output folder '{self.path}' is in use by another freefloat run") from None
        try:
            self._clear(overwrite, keep_foreign, resume)
            self.write_text(".freefloat-write-check", "")
            (self.path / ".freefloat-write-check").unlink()
        except BaseException:
            self.close()
            raise
        self._taken = True

    def owned(self) -> list[str]:
        """The names the ownership record lists (each checked to name a path inside the folder).

        Raises:
            RunFolderError: naming the record when it lists a path outside the folder.
        """
        record = self.path / RECORD
        if not os.path.lexists(record):
            return []
        fd = open_own(record, os.O_RDONLY)
        with os.fdopen(fd, errors="replace") as file:
            names = [line.rstrip("\n") for line in file if line.strip() and not line.startswith("#")]
        for name in names:
            parts = PurePosixPath(name).parts
            if not parts or parts[0] == "/" or ".." in parts or len(parts) > 2:
                raise RunFolderError(f"'{record}' names '{name}', which is not a path inside the folder; "
                                     "not clearing it")
        return names

    def _clear(self, overwrite: bool, keep_foreign: bool, resume: bool) -> None:
        with contextlib.suppress(FileNotFoundError):
            (self.path / RECORD_NEW).unlink()  # a rewrite a kill cut short (the record stands)
        held = [p for p in self.path.iterdir() if p.name not in (LOCK, RECORD)]
        if not held:
            return
        self._refuse_links(self.owned())
        if resume and not overwrite:
            owned = self.owned()
            foreign = sorted(p.name for p in held if p.name not in {n.split("/")[0] for n in owned})
            if not foreign:  # a previous run of the same command: continue it, its files are ours
                self._mine.update(n.rstrip("/") for n in owned)
                for name in owned:  # what a killed run was making out of sight (the lock is ours now)
                    if name.startswith(_PRIVATE):
                        _remove(self.path / name.rstrip("/"), folder=True)
                return
            raise RunFolderError(f"output folder '{self.path}' holds files freefloat did not write "
                                 f"({few(foreign, LISTED)}); {_another_folder()}")
        owned = self.owned()
        foreign = sorted(p.name for p in held if p.name not in {n.split("/")[0] for n in owned})
        if not owned:  # overwriting would not clear it either: say only what works
            raise RunFolderError(f"output folder '{self.path}' holds files freefloat did not write "
                                 f"({few(foreign, LISTED)}); {_another_folder()}")
        if foreign and not keep_foreign:
            raise RunFolderError(f"output folder '{self.path}' holds files freefloat did not write ({few(foreign, LISTED)}) "
                                 "and this command writes files whose names it does not know up front; "
                                 f"{_another_folder()}")
        if not overwrite:
            raise RunFolderError(f"output folder '{self.path}' holds a previous run; choose another "
                                 f"{spelled('out=', '--out')}, or pass {spelled('overwrite=True', '--overwrite')} to "
                                 "replace that run" + (f" (your files there stay: {few(foreign, LISTED)})"
                                                       if foreign else ""))
        for name in sorted(set(owned), key=lambda n: -n.rstrip("/").count("/")):  # a folder's contents before it
            _remove(self.path / name.rstrip("/"), folder=name.endswith("/"))
        with contextlib.suppress(FileNotFoundError):
            (self.path / RECORD).unlink()
        kept = sorted(p.name for p in self.path.iterdir() if p.name != LOCK)
        if kept:
            warnings.warn(f"{spelled('overwrite=True', '--overwrite')} kept {len(kept)} file(s) in '{self.path}' that "
                          f"freefloat did not write: {', '.join(kept)}", stacklevel=2)

    def _refuse_links(self, names: list[str]) -> None:
        """Refuse the folder when a recorded name, or the folder it sits in, is a symbolic link:
        freefloat never makes one, so it is not freefloat's, and neither resuming (reading and
        writing through it) nor overwriting (removing it or what it points to) may touch it.

        Raises:
            RunFolderError: naming the first such link.
        """
        for name in names:
            self._no_link(name)

    def _no_link(self, name: str) -> None:
        """Raise :class:`RunFolderError` when ``name`` (relative, ``/``-separated) or one of the
        folders it sits in inside :attr:`path` is a symbolic link."""
        parts = PurePosixPath(name.rstrip("/")).parts
        for depth in range(1, len(parts) + 1):
            path = self.path.joinpath(*parts[:depth])
            if path.is_symlink():
                raise RunFolderError(f"'{path}' is a symbolic link where freefloat keeps its own "
                                     f"{'file' if depth == len(parts) and not name.endswith('/') else 'folder'}; "
                                     "freefloat neither follows nor removes links it did not create (remove it, "
                                     f"or choose another {spelled('out=', '--out')})")

    def claim(self, name: str) -> Path:
        """Record ``name`` (relative to the folder; a folder ends with ``/``) as freefloat's before
        it is created, and return its path.

        Raises:
            RunFolderError: naming the file when it exists and is not freefloat's (not written by
                this run), or when the record cannot be written; naming the link when ``name``'s
                folder, or a folder ``name`` itself, is a symbolic link (even one the record names).
        """
        bare = name.rstrip("/")
        path = self.path / bare
        self._no_link(name if name.endswith("/") else str(PurePosixPath(bare).parent))
        if bare not in self._mine:
            reusable = name.endswith("/") and path.is_dir() and not path.is_symlink()  # its files are claimed one by one
            if os.path.lexists(path) and not reusable:
                raise RunFolderError(f"'{path}' exists and freefloat did not write it; not replacing it "
                                     f"(move it away or choose another {spelled('out=', '--out')})")
            fd = open_own(self.path / RECORD, os.O_WRONLY | os.O_CREAT | os.O_APPEND)
            try:
                if os.fstat(fd).st_size == 0:
                    os.write(fd, _HEADER.encode())
                os.write(fd, f"{name}\n".encode())
            finally:
                os.close(fd)
            self._mine.add(bare)
        return path

    def _claim_file(self, name: str) -> tuple[Path, Path]:
        """Claim ``name`` and its temporary name; both paths, the temporary one created empty (a
        link or file left there before is removed first, so nothing is written through it)."""
        final = self.claim(name)
        partial = self.claim(str(PurePosixPath(name).with_name(f".{PurePosixPath(name).name}.partial")))
        with contextlib.suppress(FileNotFoundError):
            partial.unlink()
        os.close(open_own(partial, os.O_WRONLY | os.O_CREAT | os.O_EXCL))
        return final, partial

    def close(self) -> None:
        """Release the lock, once the record of a folder this run took lists only the names still
        there (:meth:`prune`); a folder this run made and left with nothing in its record (a run
        refused before it wrote anything) is removed again."""
        if self._taken:
            with contextlib.suppress(OSError, FreefloatError):
                self.prune()
                if not self.owned():
                    (self.path / RECORD).unlink(missing_ok=True)
        with contextlib.suppress(OSError):
            (self.path / LOCK).unlink()
        with contextlib.suppress(OSError):
            os.close(self._lock)
        if self._made:
            with contextlib.suppress(OSError):
                self.path.rmdir()  # only when empty

    def prune(self) -> None:
        """Drop from the record the names no longer in the folder (temporary files renamed into
        place, checkpoints removed once the telemetry was written, private folders): a name
        freefloat removed itself is no longer its own, and a user's file made under it later is
        not ``--overwrite``'s to remove. The record is rewritten under :data:`RECORD_NEW` and
        renamed over the old one, so a kill leaves one whole record or the other."""
        names = self.owned()
        kept = [n for n in names if os.path.lexists(self.path / n.rstrip("/"))]
        if len(kept) == len(names):
            return
        fresh = self.path / RECORD_NEW
        with contextlib.suppress(FileNotFoundError):
            fresh.unlink()
        with os.fdopen(open_own(fresh, os.O_WRONLY | os.O_CREAT | os.O_EXCL), "w") as file:
            file.write(_HEADER + "".join(f"{name}\n" for name in kept))
        os.replace(fresh, self.path / RECORD)

    def __enter__(self) -> RunFolder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def atomic(self, name: str) -> Iterator[Path]:
        """A temporary path to write ``name`` to; renamed into place when the block ends
        normally, removed otherwise, so no half-written file ever carries the name.

        Raises:
            RunFolderError: naming the file when the disk refuses it (full, read-only), or when a
                file of that name exists that freefloat did not write.
        """
        try:
            final, partial = self._claim_file(name)
        except OSError as exc:
            raise RunFolderError(f"could not write '{self.path / name}': {exc.strerror or exc}") from exc
        try:
            yield partial
            os.replace(partial, final)
        except OSError as exc:
            raise RunFolderError(f"could not write '{final}': {exc.strerror or exc}") from exc
        finally:
            with contextlib.suppress(OSError):
                partial.unlink()

    def write_text(self, name: str, text: str) -> Path:
        """Write ``name`` atomically; returns its path."""
        with self.atomic(name) as partial:
            partial.write_text(text)
        return self.path / name

    def journal(self, name: str) -> Journal:
        """``name`` opened for appending lines (a journal), claimed first and never through a link."""
        path = self.claim(name)
        return Journal(path, open_own(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND))

    def save(self, name: str, arrays: Arrays, *, compressed: bool = True, **metadata: object) -> Path:
        """Save telemetry as ``name`` (.npz, atomically, see ``Arrays.save``); returns its path.

        Raises:
            RunFolderError: naming the file when the disk refuses it.
        """
        final, _ = self._claim_file(name)
        try:
            arrays.save(final, compressed=compressed, **metadata)
        except OSError as exc:
            raise RunFolderError(f"could not write '{final}': {exc.strerror or exc}") from exc
        return final

    def subfolder(self, name: str) -> Path:
        """The subfolder ``name`` of freefloat's, claimed and created (or reopened, on a resume),
        never through a symbolic link.

        Raises:
            RunFolderError: naming it when it is a symbolic link or a file.
        """
        path = self.claim(f"{name}/")
        try:
            path.mkdir(exist_ok=True)
        except OSError as exc:
            raise RunFolderError(f"'{path}' cannot be made a folder: {exc.strerror or exc}") from exc
        self._no_link(f"{name}/")  # made between the check and mkdir
        return path

    def private_dir(self) -> Path:
        """A new, uniquely named hidden subfolder of freefloat's (for files made out of sight and
        then :meth:`place`-d: a file appears in the folder only whole, and whatever a kill leaves
        half-made stays in a folder of freefloat's, removed by ``--overwrite`` or a resume)."""
        into = self.claim(f"{_PRIVATE}{secrets.token_hex(6)}/")
        into.mkdir()
        return into

    def place(self, made: Path) -> Path:
        """Move the file ``made`` (in a :meth:`private_dir`) into the folder under its name."""
        final = self.claim(made.name)
        os.replace(made, final)
        return final

    def checkpoint(self, chunk: Arrays) -> None:
        """Save the next chunk of a running run's telemetry under :data:`PARTS`; the same chunk
        object again (its hand-over was interrupted, see ``Chunks``) replaces its own part, so no
        row is ever saved twice."""
        self.subfolder(PARTS)
        last, index = self._last_part
        index = index if chunk is last else index + 1
        self.save(f"{PARTS}/part-{index:05d}.npz", chunk, compressed=False)  # removed when the run ends
        self._last_part = (chunk, index)  # one assignment: an interrupt leaves the old pair or the new

    def drop_checkpoints(self) -> None:
        """Remove the checkpoints once the whole telemetry is written (a file in :data:`PARTS`
        that freefloat did not write stays, and so does the folder then)."""
        parts = self.path / PARTS
        if PARTS not in self._mine or parts.is_symlink() or not parts.is_dir():
            return
        for part in parts.iterdir():
            if f"{PARTS}/{part.name}" in self._mine:
                part.unlink()
        with contextlib.suppress(OSError):
            parts.rmdir()


def journal_entries(path: Path, again: str) -> list[tuple[int, dict]]:
    """The entries of the journal ``path`` (one JSON object a line, as :class:`Journal` appends
    them), with their line numbers; none when there is no such file. A last line without its
    newline (a kill during the append) is dropped; ``again`` says how to start over, for the
    message.

    Raises:
        RunFolderError: naming the file and the line for a line that is not a JSON object.
    """
    if not path.is_file():
        return []
    text = path.read_text(errors="replace")
    entries = []
    for number, line in enumerate(text.splitlines()[:None if text.endswith("\n") else -1], 1):
        try:
            entry = json.loads(line) if line.strip() else {}
        except json.JSONDecodeError:
            entry = None
        if not isinstance(entry, dict):
            raise RunFolderError(f"'{path}' line {number} is not a JSON object; not resuming from it ({again})")
        if entry:
            entries.append((number, entry))
    return entries


class Journal:
    """A file that lines are appended to, each written through to the operating system at once
    (unbuffered), so that a kill keeps every line appended before it.

    Raises:
        RunFolderError: naming the file when the disk refuses a line (full, read-only).
    """

    def __init__(self, path: Path, fd: int):
        self.path, self._fd = path, fd

    def append(self, line: str) -> None:
        """Append ``line`` and a newline."""
        data = (line + "\n").encode()
        try:
            while data:
                data = data[os.write(self._fd, data):]
        except OSError as exc:
            raise RunFolderError(f"could not write '{self.path}': {exc.strerror or exc}") from None

    def close(self) -> None:
        """Close the file."""
        with contextlib.suppress(OSError):
            os.close(self._fd)

    def __enter__(self) -> Journal:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _remove(path: Path, folder: bool) -> None:
    """Remove one recorded name: a file or link by unlinking it, a folder once it is empty (a
    private drawing folder with what it holds)."""
    if not os.path.lexists(path):
        return
    try:
        if path.is_symlink() or not path.is_dir():
            path.unlink()
        elif path.name.startswith(_PRIVATE):
            shutil.rmtree(path)
        elif folder:
            with contextlib.suppress(OSError):
                path.rmdir()  # it still holds files freefloat did not write
    except OSError as exc:
        raise RunFolderError(f"could not remove '{path}': {exc.strerror or exc}") from exc
