"""The README and the docs site show only what works: every Python snippet runs, every
``freefloat`` command parses, every script exists, every scene file is accepted."""

from __future__ import annotations

import os
import re
import shlex
import tomllib

import pytest

from freefloat.app import cli
from freefloat.app.scenes import parse_scene

from .conftest import REPO

PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
#: Placeholders in command synopses and what a check substitutes for them.
PLACEHOLDERS = {"SCENE": "four_arm_joint_space", "URDF": "urdf/four_arm_planar.urdf", "DIR": "runs/x",
                "FILE": "runs/x.json", "N": "2", "ADDR": "tcp://127.0.0.1:8786", "RUN_DIR": "runs/x",
                "ROBOT": "ur5"}


def blocks(language: str) -> list[tuple[str, str]]:
    """(where, code) of every fenced block in ``language`` on the pages."""
    found = []
    for page in PAGES:
        for i, code in enumerate(re.findall(rf"^```{language}\n(.*?)^```", page.read_text(), re.DOTALL | re.MULTILINE)):
            found.append((f"{page.name}#{language}{i}", code))
    return found


def commands() -> list[tuple[str, list[str]]]:
    """(where, argv) of every ``freefloat`` or ``python3 scripts/...`` line of the bash blocks,
    comments dropped, optional brackets opened and placeholders filled."""
    found = []
    for where, code in blocks("bash"):
        for line in code.splitlines():
            line = line.split("  #")[0].split(" # ")[0].strip()
            if not line.startswith(("freefloat", "python3 scripts/")):
                continue
            line = re.sub(r"\[([^\]]*)\]", r"\1", line)
            found.append((where, [PLACEHOLDERS.get(word, word) for word in shlex.split(line)]))
    return found


@pytest.mark.parametrize(("where", "code"), blocks("python"), ids=[w for w, _ in blocks("python")])
def test_python_snippet_runs(where, code, tmp_path, monkeypatch):
    """The snippet executes without error (from a fresh folder)."""
    monkeypatch.chdir(tmp_path)
    exec(compile(code, where, "exec"), {"__name__": "snippet"})  # noqa: S102 -- running the snippet is the test


@pytest.mark.parametrize(("where", "argv"), commands(), ids=[" ".join(a) for _, a in commands()])
def test_command_parses(where, argv, monkeypatch):
    """A ``freefloat`` command is accepted by the command line (its work stubbed out); a script exists."""
    if argv[0] == "python3":
        assert (REPO / argv[1]).is_file(), f"{where}: no {argv[1]}"
        return
    seen = []
    for name in ("_simulate", "_verify", "_reproduce", "_scenes", "_view", "_info", "_bench"):
        monkeypatch.setattr(cli, name, lambda *args, name=name: seen.append(name) or 0)
    assert cli.main(argv[1:]) == 0 and seen, f"{where}: {' '.join(argv)}"


@pytest.mark.parametrize(("where", "text"), blocks("toml"), ids=[w for w, _ in blocks("toml")])
def test_scene_example_is_accepted(where, text, monkeypatch):
    """A TOML example that is a scene passes the scene validation."""
    monkeypatch.chdir(REPO / "src" / "freefloat" / "app" / "scenes")
    parse_scene(tomllib.loads(text))


def test_site_builds_with_warnings_as_errors(tmp_path):
    """``mkdocs build --strict`` succeeds (skipped without the docs extra)."""
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings")
    import subprocess
    import sys

    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                          check=False, cwd=REPO, capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert (tmp_path / "site" / "index.html").is_file()
