"""Figures rendered in two processes without a fork: the helper (a new interpreter fed pickled
figures) writes its share, nothing calls os.fork, and a lost helper costs no figure."""

from __future__ import annotations

import os

import numpy as np
import pytest

from freefloat.app.viz import plotting, rendering


def _figures(count: int) -> dict:
    """``count`` small figures of a sine."""
    out = {}
    for k in range(count):
        fig, (ax,) = plotting.figure(1, 1, (4, 3), f"figure {k}")
        t = np.linspace(0, 1, 200)
        plotting.curve(ax, t, np.sin((k + 1) * t), "sine")
        out[f"figure{k}"] = fig
    return out


def test_the_helper_renders_what_it_is_sent(tmp_path):
    """Each job sent to the helper comes back as the paths it wrote, and they are there."""
    figures = _figures(2)
    helper = rendering.Renderer(plotting.save)
    assert all(helper.send(fig, tmp_path, stem, ("png", "pdf")) for stem, fig in figures.items())
    replies = helper.collect()
    assert replies == [[tmp_path / f"{stem}.{fmt}" for fmt in ("png", "pdf")] for stem in figures]
    assert all(path.stat().st_size > 0 for reply in replies for path in reply)


def test_save_all_never_forks(tmp_path, monkeypatch):
    """Every figure is written with os.fork made to fail (it was the way to a second process)."""
    def no_fork():
        raise AssertionError("os.fork called")

    monkeypatch.setattr(os, "fork", no_fork)
    paths = plotting.save_all(_figures(4), tmp_path)
    assert len(paths) == 4 and all(path.is_file() for path in paths)


def test_a_lost_helper_costs_no_figure(tmp_path, monkeypatch):
    """With the helper dead (killed), save_all writes every figure itself."""
    rendering.warm_up()
    rendering._helper.kill()
    rendering._helper.wait()
    monkeypatch.setattr(rendering, "warm_up", lambda: None)  # keep the dead helper for this call
    paths = plotting.save_all(_figures(3), tmp_path)
    assert len(paths) == 3 and all(path.is_file() for path in paths)


@pytest.mark.slow
def test_a_figure_redrawn_after_it_was_sent_is_rendered_as_sent(tmp_path, monkeypatch):
    """The helper renders a figure as it was when sent, and so does this process when the helper
    failed on it: a later change to the same Figure (the next figure redrawing it) reaches neither."""
    (fig,) = _figures(1).values()
    helper = rendering.Renderer(plotting.save)
    helper.send(fig, tmp_path, "sent", ("png",))
    fig.axes[0].lines[0].set_ydata(np.zeros(200))  # redrawn for the next figure
    plotting.save(fig, tmp_path, "changed", ("png",))
    helper.collect()
    fresh = _figures(1)["figure0"]
    plotting.save(fresh, tmp_path, "fresh", ("png",))
    assert (tmp_path / "sent.png").read_bytes() == (tmp_path / "fresh.png").read_bytes()
    assert (tmp_path / "changed.png").read_bytes() != (tmp_path / "fresh.png").read_bytes()


def test_the_helper_knows_it_is_the_helper():
    """A job run in the helper sees in_helper() true (so that its figures are rendered there,
    never sent on to a helper of its own), and this process sees it false."""
    helper = rendering.Renderer(rendering.in_helper)
    assert helper.send()
    assert helper.collect() == [True] and not rendering.in_helper()


def test_cool_down_ends_the_helper_and_the_next_warm_up_starts_another():
    """A helper started for nothing is ended by cool_down; warm_up then starts a new one."""
    rendering.warm_up()
    started = rendering._helper
    rendering.cool_down()
    assert started.poll() is not None and rendering._helper is None
    rendering.warm_up()
    assert rendering._helper is not started and rendering._helper.poll() is None


class _Refused:
    """An object whose pickling raises a RuntimeError, as a Boost.Python type's does."""

    def __reduce__(self):
        raise RuntimeError('Pickling of "RigidConstraintModel" instances is not enabled')


def test_a_job_whose_pickling_raises_anything_is_not_sent():
    """A job that cannot be pickled, whatever the error, is refused (the run draws it itself)."""
    renderer = rendering.Renderer(plotting.save)
    try:
        assert renderer.send(_Refused()) is False
    finally:
        renderer.close()
