"""The README's commands are true: CI runs its install and test commands, and the package
description links nothing outside the repository (its Python: tests/test_docs.py)."""

from __future__ import annotations

import re
from pathlib import Path

README = (Path(__file__).resolve().parents[1] / "README.md").read_text()
CI = (Path(__file__).resolve().parents[1] / ".ci" / "run").read_text()


def code_blocks(language: str) -> list[str]:
    """The README's fenced blocks of ``language``."""
    return re.findall(rf"```{language}\n(.*?)```", README, flags=re.S)


def test_ci_runs_the_quick_start_commands():
    """.ci/run creates the venv, installs and tests with the README's quick-start commands."""
    quick_start = code_blocks("bash")[0]
    commands = [line.split("#")[0].strip() for line in quick_start.splitlines()]
    venv, install, _, test = commands[:4]
    assert venv.startswith("python3 -m venv") and install.startswith("python3 -m pip install")
    for command in (venv, install, test):
        assert command in CI, command


def test_no_links_outside_the_repository():
    """No Markdown link or path in the package description points above the repository."""
    assert not re.search(r"\]\(\.\./|`\.\./", README)
