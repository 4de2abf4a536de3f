"""freefloat's errors: an unknown name gets the nearest valid ones and a short list."""

from __future__ import annotations

import pytest

from freefloat.errors import LISTED, UnknownName, did_you_mean


def test_the_nearest_names_come_first_and_the_list_after():
    """A typo gets its nearest names (up to three, case ignored) before the valid ones."""
    assert did_you_mean("rk45", ["euler", "rkmk4", "dopri5"]) == "; did you mean 'rkmk4'? (valid: euler, rkmk4, dopri5)"
    assert did_you_mean("UR55", ["ur5", "ur10", "panda"], "known") == "; did you mean 'ur5'? (known: ur5, ur10, panda)"
    assert did_you_mean("zzz", ["euler", "rkmk4"]) == "; valid: euler, rkmk4"


def test_a_long_list_is_cut_and_says_where_the_rest_is():
    """More than LISTED names: the first LISTED, a count of the rest and where to see them all."""
    names = [f"robot_{i:03d}" for i in range(80)]
    text = did_you_mean("robto_042", names, "known", "freefloat robots")
    assert text.startswith("; did you mean 'robot_042'")
    assert f"and {80 - LISTED} more, listed by freefloat robots)" in text and "robot_079" not in text


def test_unknown_name_suggests_the_nearest():
    """UnknownName, every registry's error, suggests the nearest name and keeps the choices."""
    error = UnknownName("integrator", "rkmk5", ["euler", "rkmk4", "rkmk6"])
    assert str(error).startswith("unknown integrator 'rkmk5'; did you mean 'rkmk4' or 'rkmk6'?")
    assert error.choices == ("euler", "rkmk4", "rkmk6")
    with pytest.raises(KeyError):
        raise error


def test_a_message_names_the_argument_as_the_caller_spells_it():
    """Outside the command line a message names the Python argument; inside it, the option."""
    from freefloat.errors import command_line, spelled

    assert spelled("out=", "--out") == "out="
    with command_line():
        assert spelled("out=", "--out") == "--out"
    assert spelled("overwrite=True", "--overwrite") == "overwrite=True"


#: Folders whose messages and raises the two scans leave out (none: the lab and the atlas are held to them too).
ELSEWHERE: tuple[str, ...] = ()
#: Where a message may name a command-line option as such: the command line itself and the parser
#: of its ``--vary`` text.
OPTIONS_SPOKEN = ("app/cli.py", "app/batch/bands.py")


def package_sources(skip: tuple[str, ...]):
    """``(where, tree, lines)`` of every module of the package but those under ``skip``: its path
    in the package, its syntax tree and its lines."""
    import ast
    from pathlib import Path

    import freefloat

    root = Path(freefloat.__file__).parent
    for path in sorted(root.rglob("*.py")):
        where = path.relative_to(root).as_posix()
        if not where.startswith(skip):
            text = path.read_text()
            yield where, ast.parse(text), text.splitlines()


def test_messages_outside_the_command_line_spell_options_for_their_caller():
    """No string of the package outside :data:`OPTIONS_SPOKEN` names a ``--option`` in a raise or
    a warning except through ``spelled`` (a Python call into a used folder answered ``--out``)."""
    import ast
    import re

    found = []
    for where, tree, _ in package_sources(ELSEWHERE + OPTIONS_SPOKEN):
        spelt = {id(c) for node in ast.walk(tree) if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "spelled"
                 for c in ast.walk(node)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) or (isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "warn"):
                found += [f"{where}:{part.lineno}: {part.value!r}" for part in ast.walk(node)
                          if isinstance(part, ast.Constant) and isinstance(part.value, str) and id(part) not in spelt
                          and re.search(r"--[a-z]", part.value)]
    assert not found, "\n".join(found)


def test_every_bare_base_class_raise_is_justified():
    """Every ``raise FreefloatError(...)`` in the package carries ``# base class: <why>`` on its
    line or the line before; everywhere else a specific class applies (InvalidArgument,
    NotAssembled, ClosureFileError, RunFolderError, ...), so that ``except`` can tell them apart."""
    import ast

    bare = []
    for where, tree, lines in package_sources(ELSEWHERE):
        bare += [f"{where}:{node.lineno}: {lines[node.lineno - 1].strip()}" for node in ast.walk(tree)
                 if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call)
                 and getattr(node.exc.func, "id", "") == "FreefloatError"
                 and "# base class:" not in " ".join(lines[node.lineno - 2:node.lineno])]
    assert not bare, "\n".join(bare)


def test_every_error_class_is_exported_and_documented():
    """Every error and warning class of freefloat.errors is ``freefloat.<name>``, and the API
    reference documents the module that defines them."""
    import inspect

    import freefloat
    from freefloat import errors

    from .conftest import REPO

    classes = {name for name, value in vars(errors).items()
               if inspect.isclass(value) and issubclass(value, (errors.FreefloatError, errors.FreefloatWarning))}
    assert {"NotAssembled", "InfeasiblePlan", "ClosureFileError", "DataFileError", "RunFolderError"} <= classes
    assert classes <= set(freefloat.__all__) and all(getattr(freefloat, name) is getattr(errors, name) for name in classes)
    assert "::: freefloat.errors" in (REPO / "docs" / "api.md").read_text()


@pytest.mark.parametrize("specific, base", [("ClosureFileError", "RobotModelError"), ("DataFileError", "RobotModelError"),
                                            ("NotAssembled", "FreefloatError"), ("RunFolderError", "FreefloatError"),
                                            ("TargetMissed", "FreefloatError"), ("BadShape", "InvalidArgument")])
def test_a_specific_error_is_still_caught_by_its_family(specific, base):
    """Each specific class subclasses its family's, so an ``except`` written for the family (or
    for FreefloatError) still catches it."""
    from freefloat import errors

    assert issubclass(getattr(errors, specific), getattr(errors, base))
    assert issubclass(getattr(errors, specific), errors.FreefloatError)
