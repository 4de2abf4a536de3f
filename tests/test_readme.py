"""The README is short and its commands are true: CI runs its install and test commands, its quick
subset has a test of every module and runs on the lowest versions too, its Python runs (checked in
tests/test_docs.py), its times come from the docs, its map links every docs page, and the package
description links nothing outside the repository."""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text()
CI = (REPO / ".ci" / "run").read_text()
LOWEST = (REPO / ".ci" / "lowest").read_text()
#: The README's length limit (issue 37: what it is, install, first run, tests, an example, a map).
MOST_LINES = 150


def section(title: str, text: str = README) -> str:
    """The ``## title`` section of ``text``, up to the next ``## `` heading."""
    start = text.index(f"\n## {title}\n")
    end = text.find("\n## ", start + 1)
    return text[start:] if end < 0 else text[start:end]


def code_blocks(language: str, text: str = README) -> list[str]:
    """The fenced blocks of ``language`` in ``text``."""
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.S | re.M)


def commands(title: str) -> list[str]:
    """The commands of the one bash block of the README's ``title`` section, comments dropped."""
    (block,) = code_blocks("bash", section(title))
    return [line.split("#")[0].strip() for line in block.splitlines() if line.split("#")[0].strip()]


def ci_lines(script: str) -> list[str]:
    """The lines of a CI script, stripped."""
    return [line.strip() for line in script.splitlines()]


def test_the_readme_is_short():
    """The README keeps to its limit; what does not fit is in docs/."""
    assert len(README.splitlines()) <= MOST_LINES


def test_ci_installs_with_the_readme_install_command():
    """The install section is one venv line and one install command, and .ci/run runs both as written."""
    venv, install = commands("Install")
    assert venv.startswith("python3 -m venv") and install.startswith("python3 -m pip install")
    assert 'uv pip install -e ".[test]"' in install
    assert venv in ci_lines(CI) and install in ci_lines(CI)


def test_the_first_run_is_the_default_job():
    """The first run is one command: ``freefloat simulate`` on the built-in default scene."""
    assert commands("First run") == ["freefloat simulate"]


def test_ci_runs_the_readme_test_commands():
    """The tests section names the full command, which .ci/run runs, and the quick subset, which
    .ci/lowest runs on the lowest versions the bounds allow (and .ci/run calls .ci/lowest)."""
    full, quick = commands("Tests")
    assert full == "python3 -m pytest" and full in ci_lines(CI)
    assert quick == 'python3 -m pytest -m "not slow"'
    assert quick in LOWEST and "--resolution lowest-direct" in LOWEST and "bash .ci/lowest" in CI


def test_the_readme_times_come_from_the_docs():
    """Every time and memory the install and tests sections quote is in docs/bench.md's table of
    install and test times; the check finds the numbers of a planted sentence."""
    def quoted(text: str) -> list[str]:
        return re.findall(r"\d+ min \d+ s|\d+(?:\.\d+)?(?:-\d+(?:\.\d+)?)? (?:s|GiB)\b", text)

    assert quoted("took 69.2-73.0 s and 1.69 GiB, then 108 s; the suite 21 min 41 s") == [
        "69.2-73.0 s", "1.69 GiB", "108 s", "21 min 41 s"]
    times = section("Install and test times", (REPO / "docs" / "bench.md").read_text())
    numbers = quoted(section("Install") + section("Tests"))
    assert numbers and [n for n in numbers if n not in times] == []


def test_the_readme_python_is_run_and_checked():
    """The README has a Python example, and each of its blocks has a check in tests/test_docs.py
    (which runs it and compares what it computes with an independent reference)."""
    from .test_docs import SNIPPET_CHECKS

    blocks = code_blocks("python")
    assert blocks and [f"README.md#python{i}" for i in range(len(blocks))
                       if f"README.md#python{i}" not in SNIPPET_CHECKS] == []


def test_the_map_links_every_docs_page():
    """The README's documentation map links every page of docs/, and every page it links exists."""
    linked = set(re.findall(r"\]\(docs/([\w.-]+\.md)(?:#[\w-]*)?\)", section("Documentation")))
    pages = {path.name for path in (REPO / "docs").glob("*.md")}
    assert sorted(pages - linked) == [] and sorted(linked - pages) == []


def has_quick_test(source: str) -> bool:
    """Whether a test module's ``source`` has a test that is not marked ``pytest.mark.slow``
    (by a decorator or by the module's ``pytestmark``)."""
    body = ast.parse(source).body
    if any(isinstance(node, ast.Assign) and "pytest.mark.slow" in ast.unparse(node.value)
           and any(getattr(target, "id", None) == "pytestmark" for target in node.targets) for node in body):
        return False
    return any(isinstance(node, ast.FunctionDef) and node.name.startswith("test_")
               and not any(ast.unparse(d) == "pytest.mark.slow" for d in node.decorator_list) for node in body)


def test_the_quick_subset_has_a_test_of_every_module():
    """Every tests/test_*.py keeps a test outside the slow marker, so that the quick command (and
    with it the lowest versions' run) touches every module; the check sees a planted all-slow one."""
    assert not has_quick_test("import pytest\npytestmark = pytest.mark.slow\ndef test_a(): pass\n")
    assert not has_quick_test("import pytest\n@pytest.mark.slow\ndef test_a(): pass\ndef helper(): pass\n")
    assert has_quick_test("import pytest\n@pytest.mark.slow\ndef test_a(): pass\ndef test_b(): pass\n")
    assert [path.name for path in sorted((REPO / "tests").glob("test_*.py")) if not has_quick_test(path.read_text())] == []


def test_no_links_outside_the_repository():
    """No Markdown link or path in the package description points above the repository."""
    assert not re.search(r"\]\(\.\./|`\.\./", README)
