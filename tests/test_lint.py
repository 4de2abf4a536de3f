"""The project's lint (ruff, configured in pyproject.toml) passes on the package, the tests, the
scripts and the examples, as part of the test command."""

from __future__ import annotations

import subprocess
import sys

from .conftest import REPO

#: What the lint covers.
LINTED = ("src", "tests", "scripts", "examples")


def test_ruff_finds_nothing():
    """``ruff check`` with the project's configuration reports no finding."""
    done = subprocess.run([sys.executable, "-m", "ruff", "check", *LINTED], cwd=REPO, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
