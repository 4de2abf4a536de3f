"""``freefloat reproduce``: the command's arguments and its run (registered by :mod:`freefloat.lab.plugin`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ...app.commands import Command
from ...app.shown_warnings import shown_warnings
from . import ALL_STUDIES, STUDIES


def arguments(parser: argparse.ArgumentParser) -> None:
    """The command's arguments; the studies' names and help come from their registry."""
    parser.add_argument("study", choices=[*STUDIES, ALL_STUDIES],
                        help="; ".join(f"{name}: {study.help}" for name, study in STUDIES.items())
                             + f"; {ALL_STUDIES}: every study, then one report of both documents (HTML and PDF)")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default: runs/reproduce-<study>-<time>)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace the study freefloat wrote in --out (default: continue it from its journal; a "
                             "folder holding other files is refused)")
    parser.add_argument("--quick", action="store_true", help="short runs and few samples (a smoke test)")
    parser.add_argument("--workers", type=int, default=2,
                        help="parallel processes (default 2; at most the machine's cores, see --force-workers)")
    parser.add_argument("--force-workers", action="store_true",
                        help="start --workers processes even beyond the cores (they take turns)")
    parser.add_argument("--runs", type=int, default=None,
                        help="robustness: Monte-Carlo runs (default 20, 2 with --quick)")
    parser.add_argument("--error", type=float, default=0.5,
                        help="robustness: parameter error band (default 0.5 = 50 %%)")
    parser.add_argument("--scheduler", default=None,
                        help="robustness: Dask scheduler address (default: a local cluster)")


def run(args: argparse.Namespace) -> int:
    """One study into its folder, or ``all`` of them into one folder each plus the report
    (:mod:`~.folders`)."""
    from ...app.batch.executors import Workers
    from .folders import run_all, run_study

    workers = Workers(args.workers, dask=args.scheduler is not None, scheduler=args.scheduler,
                      force=args.force_workers)  # refused as batch refuses it
    options = {"workers": workers.count, "runs": args.runs, "relative_error": args.error,
               "scheduler": args.scheduler}
    out = args.out or Path("runs") / f"reproduce-{args.study}-{time.strftime('%Y%m%d-%H%M%S')}"
    if args.study == ALL_STUDIES:
        start = time.perf_counter()
        with shown_warnings() as held:
            held.release()  # a study's warnings are shown as they come, beside its progress lines
            run_all(out, args.overwrite, args.quick, options)
        print(f"wrote {out / 'report.html'} and {out / 'report.pdf'} in {time.perf_counter() - start:.0f} s")
        return 0
    with shown_warnings() as held:
        held.release()
        report = run_study(args.study, out, args.overwrite, args.quick, options)
    print((out / "report.md").read_text())
    print(f"wrote {out} in {report['wall_time_s']:.0f} s")
    return 0


REPRODUCE = Command("reproduce", "reproduce a study of the documents against the exact reference", arguments, run,
                    heavy="freefloat.app.runner")
