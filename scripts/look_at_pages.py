"""Look at run pages headlessly: coverage, extent and motion (start against halfway: a periodic
motion is back at its start at the end) of each run's trajectory.html, plus its pictures at the
start and halfway, into runs/look-<time>/ (needs Chromium).

    python3 scripts/look_at_pages.py runs/four_arm_joint_space-... runs/satellite_dual_arm-...
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib.image

from freefloat.app.outputs import strict_json, versions
from freefloat.app.viz.meshcat_html import read_settings
from freefloat.app.viz.screenshot import look, render


def main() -> None:
    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--out", type=Path, default=Path("runs") / f"look-{time.strftime('%Y%m%d-%H%M%S')}")
    args.add_argument("runs", nargs="+", type=Path, help="run folders holding trajectory.html")
    options = args.parse_args()
    options.out.mkdir(parents=True, exist_ok=True)
    report = {}
    for run in options.runs:
        page = run / "trajectory.html"
        settings = read_settings(page)
        start, halfway = settings["t0"], settings["t0"] + settings["duration"] / 2
        report[run.name] = {"page_bytes": page.stat().st_size, **look(page, start, halfway)}
        for label, moment in (("start", start), ("halfway", halfway)):
            matplotlib.image.imsave(options.out / f"{run.name}_{label}.png", render(page, f"t={moment}"))
        print(run.name, report[run.name])
    (options.out / "look.json").write_text(strict_json({"pages": report, "versions": versions()}))
    print("wrote", options.out / "look.json")


if __name__ == "__main__":
    main()
