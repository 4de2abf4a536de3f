"""Benchmark: the cost of writing a run's figures beside the simulation itself (default scene,
four-arm robot, 5 s at 1 ms), best of three, side by side in one process. JSON + chart in
runs/bench-figures-<time>/."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from bench_common import parser, write_json
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from freefloat import simulate
from freefloat import find_scene
from freefloat.app.viz import plotting


def best_of(fn, repeats: int = 3) -> float:
    """Best wall time of ``fn()`` over ``repeats`` calls, s."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    options = parser(__doc__, "figures").parse_args()
    scene = find_scene("four_arm_joint_space")
    outcome = simulate(scene)
    report = {"simulation_s": best_of(lambda: simulate(scene), repeats=1)}
    with tempfile.TemporaryDirectory() as folder:
        report["figures_png_pdf_s"] = best_of(lambda: outcome.figures(Path(folder)))
        formats, plotting.FORMATS = plotting.FORMATS, ("png",)
        report["figures_png_s"] = best_of(lambda: outcome.figures(Path(folder)))
        plotting.FORMATS = formats
    report["figures_over_simulation"] = report["figures_png_pdf_s"] / report["simulation_s"]
    path = write_json(options.out, "figures", report)
    fig = Figure(figsize=(6.0, 3.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    labels = ["simulation", "figures PNG + PDF", "figures PNG"]
    ax.barh(labels, [report["simulation_s"], report["figures_png_pdf_s"], report["figures_png_s"]])
    ax.set_xlabel("wall time (s), best of 3")
    ax.set_title("Default scene: figures against the simulation")
    fig.subplots_adjust(left=0.3, bottom=0.18)
    fig.savefig(options.out / "bench_figures.png", dpi=120)
    print(report, "\nwrote", path)


if __name__ == "__main__":
    main()
