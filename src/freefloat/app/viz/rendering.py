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


def render_each(save: Callable[[Figure, Path, str], list[Path]],
                jobs: list[tuple[Figure, Path, str]]) -> Callable[[], list[Any]]:
    """Start ``save(*job)`` for each job in the helper (started now if it is not); returns the
    call that waits for them: in order, the paths each wrote or the exception it raised there
    (also when the helper is lost). The figures are pickled and sent from a thread, so this
    process goes on with its own share meanwhile."""
    warm_up()
    helper = _helper

    sent = [0]

    def feed() -> None:
        try:
            for job in jobs:
                _send(helper.stdin, (save, *job))
                sent[0] += 1
        except (OSError, pickle.PicklingError, TypeError, AttributeError):
            pass  # a job that cannot be sent (the helper gone, a figure that cannot be pickled) is not awaited

    feeder = threading.Thread(target=feed, daemon=True)
    feeder.start()

    def collect() -> list[Any]:
        feeder.join()  # the helper reads while it renders, so the last job is sent soon after its turn
        replies: list[Any] = []
        try:
            for _ in range(sent[0]):
                replies.append(_receive(helper.stdout))
        except (EOFError, OSError, pickle.UnpicklingError) as exc:
            replies += [exc] * (sent[0] - len(replies))
        return replies + [RuntimeError("not sent to the figure helper")] * (len(jobs) - sent[0])

    return collect


def _serve() -> None:
    """The helper's loop: (save, figure, folder, stem) in, save's paths (or its exception) out."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import matplotlib.backends.backend_agg  # noqa: F401  (what unpickling and saving a figure need)

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
