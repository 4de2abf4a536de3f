"""A run's cost estimate: the per-call cost is measured once per key in a process."""

from __future__ import annotations

from freefloat.app.experiments.budget import seconds_per_call_once


def test_the_cost_of_a_call_is_measured_once_per_key():
    """A second estimate under the same key calls nothing and gives the first one's time; a new
    key measures again."""
    calls = []
    first = seconds_per_call_once(("test", id(calls)), lambda: calls.append(1))
    measured = len(calls)
    again = seconds_per_call_once(("test", id(calls)), lambda: calls.append(1))
    assert measured > 0 and len(calls) == measured and again == first
    seconds_per_call_once(("test", id(calls), "other"), lambda: calls.append(1))
    assert len(calls) == 2 * measured
