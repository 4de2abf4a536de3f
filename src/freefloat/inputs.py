"""Reading the files a user hands freefloat (scenes, closure files, mechanism data): TOML read
with errors that name the file, and strict keys, so that a misspelt key is refused with the list
of valid ones instead of being silently ignored; and TOML written back (a scene as it ran)."""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from .errors import FreefloatError, did_you_mean


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
        error: naming the key, the closest valid keys if any are close, and the valid keys
            (:func:`~freefloat.errors.did_you_mean`).
    """
    allowed = sorted(allowed)
    for key in table:
        if key not in allowed:
            name = f"[{section}] key '{key}'" if section else f"top-level key '{key}'"
            raise error(f"{where}unknown {name}{did_you_mean(key, allowed, 'allowed')}")


def toml_text(table: dict[str, Any]) -> str:
    """``table`` as TOML that :func:`tomllib.loads` reads back equal: its plain values first, then
    each dict value as a ``[section]`` (dicts inside a section inline) and each list of dicts as
    ``[[section]]`` entries. None values are left out (TOML has no null: the key's default)."""
    plain = {k: v for k, v in table.items() if not _is_table(v) and not _is_table_list(v) and v is not None}
    lines = [f"{_key(k)} = {_value(v)}" for k, v in plain.items()]
    for name, value in table.items():
        if _is_table(value):
            lines += ["", f"[{_key(name)}]", *(f"{_key(k)} = {_value(v)}" for k, v in value.items() if v is not None)]
        elif _is_table_list(value):
            for entry in value:
                lines += ["", f"[[{_key(name)}]]", *(f"{_key(k)} = {_value(v)}" for k, v in entry.items()
                                                     if v is not None)]
    return "\n".join(lines) + "\n"


def _is_table(value: Any) -> bool:
    return isinstance(value, dict)


def _is_table_list(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and len(value) > 0 and all(isinstance(v, dict) for v in value)


def _key(key: str) -> str:
    bare = key.replace("_", "").replace("-", "").isalnum() and key.isascii()
    return key if bare else _value(key)


def _value(value: Any) -> str:
    """One TOML value: strings as JSON-style basic strings, floats exactly (repr; inf, nan),
    arrays, and dicts as inline tables."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("nan" if math.isnan(value) else ("inf" if value > 0 else "-inf"))
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")  # TOML escapes DEL too
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        items = ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items() if v is not None)
        return "{ " + items + " }" if items else "{}"
    raise TypeError(f"no TOML form for {type(value).__name__} {value!r}")
