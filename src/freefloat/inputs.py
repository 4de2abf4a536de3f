"""Reading the files a user hands freefloat (scenes, closure files, mechanism data): TOML read
with errors that name the file, and strict keys, so that a misspelt key is refused with the list
of valid ones instead of being silently ignored."""

from __future__ import annotations

import difflib
import tomllib
from pathlib import Path
from typing import Any, Iterable

from .errors import FreefloatError


def read_toml(path: Path, what: str, error: type[FreefloatError] = FreefloatError) -> dict[str, Any]:
    """The parsed TOML file ``path`` (a ``what``, named in errors).

    Raises:
        error: naming the file when it is missing, unreadable, not UTF-8, not TOML, or nested too
            deeply to parse.
    """
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML ({exc})") from None
    except RecursionError:
        raise error(f"{path}: nested too deeply to be a {what}") from None


def reject_unknown(where: str, table: dict[str, Any], allowed: Iterable[str], section: str = "",
                   error: type[FreefloatError] = FreefloatError) -> None:
    """Refuse a key of ``table`` that is not in ``allowed``.

    Args:
        where: the file, as the message's prefix (``"scene.toml: "``).
        section: the table's name (``"platform"``, ``"closures[0]"``), empty for the top level.

    Raises:
        error: naming the key, the closest valid key if one is close, and every valid key.
    """
    allowed = sorted(allowed)
    for key in table:
        if key not in allowed:
            name = f"[{section}] key '{key}'" if section else f"top-level key '{key}'"
            close = difflib.get_close_matches(str(key), allowed, n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise error(f"{where}unknown {name}{hint}; allowed: {', '.join(allowed)}")
