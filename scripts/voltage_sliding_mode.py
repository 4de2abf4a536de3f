"""Sliding mode with the motors' voltage as the control input (thesis proposal sec 9, items 10-11):
the study ``freefloat reproduce voltage_sliding`` (:mod:`freefloat.lab.reproduce.voltage_sliding_report`),
plus the 5R's current-loop bandwidth sweep.

    python3 scripts/voltage_sliding_mode.py [--quick] [--out DIR] [--sweep 2000 5000]

writes the study's ``report.json``, ``report.md`` and ``errors.png`` into DIR and, with ``--sweep``,
``sweep.json``: the 5R's voltage-input sliding mode at those current-loop bandwidths (1/s).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from freefloat.lab.reproduce.voltage_sliding_report import reproduce, sweep


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the 5R alone, 0.25 s")
    parser.add_argument("--out", type=Path, default=Path("voltage_sliding_mode"))
    parser.add_argument("--sweep", type=float, nargs="*", default=(), help="the 5R's bandwidths to sweep, 1/s")
    args = parser.parse_args()
    reproduce(args.out, args.quick)
    print((args.out / "report.md").read_text())
    if args.sweep:
        rows = sweep(list(args.sweep))
        (args.out / "sweep.json").write_text(json.dumps(rows, indent=1))
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
