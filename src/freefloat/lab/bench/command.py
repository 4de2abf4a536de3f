"""``freefloat bench``: the command's arguments and its run (registered by :mod:`freefloat.lab.plugin`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from ...app.commands import Command
from ...app.folder_names import default_folder
from ...app.shown_warnings import HeldWarnings, shown_warnings


def arguments(parser: argparse.ArgumentParser) -> None:
    """The command's arguments; the suites' and scenes' names and help come from their registries."""
    from .scenes import SCENES
    from .suites import ALL, DEFAULT, SUITES

    default = [entry.name for entry in SCENES.values() if entry.default]
    others = [entry.name for entry in SCENES.values() if not entry.default]
    parser.add_argument("scenes", nargs="*", metavar="SCENE",
                        help=f"the {DEFAULT} suite's scenes: {', '.join(default)} (default: these {len(default)}), "
                             f"and {', '.join(others)}")
    parser.add_argument("--suite", nargs="+", default=None, metavar="NAME",
                        help="; ".join(f"{name}: {suite.help}" for name, suite in SUITES.items()).replace("%", "%%")
                             + f"; {ALL}: every suite (default: {DEFAULT})")
    parser.add_argument("--quick", action="store_true", help="a few points, short runs, one repeat (a smoke test)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="repeats of each measurement (default: each suite's own, fewer with --quick)")
    parser.add_argument("--out", type=Path, default=None,
                        help="output folder (default: runs/bench-<time>; with --suite, runs/bench-<names>-<time>)")


def run(args: argparse.Namespace) -> int:
    """The suites into one folder; 1 when one stopped early (what it measured is kept)."""
    from .options import Options
    from .suites import DEFAULT, run_suites

    out = args.out or default_folder("-".join(["bench", *(args.suite or ())]))
    with shown_warnings() as held:
        ended = run_suites(out, args.suite or [DEFAULT], Options(args.quick, args.repeats, tuple(args.scenes)),
                           _released(held, print))
    print("\n".join(line for suite in ended for line in suite.lines))
    print(f"written to {out}")
    if ended[-1].status != "completed":
        print(f"freefloat: bench stopped early: {ended[-1].status} (what was measured is kept in {out})",
              file=sys.stderr)
        return 1
    return 0


def _released(held: HeldWarnings, show: Callable[[str], None]) -> Callable[[str], None]:
    """``show`` that first releases the held warnings (its first line means the command is past
    its checks)."""
    def show_line(line: str) -> None:
        held.release()
        show(line)

    return show_line


BENCH = Command("bench", "speed side by side in one process: freefloat against MuJoCo per scene, or a suite of "
                         "measurements (--suite)", arguments, run, heavy="freefloat.app.runner")
