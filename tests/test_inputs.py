"""Reading user files: TOML errors name the file, unknown keys are refused with the valid ones."""

from __future__ import annotations

import tomllib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from freefloat.errors import FreefloatError, SceneError
from freefloat.inputs import read_toml, reject_unknown, toml_text


def test_a_deeply_nested_file_is_refused_not_a_recursion_error(tmp_path):
    """A TOML file nested thousands deep raises the given error naming the file."""
    (tmp_path / "deep.toml").write_text("a = " + "[" * 20000 + "]" * 20000 + "\n")
    with pytest.raises(SceneError, match="deep.toml: nested too deeply to be a scene file"):
        read_toml(tmp_path / "deep.toml", "scene file", SceneError)


def test_an_unknown_key_names_the_closest_valid_one_and_all():
    """A misspelt key is refused with a suggestion and the list of valid keys."""
    with pytest.raises(FreefloatError, match=r"f.toml: unknown \[platform\] key 'coordinate'; did you mean "
                                             r"'coordinates'\? \(allowed: coordinates, frame\)"):
        reject_unknown("f.toml: ", {"coordinate": 1}, ["frame", "coordinates"], "platform")


@given(st.lists(st.sampled_from(["frame", "coordinates", "frames", "coordinate", "gravty", ""]), max_size=4))
def test_a_table_is_refused_exactly_when_a_key_is_not_allowed(keys):
    """reject_unknown refuses a table iff its keys are not a subset of the allowed ones (set
    arithmetic as the reference), naming the first key that is not."""
    allowed = ["frame", "coordinates"]
    table = dict.fromkeys(keys, 1)
    extra = [key for key in table if key not in allowed]
    if not extra:
        assert reject_unknown("f.toml: ", table, allowed) is None
        return
    with pytest.raises(FreefloatError, match=f"unknown top-level key '{extra[0]}'"):
        reject_unknown("f.toml: ", table, allowed)


_scalars = st.one_of(st.booleans(), st.integers(-2**63, 2**63 - 1), st.floats(allow_nan=False), st.text(max_size=12))
_values = st.recursive(_scalars, lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner,
                                                                                               max_size=3), max_leaves=8)


@given(st.dictionaries(st.text(max_size=8), _values | st.dictionaries(st.text(max_size=8), _values, max_size=4),
                       max_size=5))
def test_toml_text_reads_back_equal(table):
    """Any table of TOML's values (odd keys, quotes, newlines, infinities, nesting) is read back
    by tomllib as it was written."""
    assert tomllib.loads(toml_text(table)) == table
