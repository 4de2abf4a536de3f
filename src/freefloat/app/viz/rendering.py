"""A helper process that renders figures while this one renders others. It is a new
interpreter (``python -m freefloat.app.viz.rendering``) fed pickled figures through a pipe:
never a fork, since this process has threads (BLAS, progress bars) and a fork of a threaded
process can deadlock (Python 3.12 warns at every ``os.fork()`` there), and not
multiprocessing's spawn, which reruns the user's script in the child.

Starting it costs an interpreter and matplotlib's import (~1 s), so a run starts it before it
simulates (:func:`warm_up`) and the start overlaps the simulation. It ignores Ctrl-C (the run
decides) and ends when this process closes the pipe or ends.
"""

from __future__ import annotations

import atexit
import pickle
import queue
import signal
import struct
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

if TYPE_CHECKING:
    from matplotlib.figure import Figure

_helper: subprocess.Popen | None = None
_HEADER = struct.Struct("<Q")


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

    def send(self, *job: Any) -> bool:
        """Queue ``save(*job)`` for the helper; False (nothing queued) when the job cannot be
        pickled."""
        try:
            data = pickle.dumps((self._save, *job), protocol=pickle.HIGHEST_PROTOCOL)
        except (pickle.PicklingError, TypeError, AttributeError):
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
    """The helper's loop: (save, figure, folder, stem) in, save's paths (or its exception) out."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # warm up while the run simulates; unpickling the first job imports the plotting module itself
    import matplotlib.backends.backend_agg  # noqa: F401

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
    _serve()
