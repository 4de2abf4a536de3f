"""Names a package exports but imports on first use (PEP 562), so that importing the package,
or a light module inside it, loads none of its heavy modules; and its modules reachable as
attributes, imported on first use too (``freefloat.gjm.compute`` after ``import freefloat``)."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from types import ModuleType


def lazy_modules(package: str) -> Callable[[str], ModuleType]:
    """A module ``__getattr__`` for ``package``: its submodule ``name`` (``package.name``),
    imported on first use (the import binds it in the package).

    Raises:
        AttributeError: naming ``name`` when ``package`` has no such submodule.
    """

    def __getattr__(name: str) -> ModuleType:
        import importlib.util  # here: importing it costs the package's start-up a millisecond

        if not name.startswith("__") and importlib.util.find_spec(f"{package}.{name}") is not None:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


def lazy_exports(package: str, names: Mapping[str, str | tuple[str, str]], into: dict) -> Callable[[str], object]:
    """A module ``__getattr__`` for ``package``: name -> its module (or ``(module, attribute)``),
    imported on first use and then kept in ``into`` (the package's ``globals()``); any other name
    is a submodule (:func:`lazy_modules`)."""
    module_of = lazy_modules(package)

    def __getattr__(name: str) -> object:
        where = names.get(name)
        if where is None:
            return module_of(name)
        module, attribute = where if isinstance(where, tuple) else (where, name)
        value = getattr(importlib.import_module(module, package), attribute)
        into[name] = value
        return value

    return __getattr__
