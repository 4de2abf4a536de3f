"""A toy atlas kind for the engine's tests: f(x, y) = x^2 + 10 y on a grid over [0, 1]^2, with
its gradient as a trailing-shape array and the id of the process that evaluated each point; the
target ``"slow"`` takes 0.2 s a chunk (registered by tests/test_atlas_engine.py)."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from freefloat.app.atlas.grid import Axis, Grid
from freefloat.app.atlas.kinds import Options

OPTIONS = frozenset({"grid"})


@dataclass(frozen=True)
class Toy:
    target: str


def prepare(target: str, options: Options) -> Toy:
    return Toy(target)


def grid(context: Toy, options: Options) -> Grid:
    n = options.grid or 7
    return Grid((Axis("x", 0.0, 1.0, n, "m"), Axis("y", 0.0, 1.0, n + 1, "m")))


def evaluate(context: Toy, points: np.ndarray) -> dict[str, np.ndarray]:
    if context.target == "slow":
        time.sleep(0.2)
    x, y = points.T
    return {"f": x**2 + 10 * y, "gradient": np.column_stack((2 * x, np.full_like(y, 10.0))),
            "process": np.full(len(points), os.getpid())}


def summarise(context: Toy, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    return {"max_f": float(result["f"].max()), "target": context.target}


def figures(context: Toy, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    path = out / "toy.txt"
    path.write_text("a figure")
    return [path]
