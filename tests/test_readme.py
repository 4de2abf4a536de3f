"""The README's commands are true: CI runs its install and test commands, its quick subset has a
test of every module and runs on the lowest versions too, and the package description links
nothing outside the repository (its Python: tests/test_docs.py)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text()
CI = (REPO / ".ci" / "run").read_text()
LOWEST = (REPO / ".ci" / "lowest").read_text()


def code_blocks(language: str) -> list[str]:
    """The README's fenced blocks of ``language``."""
    return re.findall(rf"```{language}\n(.*?)```", README, flags=re.S)


def quick_start_commands() -> list[str]:
    """The commands of the README's quick-start block, comments dropped."""
    return [line.split("#")[0].strip() for line in code_blocks("bash")[0].splitlines()]


def test_ci_runs_the_quick_start_commands():
    """.ci/run creates the venv, installs and tests with the README's quick-start commands."""
    venv, install, _, test = quick_start_commands()[:4]
    assert venv.startswith("python3 -m venv") and install.startswith("python3 -m pip install")
    for command in (venv, install, test):
        assert command in CI, command


def test_ci_runs_the_quick_subset_on_the_lowest_versions():
    """The quick-start block names the quick subset's command; .ci/lowest installs the lowest
    versions the bounds allow and runs it, and .ci/run calls .ci/lowest."""
    [quick] = [command for command in quick_start_commands() if "not slow" in command]
    assert quick in LOWEST and "--resolution lowest-direct" in LOWEST and "bash .ci/lowest" in CI


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
