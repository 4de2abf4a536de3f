"""Names a package exports but imports on first use (PEP 562), so that importing the package,
or a light module inside it, loads none of its heavy modules."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping


def lazy_exports(package: str, names: Mapping[str, str | tuple[str, str]], into: dict) -> Callable[[str], object]:
    """A module ``__getattr__`` for ``package``: name -> its module (or ``(module, attribute)``),
    imported on first use and then kept in ``into`` (the package's ``globals()``)."""

    def __getattr__(name: str) -> object:
        where = names.get(name)
        if where is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attribute = where if isinstance(where, tuple) else (where, name)
        value = getattr(importlib.import_module(module, package), attribute)
        into[name] = value
        return value

    return __getattr__
