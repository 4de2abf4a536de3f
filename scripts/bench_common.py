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
