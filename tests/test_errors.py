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
