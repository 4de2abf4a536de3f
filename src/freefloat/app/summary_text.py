"""Summary values as the command line prints them: numbers to :data:`DIGITS` significant digits
followed by the key's unit (an experiment kind's ``units``, from the modules that compute the
keys); ``summary.json`` keeps every digit."""

from __future__ import annotations

from typing import Any

#: Significant digits of a number on the terminal.
DIGITS = 4


def shown(value: Any, unit: str = "") -> str:
    """``value`` (a number, a vector, a table keyed by name, a text, a flag, or None) as one
    terminal line's worth of text, with ``unit`` after a number, a vector or a table of numbers:
    ``7.543e-08 rad``, ``[-0.2185, -0.2185, 0] m``, ``{wheel_x: 0.06286, wheel_y: 0.8199} N m s``."""
    text = _plain(value)
    numeric = not isinstance(value, (str, bool)) and value is not None
    return f"{text} {unit}" if unit and numeric else text


def _plain(value: Any) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.{DIGITS}g}"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_plain(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_plain(v) for v in value) + "]"
    return str(value)
