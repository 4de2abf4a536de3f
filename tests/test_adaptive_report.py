"""``freefloat reproduce adaptive``: when the estimates have settled."""

from __future__ import annotations

from freefloat.lab.reproduce.adaptive_report import settled_from


def test_settled_from_is_the_time_after_the_last_excursion():
    """The first time from which every ratio stays within the band; None when the last is outside."""
    t = [0.0, 0.1, 0.2, 0.3, 0.4]
    ratios = [[1.5, 1.0], [1.0, 0.9], [1.02, 1.0], [0.97, 1.01], [1.0, 1.0]]
    assert settled_from(t, ratios, 0.05) == 0.2
    assert settled_from(t, ratios, 0.2) == 0.1
    assert settled_from(t, ratios, 0.6) == 0.0
    assert settled_from(t, ratios + [[1.1, 1.0]], 0.05) is None
