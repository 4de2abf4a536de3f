"""The package root: every public name resolves to the object its module defines, importing
freefloat alone imports none of them, and an unknown name says so."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import freefloat


@pytest.mark.parametrize("name", [n for n in freefloat.__all__ if n != "__version__"])
def test_every_public_name_is_its_modules_object(name):
    """``freefloat.X`` is the object of the module the front door names for it."""
    where = freefloat._PUBLIC.get(name)
    value = getattr(freefloat, name)
    if where is None:  # the error types, defined in freefloat.errors
        assert value is getattr(importlib.import_module("freefloat.errors"), name)
    else:
        module, attribute = where if isinstance(where, tuple) else (where, name)
        assert value is getattr(importlib.import_module(module), attribute)


def test_importing_freefloat_loads_no_public_module():
    """``import freefloat`` imports only the error types and the lazy-export helper: the robot
    loader (yourdfpy, trimesh), the loop and the application stay unimported until a name is used."""
    code = ("import sys, freefloat; print(sorted(m for m in sys.modules if m.startswith('freefloat.') "
            "and m not in ('freefloat.errors', 'freefloat.lazy')))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "[]"


def test_an_unknown_name_is_an_attribute_error():
    """A name the package does not have raises AttributeError naming it."""
    with pytest.raises(AttributeError, match="no attribute 'load_robbot'"):
        freefloat.load_robbot  # noqa: B018


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["batch", "--help"], ["reproduce", "--help"],
                                  ["bench", "--help"]])
def test_the_command_line_answers_without_heavy_libraries(argv):
    """``freefloat --version`` and the help texts import no numerical, robot or figure library
    (they made ``--version`` take 2.4 s, 4x ``import pinocchio``)."""
    heavy = ("numpy", "pinocchio", "scipy", "yourdfpy", "trimesh", "matplotlib", "meshcat", "tqdm", "dask")
    code = ("import sys\nfrom freefloat.app.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n"
            f"    pass\nprint(sorted(m for m in {heavy!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"
