"""A study's journal read back for a resume (``models``: ``parts.jsonl``, ``robustness``:
``samples.jsonl``): one JSON object per line, appended as each part finishes.

The file is data anyone could have edited, so it is checked before a line is used: every line
must be a JSON object (the last one may be cut short by a kill, and is then dropped), and every
entry written with the settings of this run must have the fields the study reads back. Anything
else is refused, naming the file and the line, never read as a result.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ...app.run_folder import journal_entries
from ...errors import RunFolderError


def entries(path: Path, settings: dict, problem: Callable[[dict], str | None]) -> list[dict]:
    """The entries of the journal ``path`` written with ``settings`` (each without its
    ``settings``), in order; ``problem(entry)`` says what is wrong with an entry (None: nothing).

    Raises:
        RunFolderError: naming the file, the line and the problem for a line that is not a JSON
            object (:func:`~freefloat.app.run_folder.journal_entries`) or an entry of these
            settings that ``problem`` refuses.
    """
    again = "move the file away, or pass --overwrite to start the study again"
    found = []
    for number, entry in journal_entries(path, again):
        if entry.get("settings") == settings:
            entry = {k: v for k, v in entry.items() if k != "settings"}
            if (wrong := problem(entry)) is not None:
                raise RunFolderError(f"'{path}' line {number} {wrong}; not resuming from it ({again})")
            found.append(entry)
    return found
