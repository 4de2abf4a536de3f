"""The lab's plug-in (entry point ``lab`` of group ``freefloat.plugins`` in pyproject.toml): the
commands ``freefloat reproduce`` and ``freefloat bench``, registered into the command line's
:data:`~freefloat.app.commands.COMMANDS`. Importing it loads only the two commands' modules."""

from __future__ import annotations

from ..app.commands import COMMANDS
from .bench.command import BENCH
from .reproduce.command import REPRODUCE

COMMANDS.register(REPRODUCE)
COMMANDS.register(BENCH)
