"""``figures`` suite: the cost of writing a run's figures beside the simulation itself (the
default scene: four-arm robot, 5 s at 1 ms), best of ``repeats``, in one process."""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from pathlib import Path

from ...runner import simulate
from ...scenes import DEFAULT_SCENE, find_scene
from ...viz import plotting
from .drawing import save, subplots
from .timing import per_call


def settings(quick: bool, repeats: int | None) -> dict:
    """The scene and the repeats (best of; default 3, 1 quick)."""
    return {"scene": DEFAULT_SCENE, "repeats": repeats or (1 if quick else 3)}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part: the simulation's wall time (s), the figures' as PNG and PDF and as PNG only, and
    the figures' time over the simulation's."""
    scene = find_scene(settings["scene"])
    outcome = simulate(scene)
    times = {"simulation_s": per_call(lambda: simulate(scene), 1, settings["repeats"])}
    formats = plotting.FORMATS
    with tempfile.TemporaryDirectory() as folder:
        try:
            times["figures_png_pdf_s"] = per_call(lambda: outcome.figures(Path(folder)), 1, settings["repeats"])
            plotting.FORMATS = ("png",)
            times["figures_png_s"] = per_call(lambda: outcome.figures(Path(folder)), 1, settings["repeats"])
        finally:
            plotting.FORMATS = formats
    yield "figures", times | {"figures_over_simulation": times["figures_png_pdf_s"] / times["simulation_s"]}


def chart(report: dict, path: Path) -> None:
    """Bars: the simulation's and the figures' wall times."""
    times = report["figures"]
    fig, ax = subplots(1, 1, (6.0, 3.5))
    ax.barh(["simulation", "figures PNG + PDF", "figures PNG"],
            [times["simulation_s"], times["figures_png_pdf_s"], times["figures_png_s"]])
    ax.set_xlabel(f"wall time (s), best of {report['settings']['repeats']}")
    ax.set_title("Default scene: figures against the simulation")
    save(fig, path)
