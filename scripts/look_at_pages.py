"""Look at run pages headlessly: coverage, extent and motion (start against halfway: a periodic
motion is back at its start at the end) of each run's trajectory.html, plus its pictures at the
start and halfway, into runs/look-<time>/ (needs Chromium).

    python3 scripts/look_at_pages.py runs/four_arm_joint_space-... runs/satellite_dual_arm-...
"""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
from bench_common import parser, write_json

from freefloat.app.viz.meshcat_html import read_settings
from freefloat.app.viz.screenshot import look, render


def main() -> None:
    args = parser(__doc__, "look")
    args.add_argument("runs", nargs="+", type=Path, help="run folders holding trajectory.html")
    options = args.parse_args()
    report = {}
    for run in options.runs:
        page = run / "trajectory.html"
        settings = read_settings(page)
        start, halfway = settings["t0"], settings["t0"] + settings["duration"] / 2
        report[run.name] = {"page_bytes": page.stat().st_size, **look(page, start, halfway)}
        for label, time in (("start", start), ("halfway", halfway)):
            options.out.mkdir(parents=True, exist_ok=True)
            matplotlib.image.imsave(options.out / f"{run.name}_{label}.png", render(page, f"t={time}"))
        print(run.name, report[run.name])
    print("wrote", write_json(options.out, "look", {"pages": report}))


if __name__ == "__main__":
    main()
