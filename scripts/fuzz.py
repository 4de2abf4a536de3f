"""The whole fuzz corpus, counted by class and outcome (tests/fuzz_corpus.py): mutated URDFs,
scenes and closure files through ``freefloat simulate``; output folders holding a user's files or
symbolic links; URL textures in pages; signals at checkpoints; Python API calls with hostile
arguments. A good outcome is a completed run, a run stopped early with its partial results (exit
1) or a clean refusal (exit 2, or one of freefloat's errors); anything else (a traceback, a hang
over the time bound, a crash of the process, a non-finite result, a file outside the run folder,
a user's file or a link's target changed, a URL in a page, a corrupted folder, a rerun that
fails, a plainly wrong argument accepted) is a failure, listed with its seed and mutation. Writes
counts.json and failures.json to runs/fuzz-<time>/ and exits 1 when any case failed.

    python3 scripts/fuzz.py [--urdfs 1000] [--scenes 1000] [--folders 300] [--links 300]
        [--textures 300] [--signals 60] [--api 1000] [--first-seed 0] [--workers 2]
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import sys
import tempfile
import threading
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.fuzz_corpus import CLASSES, GOOD  # noqa: E402
from tests.fuzzing import TIME_BOUND  # noqa: E402

#: Cases per class by default (a signal case starts a process and reruns it: a few seconds each).
SIZES = {"urdf": 1000, "scene": 1000, "folders": 300, "links": 300, "textures": 300, "signals": 60, "api": 1000}
#: Flag of each class.
FLAGS = {"urdf": "urdfs", "scene": "scenes", "folders": "folders", "links": "links", "textures": "textures",
         "signals": "signals", "api": "api"}


def one(kind: str, seed: int, root: str) -> tuple[str, int, str, str, str]:
    """Run one case in a worker process: (kind, seed, mutation, outcome, detail). A case stuck
    where no Python handler can reach it (compiled code) ends the worker after three time bounds,
    which counts as a crash."""
    warnings.simplefilter("ignore")
    watchdog = threading.Timer(3 * TIME_BOUND, os._exit, (3,))
    watchdog.daemon = True
    watchdog.start()
    try:
        case = CLASSES[kind](seed)
        outcome, detail = case.run(Path(root) / f"{kind}-{seed}")
    finally:
        watchdog.cancel()
    return kind, seed, case.mutation, outcome, detail


def run_all(jobs: list[tuple[str, int]], root: str, workers: int) -> list[tuple[str, int, str, str, str]]:
    """Every job through a pool of processes; a job that kills its process is a 'crash'."""
    results, pending = [], list(jobs)
    while pending:
        batch, pending = pending[:200], pending[200:]
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = {pool.submit(one, kind, seed, root): (kind, seed) for kind, seed in batch}
            broken = []
            for future, (kind, seed) in futures.items():
                try:
                    results.append(future.result())
                except BrokenProcessPool:
                    broken.append((kind, seed))
        for kind, seed in broken:  # alone, to tell the crashing case from its neighbours
            with ProcessPoolExecutor(max_workers=1) as pool:
                try:
                    results.append(pool.submit(one, kind, seed, root).result())
                except BrokenProcessPool:
                    results.append((kind, seed, CLASSES[kind](seed).mutation, "crash", "the process died"))
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    for kind, flag in FLAGS.items():
        parser.add_argument(f"--{flag}", type=int, default=SIZES[kind], help=f"{kind} cases (default {SIZES[kind]})")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    out = Path("runs") / f"fuzz-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    sizes = {kind: getattr(args, flag) for kind, flag in FLAGS.items()}
    jobs = [(kind, seed) for kind, n in sizes.items() for seed in range(args.first_seed, args.first_seed + n)]
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as root:
        results = run_all(jobs, root, args.workers)
    counts = {kind: dict(collections.Counter(r[3] for r in results if r[0] == kind)) for kind in CLASSES if sizes[kind]}
    failures = [dict(zip(("kind", "seed", "mutation", "outcome", "detail"), r)) for r in results if r[3] not in GOOD]
    (out / "counts.json").write_text(json.dumps({"cases": len(results), "counts": counts, "failures": len(failures),
                                                 "first_seed": args.first_seed, "seconds": time.perf_counter() - start},
                                                indent=2))
    (out / "failures.json").write_text(json.dumps(failures, indent=2))
    print(f"{len(results)} cases in {time.perf_counter() - start:.0f} s -> {out}")
    for kind, by_outcome in counts.items():
        print(f"  {kind}: " + ", ".join(f"{k} {v}" for k, v in sorted(by_outcome.items())))
    for failure in failures[:20]:
        print(f"  FAILED {failure['kind']} seed {failure['seed']} ({failure['mutation']}): "
              f"{failure['outcome']}: {failure['detail'][:200]}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
