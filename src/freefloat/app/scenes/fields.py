"""Checks shared by every scene schema: each value's type, range and choices, with errors that
name the scene file and the key."""

from __future__ import annotations

import dataclasses
import math
import pickle
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, field
from typing import Any, NamedTuple

from ... import inputs
from ...errors import InvalidArgument, SceneError, did_you_mean
from ...registry import use
from .. import figure_set
from ..figure_set import FigureChoice, FigureFormats  # noqa: F401  (the annotations parse_section reads)

#: Largest size of any number in a scene (SI units: nothing physical a scene sets comes near it;
#: beyond it float arithmetic overflows).
MAX_MAGNITUDE = 1e15
#: Frames per second of simulated time a page may show (a page holds duration * fps frames).
MAX_HTML_FPS = 1000.0


@dataclass(frozen=True)
class OutputSection:
    """``[output]``: which artefacts a run writes; ``figures`` and ``figure_formats`` as
    :mod:`freefloat.app.figure_set` says."""

    figures: FigureChoice = True
    figure_formats: FigureFormats = ("png",)
    html: bool = True
    html_fps: float = 30.0


class Rules(NamedTuple):
    """Value rules of one scene kind, keyed by ``(section, key)`` (section ``""``: top level):
    the allowed strings (or a function giving them, read when a scene is checked: a registry's
    names, so that what is registered later is accepted), and the numbers that must be > 0 or >= 0."""

    choices: dict[tuple[str, str], tuple[str, ...] | Callable[[], tuple[str, ...]]]
    positive: set[tuple[str, str]]
    non_negative: set[tuple[str, str]]


class PluginsFirst:
    """A scene that pickles with its ``plugins`` (paths or module names) imported first on the
    other side: a spawned worker that unpickles it has not imported them, and the settings of
    their entries are their classes."""

    plugins: tuple[str, ...]

    def __reduce_ex__(self, protocol: Any) -> Any:
        if not self.plugins:
            return super().__reduce_ex__(protocol)
        state = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return _plugins_first, (self.plugins, type(self), pickle.dumps(state, protocol))


def _plugins_first(plugins: tuple[str, ...], cls: type, state: bytes) -> Any:
    """A pickled :class:`PluginsFirst` scene, rebuilt after importing its plug-ins."""
    for plugin in plugins:
        use(plugin)
    return cls(**pickle.loads(state))


#: No value rules (an entry whose settings need no choices nor ranges).
NO_RULES = Rules({}, set(), set())


@dataclass(frozen=True)
class EntrySection:
    """A section that names a registered entry (``[controller]``, ``[[environment]]``): its ``kind``
    and the entry's ``settings`` (an instance of the entry's settings dataclass, from the section's
    other keys). The settings read as the section's own attributes (``scene.controller.kp``)."""

    kind: str
    settings: Any = field(default=None)

    def with_settings(self, kind: str | None = None, **changes: Any) -> EntrySection:
        """This section with another ``kind`` (its entry taking the same settings) and ``changes``
        to the settings (``dataclasses.replace`` on them)."""
        return EntrySection(self.kind if kind is None else kind, dataclasses.replace(self.settings, **changes))

    def __getattr__(self, key: str) -> Any:
        if key.startswith("__") or key == "settings":  # copy and pickle probe dunders before settings is set
            raise AttributeError(key)
        return getattr(self.settings, key)


def check_settings(family: str, name: str, settings: Any) -> None:
    """An entry's ``settings``: a dataclass whose fields are its scene keys, none called ``kind``.

    Raises:
        InvalidArgument: naming the entry, when it is not.
    """
    if not (isinstance(settings, type) and dataclasses.is_dataclass(settings)):
        raise InvalidArgument(f"{family} '{name}': settings must be a dataclass (its fields are the scene keys), got "
                              f"{settings!r}")
    if "kind" in settings.__dataclass_fields__:
        raise InvalidArgument(f"{family} '{name}': settings {settings.__name__} has a field 'kind', the key that "
                              "names the entry; rename it")


def parse_entry(where: str, section: str, raw: Any, entries: Mapping[str, Any], default: str | None,
                rules: Rules, label: str = "valid") -> EntrySection:
    """A table naming one of ``entries`` (specs with ``settings`` and ``rules``) by ``kind``
    (``default`` when absent; None: required), its other keys checked as that entry's settings
    (unknown key, type, the entry's ``rules`` with ``rules``).

    Raises:
        SceneError: naming ``section.kind`` with the nearest of ``entries`` ("did you mean"), or
            the key of the settings that is wrong.
    """
    if not isinstance(raw, dict):
        raise SceneError(f"{where}[{section}] must be a table, got {type(raw).__name__}")
    if "kind" not in raw and default is None:
        raise SceneError(f"{where}[{section}] needs key 'kind'{did_you_mean('', entries, label)}")
    kind = typed(where, f"{section}.kind", raw.get("kind", default), str)
    if kind not in entries:
        raise SceneError(f"{where}'{section}.kind' is {kind!r}{did_you_mean(kind, entries, label)}")
    entry = entries[kind]
    own = entry.rules
    merged = Rules({**rules.choices, **own.choices}, rules.positive | own.positive, rules.non_negative | own.non_negative)
    settings = parse_section(where, section, entry.settings, {k: v for k, v in raw.items() if k != "kind"}, merged)
    return EntrySection(kind, settings)


def parse_section(where: str, section: str, cls: type, raw: Any, rules: Rules) -> Any:
    """A section's dataclass from its table; how each value is checked follows the field's type
    annotation (and ``rules``)."""
    if not isinstance(raw, dict):
        raise SceneError(f"{where}[{section}] must be a table, got {type(raw).__name__}")
    fields_ = cls.__dataclass_fields__
    reject_unknown(where, section, raw, set(fields_))
    missing = [k for k, f in fields_.items() if f.default is MISSING
               and f.default_factory is MISSING and k not in raw]
    if missing:
        raise SceneError(f"{where}[{section}] needs key '{missing[0]}'")
    values = {}
    for key, value in raw.items():
        kind, name = annotation(fields_[key].type), f"{section}.{key}"
        if kind == "str":
            values[key] = choice(where, section, key, typed(where, name, value, str), rules)
        elif kind == "bool":
            values[key] = typed(where, name, value, bool)
        elif kind in ("int", "float", "float | None"):
            values[key] = number(where, section, key, value, int if kind == "int" else float, rules)
        elif kind == "tuple[str, ...] | None":
            values[key] = names(where, name, value)
        elif kind == "FigureChoice":
            values[key] = figure_set.check_choice(value, f"{where}'{name}'", SceneError)
        elif kind == "FigureFormats":
            values[key] = figure_set.check_formats(value, f"{where}'{name}'", SceneError)
        elif kind == "tuple[float, float, float]":
            values[key] = vector(where, name, value, 3)
        elif kind in ("tuple[float, ...]", "tuple[float, ...] | None"):
            values[key] = vector(where, name, value, None)
        elif kind == "tuple[int, int]":
            values[key] = indices(where, name, value, 2)
        elif kind == "tuple[tuple[float, ...], ...] | None":
            values[key] = matrix(where, name, value)
        elif kind == "dict[str, tuple[float, ...]]":
            values[key] = {k: vector(where, f"{name}.{k}", v, None)
                           for k, v in typed(where, name, value, dict).items()}
        else:
            values[key] = table(where, name, value)
    try:
        return cls(**values)
    except InvalidArgument as exc:  # a check across keys, in the settings' constructor
        raise SceneError(f"{where}[{section}] {exc}") from exc


def annotation(kind: Any) -> str:
    """A field's type annotation as text (``"float | None"``): a string already under ``from
    __future__ import annotations``, else the type's own spelling (a plug-in's settings)."""
    if isinstance(kind, str):
        return kind
    return kind.__name__ if isinstance(kind, type) else str(kind)


def reject_unknown(where: str, section: str, raw: dict, allowed: set[str]) -> None:
    """A key of ``raw`` not in ``allowed`` refused (see :func:`freefloat.inputs.reject_unknown`)."""
    inputs.reject_unknown(where, raw, allowed, section, SceneError)


def typed(where: str, key: str, value: Any, kind: type) -> Any:
    if not isinstance(value, kind):
        raise SceneError(f"{where}'{key}' must be a {kind.__name__}, got {value!r}")
    return value


def number(where: str, section: str, key: str, value: Any, kind: type, rules: Rules) -> float | int:
    name = f"{section}.{key}"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (
        kind is int and not isinstance(value, int)
    ):
        raise SceneError(f"{where}'{name}' must be a{'n integer' if kind is int else ' number'}, got {value!r}")
    if not math.isfinite(value) or abs(value) > MAX_MAGNITUDE:
        raise SceneError(f"{where}'{name}' must be finite and at most {MAX_MAGNITUDE:g} in size, got {value!r}")
    if (section, key) in rules.positive and value <= 0:
        raise SceneError(f"{where}'{name}' must be > 0, got {value!r}")
    if (section, key) in rules.non_negative and value < 0:
        raise SceneError(f"{where}'{name}' must be >= 0, got {value!r}")
    return kind(value)


def choice(where: str, section: str, key: str, value: Any, rules: Rules) -> str:
    options = rules.choices.get((section, key))
    options = options() if callable(options) else options
    if options is not None and value not in options:
        name = f"{section}.{key}" if section else key
        raise SceneError(f"{where}'{name}' is {value!r}{did_you_mean(value, options)}")
    return value


def names(where: str, key: str, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
        raise SceneError(f"{where}'{key}' must be a list of names, got {value!r}")
    return tuple(value)


def vector(where: str, key: str, value: Any, size: int | None) -> tuple[float, ...]:
    """A list of finite numbers, of length ``size`` (None: any length but empty)."""
    if (not isinstance(value, list) or len(value) != (size or len(value)) or not value
            or not all(is_finite(x) for x in value)):
        raise SceneError(f"{where}'{key}' must be a list of {size or 'one or more'} finite numbers, got {value!r}")
    return tuple(float(x) for x in value)


def matrix(where: str, key: str, value: Any) -> tuple[tuple[float, ...], ...]:
    """A list of equally long rows of finite numbers."""
    rows = [vector(where, key, row, None) for row in typed(where, key, value, list)]
    if not rows or len({len(r) for r in rows}) != 1:
        raise SceneError(f"{where}'{key}' must be a list of equally long rows of numbers, got {value!r}")
    return tuple(rows)


def indices(where: str, key: str, value: Any, size: int) -> tuple[int, ...]:
    """A list of ``size`` distinct non-negative integers."""
    if (not isinstance(value, list) or len(value) != size or len(set(value)) != size
            or not all(isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in value)):
        raise SceneError(f"{where}'{key}' must be a list of {size} distinct integers >= 0, got {value!r}")
    return tuple(value)


def is_finite(x: Any) -> bool:
    """A number (not a bool), finite and at most :data:`MAX_MAGNITUDE` in size."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and abs(x) <= MAX_MAGNITUDE


def table(where: str, key: str, value: Any) -> dict[str, float]:
    if not isinstance(value, dict) or not all(is_finite(x) for x in value.values()):
        raise SceneError(f"{where}'{key}' must be a table of finite numbers keyed by name, got {value!r}")
    return {k: float(x) for k, x in value.items()}


def whole_number_of(where: str, duration: float, period: float, duration_key: str, period_key: str) -> None:
    """``duration`` is a whole number of ``period`` s.

    Raises:
        SceneError: naming both keys, with the nearest whole numbers.
    """
    steps = duration / period
    if abs(steps - round(steps)) > 1e-9 * max(1.0, steps) or round(steps) < 1:
        raise SceneError(f"{where}'{duration_key}' ({duration} s) must be a whole number of '{period_key}' "
                         f"({period} s); e.g. {max(1, round(steps)) * period:.12g} s")


def at_most(where: str, value: float, limit: float, key: str) -> None:
    """``value`` <= ``limit``.

    Raises:
        SceneError: naming the key and the limit.
    """
    if value > limit:
        raise SceneError(f"{where}'{key}' is {value!r}; at most {limit:g}")
