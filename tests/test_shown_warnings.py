"""Warnings as the command line shows them: one line each, once per process, held back until the
command is past its checks and dropped when it is refused."""

from __future__ import annotations

import warnings

import pytest

from freefloat.app import shown_warnings
from freefloat.app.shown_warnings import shown_warnings as shown
from freefloat.errors import FreefloatError, FreefloatNote, FreefloatWarning


@pytest.fixture(autouse=True)
def fresh(monkeypatch):
    """This process as if it had shown no warning yet."""
    monkeypatch.setattr(shown_warnings, "SHOWN", set())


def test_warnings_wait_for_the_release_then_print_as_they_come(capsys):
    """Before ``release()`` nothing is printed; then what was held, each once, a note as a note;
    after it, each new warning at once."""
    with shown() as held:
        warnings.warn("the mesh is missing", FreefloatWarning)
        warnings.warn("the inertias are as printed", FreefloatNote)
        warnings.warn("the mesh is missing", FreefloatWarning)
        assert capsys.readouterr().err == ""
        held.release()
        assert capsys.readouterr().err == ("freefloat: warning: the mesh is missing\n"
                                           "freefloat: note: the inertias are as printed\n")
        warnings.warn("the run slowed down", FreefloatWarning)
        assert capsys.readouterr().err == "freefloat: warning: the run slowed down\n"


def test_a_command_that_ends_without_a_release_prints_them_at_its_end(capsys):
    """A command that never reports its start (a capture, a verify) still shows its warnings."""
    with shown():
        warnings.warn("the mesh is missing", FreefloatWarning)
    assert capsys.readouterr().err == "freefloat: warning: the mesh is missing\n"


@pytest.mark.parametrize("stop", [FreefloatError("folder in use"), KeyboardInterrupt()])
def test_an_error_before_the_release_drops_them(capsys, stop):
    """A command refused (or interrupted) before its run started prints no warning."""
    with pytest.raises(type(stop)), shown():
        warnings.warn("the mesh is missing", FreefloatWarning)
        raise stop
    assert capsys.readouterr().err == ""
    with shown():  # not shown yet: the next command of the process shows it
        warnings.warn("the mesh is missing", FreefloatWarning)
    assert capsys.readouterr().err == "freefloat: warning: the mesh is missing\n"


def test_a_warning_is_shown_once_per_process(capsys):
    """A second command in the same process does not repeat a warning the first showed."""
    for _ in range(2):
        with shown():
            warnings.warn("the mesh is missing", FreefloatWarning)
    assert capsys.readouterr().err.count("the mesh is missing") == 1
