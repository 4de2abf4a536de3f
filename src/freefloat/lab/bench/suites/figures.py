"""``figures`` suite: the cost of writing a run's figures beside the simulation itself (the
default scene: four-arm robot, 5 s at 1 ms), in one process, taking turns, best of ``repeats``:
the default set as PNG (what ``freefloat simulate`` draws), every figure as PNG, and every figure
as PNG and PDF (what it drew before the set and the format were choices)."""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from pathlib import Path

from ....app import figure_set
from ....app.runner import simulate
from ....app.scenes import DEFAULT_SCENE, find_scene
from ....app.viz import plotting, rendering
from .drawing import save, subplots
from .timing import side_by_side

#: The figure writings measured: key -> (figure names, formats).
WRITINGS = {"default_png_s": (frozenset(figure_set.DEFAULT), ("png",)),
            "all_png_s": (None, ("png",)),
            "all_png_pdf_s": (None, ("png", "pdf"))}


def settings(quick: bool, repeats: int | None) -> dict:
    """The scene and the repeats (best of; default 3, 1 quick)."""
    return {"scene": DEFAULT_SCENE, "repeats": repeats or (1 if quick else 3)}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """One part: the simulation's wall time (s), each of :data:`WRITINGS`' (s), and each
    writing's time over the simulation's."""
    scene = find_scene(settings["scene"])
    outcome = simulate(scene)
    rendering.warm_up()  # as a run does: the helper starts while it simulates

    def writing(names, formats):
        def write():
            with tempfile.TemporaryDirectory() as folder, plotting.choose(names, formats):
                outcome.figures(Path(folder))
        return write

    calls = {"simulation_s": (lambda: simulate(scene), 1)}
    calls.update({key: (writing(*choice), 1) for key, choice in WRITINGS.items()})
    times = side_by_side(calls, settings["repeats"])
    yield "figures", times | {f"{key[:-2]}_over_simulation": times[key] / times["simulation_s"] for key in WRITINGS}


def chart(report: dict, path: Path) -> None:
    """Bars: the simulation's and each figure writing's wall time."""
    times = report["figures"]
    fig, ax = subplots(1, 1, (6.5, 3.5))
    labels = {"simulation_s": "simulation", "default_png_s": "figures: default set, PNG",
              "all_png_s": "figures: all, PNG", "all_png_pdf_s": "figures: all, PNG + PDF"}
    ax.barh(list(labels.values()), [times[key] for key in labels])
    ax.set_xlabel(f"wall time (s), best of {report['settings']['repeats']}")
    ax.set_title("Default scene: figures against the simulation")
    save(fig, path)
