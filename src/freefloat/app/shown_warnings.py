"""Warnings as the command line shows them: one line each (``freefloat: warning: ...``, a
:class:`~freefloat.errors.FreefloatNote` as ``freefloat: note: ...``), each once per process
whichever command, run or load met it, and held back until the command is past its checks, so
that a command refused for bad input prints its error alone (a warning about the robot explains
nothing about a folder already in use or a mistyped key).
"""

from __future__ import annotations

import contextlib
import sys
import warnings
from collections.abc import Iterator

from ..errors import FreefloatNote

#: The warnings this process has shown (their text): each is shown once.
SHOWN: set[str] = set()


class HeldWarnings:
    """The warnings a command met so far, printed by :meth:`release` (from then on each is printed
    as it comes)."""

    def __init__(self) -> None:
        self.held: dict[str, str] = {}  # text -> its line
        self.released = False

    def take(self, message: Warning | str, category: type[Warning]) -> None:
        """Hold (or, once released, print) one warning, unless this process showed it already."""
        text = str(message)
        if text in SHOWN or text in self.held:
            return
        self.held[text] = f"freefloat: {'note' if issubclass(category, FreefloatNote) else 'warning'}: {text}"
        if self.released:
            self.release()

    def release(self) -> None:
        """The command is past its checks: print what was held, and every later warning as it comes."""
        self.released = True
        for text, line in self.held.items():
            SHOWN.add(text)
            _print(line)
        self.held.clear()


def _print(line: str) -> None:
    """One line on stderr, above a progress bar if one is showing."""
    from tqdm import tqdm

    tqdm.write(line, file=sys.stderr)


@contextlib.contextmanager
def shown_warnings() -> Iterator[HeldWarnings]:
    """Within the block, warnings are held (see the module docstring) and printed when the caller
    calls ``release()`` (the command is past its checks: its run has started) or the block ends
    without an error; an error or an interrupt before then drops them."""
    held = HeldWarnings()
    with warnings.catch_warnings():  # restores showwarning too
        warnings.simplefilter("default")
        warnings.showwarning = lambda message, category, *args, **kwargs: held.take(message, category)
        yield held
        held.release()
