"""Sphinx roles in the docstrings as cross-references of the API reference.

The docstrings name other objects the Sphinx way (``:func:`run```, ``:class:`~.plants.Plant```,
``:mod:`.rendering```); mkdocstrings would show that text as it is. This Griffe extension
(registered in ``mkdocs.yml`` under the Python handler's ``extensions``) rewrites every role, once
the package is loaded and before any docstring is parsed, into an optional autorefs reference::

    <autoref identifier="freefloat.dynamics.simulation.run" optional>`run`</autoref>

which mkdocs-autorefs renders as a link where the object is documented on the site and as plain
inline code otherwise, without a warning. The target is resolved as Sphinx and Python would:

- ``.name`` and ``..name``: relative to the package of the docstring's module (``.`` is the
  package, ``..`` its parent), as a relative import;
- ``name`` or ``name.attr``: the first name in the scope of the documented object (its members,
  then its parents', then what its module imports), else a full dotted path;
- ``~`` shows only the last name, otherwise the target is shown as written (leading dots dropped).

Each path is then followed through re-exports to where the object is defined (the identifier that
mkdocstrings registers for it).
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|mod|data|meth|attr|obj|exc|const):`(~?)(\.*)([\w.]+)`")


def _canonical(collection: griffe.ModulesCollection, path: str) -> str:
    """``path`` followed through aliases to where its object is defined; ``path`` if unknown."""
    try:
        return collection[path].canonical_path
    except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
        return path


def _absolute(obj: griffe.Object, dots: str, name: str) -> str:
    """The dotted path that a role written in ``obj``'s docstring names."""
    if dots:
        module = obj.module
        package = module.path if module.is_init_module else module.path.rpartition(".")[0]
        parts = package.split(".")
        return ".".join([*parts[: len(parts) - (len(dots) - 1)], name])
    first, _, rest = name.partition(".")
    try:
        start = obj.resolve(first)
    except griffe.NameResolutionError:
        return name
    return f"{start}.{rest}" if rest else start


def rewrite(obj: griffe.Object, collection: griffe.ModulesCollection) -> str:
    """``obj``'s docstring with each Sphinx role replaced by an optional autorefs reference."""

    def reference(match: re.Match) -> str:
        tilde, dots, name = match.groups()
        identifier = _canonical(collection, _absolute(obj, dots, name))
        shown = name.rpartition(".")[2] if tilde else name
        return f'<autoref identifier="{identifier}" optional>`{shown}`</autoref>'

    return ROLE.sub(reference, obj.docstring.value)


class SphinxRoles(griffe.Extension):
    """Rewrites the Sphinx roles of every docstring of a package once it is loaded."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        """Rewrite every docstring of ``pkg`` and of its members, recursively (aliases skipped:
        their targets are rewritten where they are defined)."""
        pending: list[griffe.Object] = [pkg]
        while pending:
            obj = pending.pop()
            if obj.docstring is not None:
                obj.docstring.value = rewrite(obj, loader.modules_collection)
            pending.extend(member for member in obj.members.values() if not member.is_alias)
