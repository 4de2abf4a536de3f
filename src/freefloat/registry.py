"""Registries: every family of named things (integrators, dynamics models, controllers, bench
suites, commands, ...) is one :class:`Registry`, and the plug-ins that add to them.

A registry maps a name to an entry, an object that carries its own ``name`` (a spec record, a
class): ``register`` adds one, ``get`` (or ``registry[name]``) finds it or raises
:class:`~freefloat.errors.UnknownName` with the nearest names, ``names()`` lists them in the order
they were registered, and a registry reads like a mapping (``in``, ``len``, iteration,
``items()``; ``registry[name] = entry`` and ``del registry[name]`` for a test's toy).

A module outside freefloat extends a family by registering into it, either when the user imports
it (:func:`use`: a file or a module) or through an entry point of group :data:`GROUP` declared by
an installed package::

    [project.entry-points."freefloat.plugins"]
    my_laws = "my_package.freefloat_plugin"

Every lookup first imports those entry points, once per process (:func:`load_plugins`); a
plug-in that fails to import raises :class:`~freefloat.errors.PluginError` naming it.

Base layer: imports nothing of freefloat but its errors.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import threading
from collections.abc import Callable, Iterator, Mapping
from importlib import metadata
from pathlib import Path
from types import ModuleType
from typing import Any, Generic, TypeVar, overload

from .errors import InvalidArgument, PluginError, UnknownName

#: The entry-point group whose modules are imported before any registry lookup.
GROUP = "freefloat.plugins"

Entry = TypeVar("Entry")
#: What ``get`` returns when the name is missing and no default is given (a sentinel).
_NO_DEFAULT: Any = object()


class Registry(Mapping[str, Entry], Generic[Entry]):
    """The entries of one family by name, in registration order.

    Args:
        family: what an entry is, for messages (``"integrator"``, ``"bench suite"``, ...).
        builtins: the module (dotted name) whose import registers the built-in entries, imported
            on the first lookup when the registry is defined below it (the scenes' experiment
            kinds: a scene's kind is asked before anything imported the experiments).
    """

    def __init__(self, family: str, builtins: str | None = None) -> None:
        self.family = family
        self._entries: dict[str, Entry] = {}
        self._builtins = builtins

    @overload
    def register(self, entry: Entry, *, replace: bool = False) -> Entry: ...

    @overload
    def register(self, entry: None = None, *, replace: bool = False) -> Callable[[Entry], Entry]: ...

    def register(self, entry: Entry | None = None, *, replace: bool = False) -> Any:
        """Add ``entry`` under its ``name``; return it (so it decorates a class with a ``name``
        attribute: ``@REGISTRY.register``, or ``@REGISTRY.register(replace=True)``).

        Raises:
            InvalidArgument: an entry without a non-empty string ``name``, or a name already taken
                and ``replace`` not set.
        """
        if entry is None:
            return lambda chosen: self.register(chosen, replace=replace)
        name = getattr(entry, "name", None)
        if not isinstance(name, str) or not name:
            raise InvalidArgument(f"a {self.family} needs a non-empty string `name` to be registered, got "
                                  f"{type(entry).__name__} with name {name!r}")
        if name in self._entries and not replace:
            raise InvalidArgument(f"{self.family} '{name}' is already registered; register(..., replace=True) "
                                  "replaces it")
        self._entries[name] = entry
        return entry

    def get(self, name: str, default: Any = _NO_DEFAULT) -> Entry:  # type: ignore[override]
        """The entry called ``name`` (``default`` if given and there is none).

        Raises:
            UnknownName: no such entry and no default; the message gives the nearest names.
        """
        self._load()
        if name in self._entries:
            return self._entries[name]
        if default is not _NO_DEFAULT:
            return default
        raise UnknownName(self.family, name, self._entries)

    def names(self) -> tuple[str, ...]:
        """Every name, in registration order."""
        self._load()
        return tuple(self._entries)

    def __getitem__(self, name: str) -> Entry:
        return self.get(name)

    def __setitem__(self, name: str, entry: Entry) -> None:
        """``registry[name] = entry``: register ``entry``, replacing the one of that name (a test's
        toy, through ``monkeypatch.setitem``); ``name`` must be the entry's.

        Raises:
            InvalidArgument: ``name`` is not ``entry.name``.
        """
        if getattr(entry, "name", None) != name:
            raise InvalidArgument(f"a {self.family} is registered under its own name, not {name!r}")
        self.register(entry, replace=True)

    def __delitem__(self, name: str) -> None:
        """``del registry[name]``: remove the entry (what ``monkeypatch.setitem`` undoes)."""
        del self._entries[self.get(name).name]

    def __contains__(self, name: object) -> bool:
        self._load()
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self.names())

    def _load(self) -> None:
        """The plug-ins (:func:`load_plugins`) and, the first time, the :attr:`_builtins` module
        (a lookup made while it is imported sees the entries registered so far)."""
        load_plugins()
        if self._builtins is not None:
            module, self._builtins = self._builtins, None
            importlib.import_module(module)

    def __repr__(self) -> str:
        return f"Registry({self.family!r}: {', '.join(self._entries)})"


class _Loader:
    """The plug-ins of this process: imported on the first lookup, once (a second thread waits
    for the first; a lookup made while a plug-in is imported, in the same thread, sees the
    entries registered so far). A failure is raised again at every later lookup."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.done = False
        self.started = False
        self.failure: PluginError | None = None

    def load(self) -> None:
        if self.done:
            return
        with self.lock:
            if self.failure is not None:
                raise self.failure
            if self.started:  # finished meanwhile, or this thread is importing a plug-in
                return
            self.started = True
            for point in metadata.entry_points(group=GROUP):
                try:
                    point.load()
                except Exception as exc:  # any error of a plug-in is reported as its own
                    self.failure = PluginError(f"plug-in '{point.name}' ({point.value}, entry point of group "
                                               f"{GROUP}) failed to import: {type(exc).__name__}: {exc}")
                    raise self.failure from exc
            self.done = True


_LOADER = _Loader()


def load_plugins() -> None:
    """Import every entry point of group :data:`GROUP`, once per process (registry lookups call
    this first).

    Raises:
        PluginError: a plug-in failed to import; the message names its entry point and its error
            (raised again by every later lookup).
    """
    _LOADER.load()


def use(plugin: str | Path, base: str | Path | None = None) -> ModuleType:
    """Import a user's module that registers entries: a Python file (``"my_pd.py"``, a path) or
    an importable module name (``"mypkg.fields"``). Importing it again returns the module.

    A file is imported as a module named after it (``my_pd``), so that what it defines pickles
    by reference in this process; a name already used by another module is refused.

    Args:
        plugin: a path to a ``.py`` file, or a dotted module name.
        base: the folder a relative path is taken from (default: the working directory; a
            scene's ``plugins`` are taken from the scene file's folder).

    Raises:
        InvalidArgument: no such file or module, or a file whose name is another module's.
        PluginError: the module raised while it was imported; the message names it.
    """
    text = str(plugin)
    if isinstance(plugin, Path) or text.endswith(".py") or "/" in text or "\\" in text:
        return _use_file(Path(base or ".") / plugin)
    if importlib.util.find_spec(text.split(".")[0]) is None:
        raise InvalidArgument(f"plug-in '{text}': no such module (nor file: a file name ends in .py)")
    try:
        return importlib.import_module(text)
    except Exception as exc:
        raise PluginError(f"plug-in module '{text}' failed to import: {type(exc).__name__}: {exc}") from exc


def _use_file(path: Path) -> ModuleType:
    """The module of the file ``path``, imported under its stem (see :func:`use`)."""
    path = path.resolve()
    if not path.is_file():
        raise InvalidArgument(f"plug-in file {path}: no such file")
    name = path.stem
    if not name.isidentifier():
        raise InvalidArgument(f"plug-in file {path}: '{name}' cannot be a module name (letters, digits, _)")
    taken = sys.modules.get(name)
    found = importlib.util.find_spec(name) if taken is None else None
    origin = getattr(taken, "__file__", None) if taken is not None else found and found.origin
    if (taken is not None or found is not None) and not (origin and Path(origin).resolve() == path):
        raise InvalidArgument(f"plug-in file {path}: the module name '{name}' is already taken by "
                              f"{origin or 'a package'}; rename the file")
    if taken is not None:
        return taken
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise PluginError(f"plug-in file {path} failed to import: {type(exc).__name__}: {exc}") from exc
    return module
