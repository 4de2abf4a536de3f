"""Tests of freefloat.arguments: the one check of the numbers handed to public functions."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.arguments import MAX_MAGNITUDE, real_array, real_number, whole_number
from freefloat.errors import BadShape, InvalidArgument


@pytest.mark.parametrize("value, message", [
    (["a", "b"], "'x' must hold real numbers, got strings"), (None, "'x' must hold real numbers, got objects"),
    (np.ones(2) + 1j, "'x' must hold real numbers, got complex numbers"), ([[1.0], [1.0, 2.0]], "'x' must be an array"),
    ([1.0, np.nan], r"'x' must be finite; entries \[1\]"), ([0.0, 2 * MAX_MAGNITUDE], "'x' must be at most 1e\\+15"),
])
def test_a_bad_array_is_refused_naming_it(value, message):
    """Strings, None, complex numbers, ragged lists, NaN and huge values are refused naming the
    argument (numpy's message, a dropped imaginary part or a NaN later, before)."""
    with pytest.raises(InvalidArgument, match=message):
        real_array("x", value)


def test_an_array_of_the_wrong_shape_is_a_bad_shape():
    """The wrong shape is a BadShape naming both shapes; lists and integers are taken."""
    with pytest.raises(BadShape, match=r"'x' must have shape \(3,\), got \(2,\)"):
        real_array("x", [1, 2], (3,))
    assert real_array("x", [1, 2, 3], (3,)).dtype == float


@pytest.mark.parametrize("value", [None, "1", True, float("nan"), float("inf"), 1e300, -1.0])
def test_a_bad_number_is_refused_naming_it(value):
    """A number that is no real number, not finite, huge or below its bound is refused."""
    with pytest.raises(InvalidArgument, match="'h' must be"):
        real_number("h", value, above=0.0)


@pytest.mark.parametrize("value", [None, 1.0, True, 0, 11])
def test_a_bad_count_is_refused_naming_it(value):
    """A count that is a float, a bool or out of range is refused (a comparison's TypeError before)."""
    with pytest.raises(InvalidArgument, match="'n' must be"):
        whole_number("n", value, 1, 10)


def test_an_object_of_the_wrong_kind_is_refused_naming_the_argument_and_what_it_takes():
    """an_object passes an instance or an object with the methods, and refuses another, naming
    the argument, what it takes and what was given."""
    from freefloat.arguments import an_object

    assert an_object("out", "runs/x", "a path", (str,)) == "runs/x"
    assert an_object("controller", np.zeros(1), "a controller", methods=("copy",)) is not None
    with pytest.raises(InvalidArgument, match=r"'controller' takes a controller, got a dict"):
        an_object("controller", {"torque": 1}, "a controller", methods=("torque",))
    with pytest.raises(InvalidArgument, match=r"'scene' takes a scene, got None"):
        an_object("scene", None, "a scene", (str,))
