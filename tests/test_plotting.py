"""Plot helpers (freefloat.app.viz.plotting): log-axis labels."""

from __future__ import annotations

import matplotlib.mathtext
import numpy as np
import pytest

from freefloat.app.viz.plotting import decade_label, figure, log_curve, save

_DIGITS = str.maketrans("\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079", "-0123456789")


@pytest.mark.parametrize("exponent", range(-16, 17))
def test_a_power_of_ten_is_labelled_with_its_exponent(exponent):
    """10^e reads back as e from the superscripts after '10'."""
    label = decade_label(10.0**exponent)
    assert label.startswith("10") and int(label[2:].translate(_DIGITS)) == exponent


@pytest.mark.parametrize("value", [2e-5, 3.5, 0.25, 7.77e9])
def test_other_values_read_back_to_three_digits(value):
    """A tick between powers of ten keeps its value to three significant digits."""
    assert float(decade_label(value)) == pytest.approx(value, rel=5e-3)


def test_a_log_axis_is_drawn_without_mathtext(tmp_path, monkeypatch):
    """Drawing a log curve never parses mathtext (matplotlib's default log labels do, and its
    first use costs a tenth of the default job)."""
    def refuse(*args, **kwargs):
        raise AssertionError("mathtext was used")

    monkeypatch.setattr(matplotlib.mathtext.MathTextParser, "parse", refuse)
    fig, [ax] = figure(1, 1, (4.0, 3.0), "drift")
    t = np.linspace(0.0, 1.0, 50)
    log_curve(ax, t, 1e-9 * np.exp(20 * t), "drift")
    save(fig, tmp_path, "drift", ("png",))
    assert (tmp_path / "drift.png").stat().st_size > 0
