"""A command that needs an optional extra says which, with exit 2, before any work: tested with
the extra made absent (its modules blocked from importing) in a fresh interpreter."""

from __future__ import annotations

import subprocess
import sys

import pytest

from freefloat import MissingExtra
from freefloat.extras import EXTRAS, require

BLOCK = "import sys\nfor name in {modules!r}:\n    sys.modules[name] = None\nfrom freefloat.app.cli import main\n" \
        "sys.exit(main(sys.argv[1:]))"


def without(extra: str, *argv: str) -> subprocess.CompletedProcess:
    """``freefloat ARGV`` in a new interpreter where the modules of ``extra`` cannot be imported."""
    code = BLOCK.format(modules=EXTRAS[extra])
    return subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=300)


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["batch", "--dask", "--runs", "2", "--vary", "joint_rate=1"],
                                  ["reproduce", "robustness", "--quick"]], ids=["batch", "reproduce"])
def test_a_command_without_dask_names_the_extra_before_any_work(tmp_path, argv):
    """Exit 2, one line naming the command, the extra and the install line; no folder made."""
    out = tmp_path / "out"
    done = without("dask", *argv, "--out", str(out))
    assert done.returncode == 2, done.stderr
    assert "needs the optional 'dask' extra" in done.stderr and 'pip install -e ".[dask]"' in done.stderr
    assert "Traceback" not in done.stderr and not out.exists()


def test_require_passes_when_the_extra_is_there_and_names_a_missing_module(monkeypatch):
    """With Dask installed (the test extra has it) nothing is raised; an extra whose module is
    absent raises MissingExtra naming the extra and the module."""
    pytest.importorskip("distributed")
    require("dask", "this test")
    monkeypatch.setitem(EXTRAS, "bench", ("freefloat_no_such_module",))
    with pytest.raises(MissingExtra, match="this test needs the optional 'bench' extra \\(freefloat_no_such_module"):
        require("bench", "this test")
