"""The numbers of docs/identification.md: the study ``freefloat reproduce identification``
(:mod:`freefloat.lab.reproduce.identification_report`) into runs/identification-<time>/.

    python3 scripts/identification.py [--quick]   # --quick: the robot and the 5R, 20 Monte-Carlo draws instead of 200
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from freefloat.lab.reproduce.identification_report import reproduce


def main(argv: list[str]) -> int:
    out = Path("runs") / f"identification-{time.strftime('%Y%m%d-%H%M%S')}"
    reproduce(out, "--quick" in argv)
    print((out / "report.md").read_text())
    print(f"wrote {out / 'report.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
