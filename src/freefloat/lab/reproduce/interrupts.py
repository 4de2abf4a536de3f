"""A study stops when its user stops it. The simulation loops catch Ctrl-C (and SIGTERM, SIGHUP
under the command line) and return an ``"interrupted"`` run, so that ``freefloat simulate`` keeps
the rows it has; a study that went on with such a run would count it as a result (a bisection as
an unstable step) and run everything after it. Each study passes its runs through
:func:`finished`."""

from __future__ import annotations

from typing import TypeVar

R = TypeVar("R")


def finished(result: R) -> R:
    """``result`` (anything with a ``status``: a ``RunResult`` or an ``Outcome``) when its run was
    not interrupted.

    Raises:
        KeyboardInterrupt: when the run's status is ``"interrupted"``.
    """
    if getattr(result, "status", None) == "interrupted":
        raise KeyboardInterrupt(getattr(result, "message", "") or "interrupted")
    return result
