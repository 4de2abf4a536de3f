"""A helper process that draws and renders figures while this one does other work. It is a new
interpreter (``python -m freefloat.app.viz.rendering``) fed pickled jobs through a pipe: never
a fork, since this process has threads (BLAS, progress bars) and a fork of a threaded process
can deadlock (Python 3.12 warns at every ``os.fork()`` there), and not multiprocessing's spawn,
which reruns the user's script in the child.

A job is a function and its arguments: a figure to render (:func:`.plotting.save`), or a run's
whole set of figures to draw and render (:func:`.figure_job.draw_chosen` of a picklable figure job
such as :class:`.figure_job.RobotFigures`), which spares the run importing matplotlib at all. Starting
the helper costs an interpreter and the import of matplotlib and the figure modules
(:data:`PRELOAD`, ~1 s of CPU), so a run starts it before it simulates (:func:`warm_up`; ``freefloat
simulate`` before its own imports) and the start overlaps them and the simulation. It ignores
Ctrl-C (the run decides) and ends when this process closes the pipe or ends (or
:func:`cool_down`, when there is nothing to draw after all).
"""

from __future__ import annotations

import atexit
import importlib
import pickle
import queue
import signal
import struct
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

#: Modules the helper imports as it starts, before its first job: the plotting stack and the
#: robot run's figures (Pinocchio, freefloat's robot and dynamics).
PRELOAD = ("matplotlib.backends.backend_agg", "freefloat.app.viz.figures")

_helper: subprocess.Popen | None = None
_HEADER = struct.Struct("<Q")
#: True in the helper process itself (its figures are rendered there, never sent on).
_in_helper = False


def _send(stream: BinaryIO, message: Any) -> None:
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(_HEADER.pack(len(data)) + data)
    stream.flush()


def _receive(stream: BinaryIO) -> Any:
    header = stream.read(_HEADER.size)
    if len(header) < _HEADER.size:
        raise EOFError("the figure helper closed its pipe")
    return pickle.loads(stream.read(_HEADER.unpack(header)[0]))


def warm_up() -> None:
    """Start the helper now (once per process), without waiting for it."""
    global _helper
    if _helper is None or _helper.poll() is not None:
        _helper = subprocess.Popen([sys.executable, "-m", __name__], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL)
        atexit.register(_stop, _helper)


def cool_down() -> None:
    """End the helper :func:`warm_up` started, before any job was sent to it (the command has
    nothing to draw after all); the next :func:`warm_up` starts another."""
    global _helper
    if _helper is not None:
        _stop(_helper)
        _helper = None


def in_helper() -> bool:
    """Whether this process is the figure helper."""
    return _in_helper


def _stop(helper: subprocess.Popen) -> None:
    """End ``helper`` and close its pipes (at this process's exit)."""
    helper.kill()
    helper.wait()
    helper.stdin.close()
    helper.stdout.close()


class Renderer:
    """Jobs ``save(*job)`` for the helper (started now if it is not): each job is pickled when
    sent, so a figure may change afterwards (the next figure of a run redraws the same one), and
    written to the helper's pipe from a thread, so this process goes on with its own share."""

    def __init__(self, save: Callable[..., list[Path]]):
        warm_up()
        self._helper, self._save = _helper, save
        self._queue: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()
        self._jobs: list[bytes] = []  # each job as pickled, in order
        self._written = 0
        self._feeder = threading.Thread(target=self._feed, daemon=True)
        self._feeder.start()

    def send(self, *job: Any, max_bytes: int | None = None) -> bool:
        """Queue ``save(*job)`` for the helper; False (nothing queued) when the job cannot be
        pickled (whatever a type's pickling raises: Boost.Python's refusal is a RuntimeError), or
        pickles to more than ``max_bytes`` (a copy in each process, and one kept here until
        collected)."""
        try:
            data = pickle.dumps((self._save, *job), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # the job is then drawn in this process
            return False
        if max_bytes is not None and len(data) > max_bytes:
            return False
        self._jobs.append(data)
        self._queue.put(data)
        return True

    def _feed(self) -> None:
        stream = self._helper.stdin
        while (data := self._queue.get()) is not None:
            try:
                stream.write(_HEADER.pack(len(data)) + data)
                stream.flush()
                self._written += 1
            except OSError:  # the helper is gone: what is not written is not awaited
                while self._queue.get() is not None:
                    pass
                return

    def close(self) -> None:
        """End the feeder of a renderer that sent nothing (the helper stays for others)."""
        self._queue.put(None)
        self._feeder.join()

    def abandon(self) -> None:
        """Stop waiting for the jobs sent: the helper is ended (its replies would otherwise be read
        by the next renderer) and the next :func:`warm_up` starts another."""
        self._helper.kill()
        self._helper.wait()
        self._queue.put(None)
        self._feeder.join()  # a write to the ended helper fails: the feeder drops the rest and returns
        _stop(self._helper)

    def collect(self) -> list[Any]:
        """Wait for the jobs sent; in order, the paths each wrote, or for a job the helper failed
        on (or lost) what this process wrote running the job as it was sent."""
        self._queue.put(None)
        self._feeder.join()  # the helper reads while it renders, so the last job is sent soon after its turn
        replies: list[Any] = []
        try:
            for _ in range(self._written):
                replies.append(_receive(self._helper.stdout))
        except (EOFError, OSError, pickle.UnpicklingError) as exc:
            replies += [exc] * (self._written - len(replies))
        replies += [RuntimeError("not sent to the figure helper")] * (len(self._jobs) - self._written)
        return [_run(data) if isinstance(reply, BaseException) else reply for data, reply in zip(self._jobs, replies)]


def _run(data: bytes) -> Any:
    """Run a pickled job ``(save, *job)`` here."""
    save, *job = pickle.loads(data)
    return save(*job)


def _serve() -> None:
    """The helper's loop: (function, *arguments) in, the function's result (or its exception) out."""
    global _in_helper
    _in_helper = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for module in PRELOAD:  # while the run simulates
        importlib.import_module(module)

    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    while True:
        try:
            save, *job = _receive(stdin)
        except EOFError:
            return
        try:
            reply: Any = save(*job)
        except Exception as exc:  # reported to the run, which renders the figure itself
            reply = exc
        _send(stdout, reply)


if __name__ == "__main__":
    # serve from the module as imported by name, so that the figure modules see in_helper() true
    importlib.import_module("freefloat.app.viz.rendering")._serve()
