"""Figures rendered in two processes without a fork: the helper (a new interpreter fed pickled
figures) writes its share, nothing calls os.fork, and a lost helper costs no figure."""

from __future__ import annotations

import os

import numpy as np

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
    replies = rendering.render_each(plotting.save, [(fig, tmp_path, stem) for stem, fig in figures.items()])()
    assert replies == [[tmp_path / f"{stem}.{fmt}" for fmt in plotting.FORMATS] for stem in figures]
    assert all(path.stat().st_size > 0 for reply in replies for path in reply)


def test_save_all_never_forks(tmp_path, monkeypatch):
    """Every figure is written with os.fork made to fail (it was the way to a second process)."""
    def no_fork():
        raise AssertionError("os.fork called")

    monkeypatch.setattr(os, "fork", no_fork)
    paths = plotting.save_all(_figures(4), tmp_path)
    assert len(paths) == 8 and all(path.is_file() for path in paths)


def test_a_lost_helper_costs_no_figure(tmp_path, monkeypatch):
    """With the helper dead (killed), save_all writes every figure itself."""
    rendering.warm_up()
    rendering._helper.kill()
    rendering._helper.wait()
    monkeypatch.setattr(rendering, "warm_up", lambda: None)  # keep the dead helper for this call
    paths = plotting.save_all(_figures(3), tmp_path)
    assert len(paths) == 6 and all(path.is_file() for path in paths)
