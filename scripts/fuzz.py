"""The whole fuzz corpus: mutated URDFs, scenes and closure files run through ``freefloat
simulate``, counted by outcome. A good outcome is a completed run, a run stopped early with its
partial results (exit 1) or a clean refusal (exit 2); anything else (a traceback, a hang over the
time bound, a crash of the process, a non-finite result, a file outside the run folder) is a
failure, listed with its seed and mutation. Writes counts.json and failures.json to
runs/fuzz-<time>/ and exits 1 when any case failed.

    python3 scripts/fuzz.py [--urdfs 1000] [--scenes 1000] [--first-seed 0] [--workers 2]
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.fuzzing import GOOD, run_case, scene_case, urdf_case  # noqa: E402

MAKERS = {"urdf": urdf_case, "scene": scene_case}


def one(kind: str, seed: int, root: str) -> tuple[str, int, str, str, str]:
    """Run one case in a worker process: (kind, seed, mutation, outcome, detail)."""
    warnings.simplefilter("ignore")
    case = MAKERS[kind](seed)
    outcome, detail = run_case(case, Path(root) / f"{kind}-{seed}")
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
                    results.append((kind, seed, MAKERS[kind](seed).mutation, "crash", "the process died"))
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--urdfs", type=int, default=1000)
    parser.add_argument("--scenes", type=int, default=1000)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    out = Path("runs") / f"fuzz-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    seeds = range(args.first_seed, args.first_seed + max(args.urdfs, args.scenes))
    jobs = [("urdf", s) for s in seeds[: args.urdfs]] + [("scene", s) for s in seeds[: args.scenes]]
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as root:
        results = run_all(jobs, root, args.workers)
    counts = {kind: dict(collections.Counter(r[3] for r in results if r[0] == kind)) for kind in MAKERS}
    failures = [dict(zip(("kind", "seed", "mutation", "outcome", "detail"), r)) for r in results if r[3] not in GOOD]
    (out / "counts.json").write_text(json.dumps({"cases": len(results), "counts": counts, "failures": len(failures),
                                                 "seconds": time.perf_counter() - start}, indent=2))
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
