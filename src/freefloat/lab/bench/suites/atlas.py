"""``atlas`` suite: a 2-D workspace-and-singularity map of the four-arm robot's arm (issue 21's
aim: 200 x 200 points in under 10 s on 2 cores), against the same number of ``gjm.compute`` calls.

Measured in this process, side by side:

- ``evaluate``: the ``singularities`` kind's chunk evaluator over the whole grid in one call (per
  point: the compiled GJM core, the J* and Jm blocks; per chunk: one batched SVD of each), and
  ``gjm_compute``: as many :func:`freefloat.gjm.compute` calls at one state (best of ``repeats``,
  taking turns), and their ratio;
- ``command``: ``run_atlas`` end to end (kind resolved, robot loaded, chunks journaled, atlas.npz,
  summary and the figures written) in this process alone and with ``--workers 2`` (this process
  and a pool of one, which takes chunks once its interpreter has started), once each.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ....app.atlas import singularities
from ....app.atlas.arm_maps import robot_of
from ....app.atlas.engine import run_atlas
from ....app.atlas.kinds import Options
from ....app.batch import Workers
from ....dynamics import gjm
from .drawing import save, subplots
from .timing import side_by_side

ROBOT, AXES = "four_arm_planar", ("arm1_joint2", "arm1_joint3")


def settings(quick: bool, repeats: int | None) -> dict:
    """Points per axis (200, 40 quick), repeats of the evaluation (3, 1 quick)."""
    return {"robot": ROBOT, "axes": list(AXES), "grid": 40 if quick else 200, "repeats": repeats or (1 if quick else 3)}


def measure(settings: dict) -> Iterator[tuple[str, dict]]:
    """``evaluate`` then ``command`` (see the module's docstring)."""
    options = Options(grid=settings["grid"], axes=tuple(settings["axes"]))
    context = singularities.prepare(settings["robot"], options)
    points = singularities.grid(context, options).points()
    robot = robot_of(context.target, context.base)
    model, q, v = gjm.model_of(robot), robot.neutral(), np.zeros(robot.model.nv)
    times = side_by_side({"evaluate": (lambda: singularities.evaluate(context, points), 1),
                          "gjm_compute": (lambda: model.compute(q, v), len(points))}, settings["repeats"])
    times["gjm_compute"] *= len(points)  # per call -> the grid's count
    yield "evaluate", {"points": len(points), "seconds": times,
                       "per_point_us": {k: t / len(points) * 1e6 for k, t in times.items()},
                       "evaluate_over_gjm_compute": times["evaluate"] / times["gjm_compute"]}
    command = {}
    with tempfile.TemporaryDirectory() as folder:
        for label, workers in (("serial", Workers(1)), ("pool_of_2", Workers(2))):
            start = time.perf_counter()
            done = run_atlas("singularities", settings["robot"], options, Path(folder) / label, workers)
            command[label] = {"seconds": time.perf_counter() - start,
                              "singular_share_free": done.summary["summary"]["singular_share_free"]}
    yield "command", {"points": len(points), **command}


def chart(report: dict, path: Path) -> None:
    """Left: seconds of the evaluation against the same number of gjm.compute calls; right: the
    command end to end, serial and on 2 processes."""
    fig, (left, right) = subplots(1, 2, (11, 4))
    evaluation = report["evaluate"]["seconds"]
    left.bar(list(evaluation), list(evaluation.values()), color=["#1f77b4", "0.6"])
    left.set_ylabel("seconds")
    left.set_title(f"{report['evaluate']['points']} points: map vs gjm.compute "
                   f"({report['evaluate']['evaluate_over_gjm_compute']:.2f}x)")
    command = {k: v["seconds"] for k, v in report["command"].items() if isinstance(v, dict)}
    right.bar(list(command), list(command.values()), color=["#1f77b4", "#2ca02c"])
    right.axhline(10.0, color="#d62728", ls="--", label="aim: 10 s")
    right.set_ylabel("seconds")
    right.set_title("freefloat atlas singularities, end to end")
    right.legend(fontsize=8)
    save(fig, path)
