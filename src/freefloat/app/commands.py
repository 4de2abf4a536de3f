"""The commands a plug-in adds to ``freefloat`` (the lab's ``bench`` and ``reproduce``, a user's
own): one registry, :data:`COMMANDS`, which the command line reads after its built-in commands."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass

from ..registry import Registry


@dataclass(frozen=True)
class Command:
    """A subcommand of ``freefloat``.

    Attributes:
        name: ``freefloat NAME``.
        help: one line for ``freefloat --help``.
        arguments: adds the command's arguments to its parser (called when ``freefloat`` builds it).
        run: runs the command from its parsed arguments; returns the exit status (0 ok, 1 stopped
            early); a :class:`~freefloat.errors.FreefloatError` is printed as bad input (status 2).
        heavy: a module to import first, while Ctrl-C is deferred (its libraries may swallow one).
    """

    name: str
    help: str
    arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    heavy: str | None = None


#: The commands plug-ins added, in registration order.
COMMANDS: Registry[Command] = Registry("command")
