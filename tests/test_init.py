"""The package root: every public name resolves to the object its module defines, importing
freefloat alone imports none of them, and an unknown name says so."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

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


@pytest.mark.slow
def test_every_module_is_an_attribute_after_importing_freefloat():
    """After ``import freefloat`` alone, every subpackage and module is reachable as an attribute
    chain (``freefloat.gjm.compute``, ``freefloat.dynamics.integrators``), imported on first use
    (or it is a function of the same name that its package exports, ``gjm.derivatives``)."""
    root = Path(freefloat.__file__).parent
    names = sorted(".".join(("freefloat", *p.relative_to(root).with_suffix("").parts)).removesuffix(".__init__")
                   for p in root.rglob("*.py") if p.name != "__main__.py")
    names = [n for n in names if n != "freefloat"]
    code = ("import functools, sys, types, warnings\nwarnings.simplefilter('ignore')\nimport freefloat\n"
            f"for name in {names!r}:\n"
            "    found = functools.reduce(getattr, name.split('.')[1:], freefloat)\n"
            "    assert found is sys.modules[name] or callable(found) and not isinstance(found, types.ModuleType), name\n"
            "print(freefloat.gjm.compute is sys.modules['freefloat.dynamics.gjm'].compute, len(sys.modules) > 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.split() == ["True", "True"], done.stderr[-2000:]


def test_an_unknown_name_is_an_attribute_error():
    """A name the package does not have raises AttributeError naming it."""
    with pytest.raises(AttributeError, match="no attribute 'load_robbot'"):
        freefloat.load_robbot  # noqa: B018
    with pytest.raises(AttributeError, match="'freefloat.dynamics' has no attribute 'integrator'"):
        freefloat.dynamics.integrator  # noqa: B018


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
