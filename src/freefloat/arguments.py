"""Checks of the numbers handed to freefloat's public functions: one place that refuses a value of
the wrong type, shape or size, not finite, or absurdly large, with
:class:`~freefloat.errors.InvalidArgument` naming the argument (instead of numpy's or Pinocchio's
message, a ``TypeError`` from a comparison, or a NaN further on). The same bound as scene files:
a magnitude of at most :data:`MAX_MAGNITUDE`.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

from .errors import BadShape, InvalidArgument

#: Largest magnitude of a number freefloat takes (as in scene files).
MAX_MAGNITUDE = 1e15


def reals(name: str, value: Any) -> np.ndarray:
    """``value`` as a float array, refused unless it holds real numbers.

    Raises:
        InvalidArgument: naming ``name`` for strings, None, complex numbers, objects or a ragged
            nesting.
    """
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise InvalidArgument(f"'{name}' must be an array of real numbers: {exc}") from None
    if array.dtype.kind not in "biuf":
        raise InvalidArgument(f"'{name}' must hold real numbers, got {_kind(array)}")
    return array.astype(float, copy=False)


def bounded(name: str, array: np.ndarray) -> np.ndarray:
    """``array`` (finite), refused when a magnitude exceeds :data:`MAX_MAGNITUDE`.

    Raises:
        InvalidArgument: naming ``name`` and the largest magnitude.
    """
    if array.size and np.abs(array).max() > MAX_MAGNITUDE:
        raise InvalidArgument(f"'{name}' must be at most {MAX_MAGNITUDE:g} in size, got {np.abs(array).max():.3g}")
    return array


def real_array(name: str, value: Any, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """``value`` as a float array, checked: real numbers (:func:`reals`), of ``shape`` when
    given, finite, at most :data:`MAX_MAGNITUDE` in size (:func:`bounded`).

    Raises:
        BadShape: when ``shape`` is given and ``value`` has another.
        InvalidArgument: naming ``name`` for anything else.
    """
    array = reals(name, value)
    if shape is not None and array.shape != shape:
        raise BadShape(f"'{name}' must have shape {shape}, got {array.shape}")
    if not np.isfinite(array).all():
        raise InvalidArgument(f"'{name}' must be finite; entries {np.flatnonzero(~np.isfinite(array)).tolist()[:10]} "
                              "are not")
    return bounded(name, array)


def real_number(name: str, value: Any, low: float | None = None, high: float | None = None,
                above: float | None = None) -> float:
    """``value`` as a float, checked: finite, within ``[low, high]`` (and ``> above``) when given,
    at most :data:`MAX_MAGNITUDE` in size.

    Raises:
        InvalidArgument: naming ``name`` and the range.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidArgument(f"'{name}' must be a real number, got {value!r}")
    number = float(value)
    if not math.isfinite(number) or abs(number) > MAX_MAGNITUDE:
        raise InvalidArgument(f"'{name}' must be finite and at most {MAX_MAGNITUDE:g} in size, got {value!r}")
    if (low is not None and number < low) or (high is not None and number > high) or \
            (above is not None and not number > above):
        bounds = [f"> {above:g}"] if above is not None else []
        bounds += [f">= {low:g}"] if low is not None else []
        bounds += [f"<= {high:g}"] if high is not None else []
        raise InvalidArgument(f"'{name}' must be {' and '.join(bounds)}, got {value!r}")
    return number


def whole_number(name: str, value: Any, low: int = 1, high: int | None = None) -> int:
    """``value`` as an int within ``[low, high]``.

    Raises:
        InvalidArgument: naming ``name`` when it is not an integer (a bool or float neither) or
            out of range.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InvalidArgument(f"'{name}' must be an integer, got {value!r}")
    if value < low or (high is not None and value > high):
        raise InvalidArgument(f"'{name}' must be from {low} to {high}, got {value}" if high is not None else
                              f"'{name}' must be >= {low}, got {value}")
    return int(value)


def an_object(name: str, value: Any, what: str, kinds: tuple[type, ...] = (), methods: tuple[str, ...] = ()) -> Any:
    """``value``, refused unless it is one of ``kinds`` or has every one of ``methods`` (an object
    where freefloat takes one: a robot, a model, an integrator, a controller, a path).

    Args:
        what: what is expected, for the message (``"a Robot (freefloat.load_robot)"``).

    Raises:
        InvalidArgument: naming ``name``, what it takes and the type given.
    """
    if (kinds and isinstance(value, kinds)) or (methods and all(callable(getattr(value, m, None)) for m in methods)):
        return value
    given = repr(value) if isinstance(value, (str, numbers.Number)) or value is None else f"a {type(value).__name__}"
    raise InvalidArgument(f"'{name}' takes {what}, got {given}")


def _kind(array: np.ndarray) -> str:
    """What an array of the wrong kind holds, for a message."""
    return {"c": "complex numbers", "U": "strings", "S": "bytes", "O": "objects"}.get(array.dtype.kind,
                                                                                     str(array.dtype))
