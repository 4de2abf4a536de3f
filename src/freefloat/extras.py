"""The optional parts of freefloat (pyproject.toml's extras) and the check a command makes
before any work: a missing extra is a :class:`~freefloat.errors.MissingExtra` naming the
command, the extra and the line that installs it, not a ``ModuleNotFoundError`` half-way."""

from __future__ import annotations

import importlib

from .errors import MissingExtra

#: Extra -> the top-level modules it brings (pyproject.toml's ``[project.optional-dependencies]``).
EXTRAS: dict[str, tuple[str, ...]] = {
    "dask": ("dask", "distributed"),
    "bench": ("mujoco",),
}


def require(extra: str, who: str) -> None:
    """Import the modules of ``extra`` (``who`` needs them: ``"freefloat batch --dask"``).

    Raises:
        MissingExtra: naming ``who``, the extra, the module missing and the install line.
    """
    for module in EXTRAS[extra]:
        try:
            importlib.import_module(module)
        except ImportError as exc:
            raise MissingExtra(f"{who} needs the optional '{extra}' extra ({module}: {exc}); install it in "
                               f'your freefloat folder: python3 -m pip install -e ".[{extra}]"') from None
