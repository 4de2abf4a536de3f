"""What the benchmark scripts share: a best-of-N timer, the command line, the JSON record."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Callable

import numpy as np

from freefloat.app.outputs import versions


def per_call(fn: Callable[[], object], calls: int, repeats: int = 5) -> float:
    """Best-of-``repeats`` mean time of ``fn()`` over ``calls`` calls, s."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def side_by_side(fns: dict[str, tuple[Callable[[], object], int]], repeats: int = 7) -> dict[str, float]:
    """Best-of-``repeats`` mean time per call, s, of each ``name: (fn, calls)``, the functions
    taking turns within each repeat so that load from other processes falls on all of them alike."""
    best = {name: np.inf for name in fns}
    for _ in range(repeats):
        for name, (fn, calls) in fns.items():
            start = time.perf_counter()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (time.perf_counter() - start) / calls)
    return best


def parser(description: str, name: str) -> argparse.ArgumentParser:
    """A parser with ``--out`` (default ``runs/bench-<name>-<time>``)."""
    out = argparse.ArgumentParser(description=description.splitlines()[0])
    out.add_argument("--out", type=Path, default=Path("runs") / f"bench-{name}-{time.strftime('%Y%m%d-%H%M%S')}")
    return out


def write_json(out: Path, name: str, report: dict) -> Path:
    """Stamp ``versions`` on ``report`` and write it as ``<out>/bench_<name>.json``."""
    report["versions"] = versions()
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"bench_{name}.json"
    path.write_text(json.dumps(report, indent=2))
    return path


#: Arm counts of the size sweeps (4 joints per arm: 8 to 64 joints).
ARM_COUNTS = (2, 4, 8, 16)


def multi_arm_robot(arms: int, folder: Path):
    """A free-floating robot with ``arms`` spatial 4-link arms evenly around a 10 kg base (links
    0.5 m, 2 kg, DH twists 90, 0, 90, 0 deg), written as URDF to ``folder`` and loaded."""
    import math
    import warnings

    from freefloat import load_robot
    from freefloat.robot.builders import ArmSpec, LinkSpec, RobotSpec, write_urdf

    links = tuple(LinkSpec(0.5, 2.0, (0.01, 0.05, 0.05), alpha=alpha) for alpha in (math.pi / 2, 0.0, math.pi / 2, 0.0))
    yaws = [2 * math.pi * i / arms for i in range(arms)]
    spec = RobotSpec(f"arms{arms}", 10.0, (0.6, 0.6, 0.6), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), tuple(
        ArmSpec(f"arm{i}", (0.5 * math.cos(y), 0.5 * math.sin(y), 0.0), (0.0, 0.0, y), links) for i, y in enumerate(yaws)))
    path = write_urdf(spec, folder / f"arms{arms}.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(path, visuals=False)


def growth_axes(ax, ylabel: str) -> None:
    """Finish an axis of a size sweep: joints on a log2 scale, ``ylabel``, title and legend."""
    ax.set_xscale("log", base=2)
    ax.set_xlabel("joints (4 per arm: 2, 4, 8, 16 arms)")
    ax.set_ylabel(ylabel)
    ax.set_title("growth with robot size")
    ax.legend(fontsize=8)


def save_chart(fig, path: Path) -> None:
    """Lay out, write (120 dpi) and close a matplotlib figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
