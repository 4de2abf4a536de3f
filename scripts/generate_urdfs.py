"""Regenerate the committed URDF files in ``urdf/`` from ``freefloat.robot.builders``.

Usage: ``python3 scripts/generate_urdfs.py [output_dir]`` (default: the repository's ``urdf/``).
``tests/test_builders.py`` checks that the committed files equal what this script writes.
"""

from __future__ import annotations

import sys
from pathlib import Path

from freefloat.parallel.five_bar import five_bar_spec
from freefloat.parallel.rsu_ppap import load_data, rsu_ppap_urdf
from freefloat.parallel.three_rrr import three_rrr_spec
from freefloat.paths import URDF_DIR
from freefloat.robot.builders import (
    build_urdf,
    dual_arm_satellite,
    four_arm_planar,
    two_arm_planar,
    write_urdf,
)


def main(out_dir: Path = URDF_DIR) -> None:
    """Write the four-arm, two-arm, dual-arm-satellite, 5R, 2RSU+PPaP and 3-RRR spanning-tree URDFs into
    ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    robots = {
        "four_arm_planar.urdf": build_urdf(four_arm_planar()),
        "two_arm_planar.urdf": build_urdf(two_arm_planar()),
        "dual_arm_satellite.urdf": dual_arm_satellite(),
        "five_bar.urdf": build_urdf(five_bar_spec()),
        "rsu_ppap.urdf": rsu_ppap_urdf(load_data()),
        "three_rrr.urdf": build_urdf(three_rrr_spec()),
    }
    for name, urdf in robots.items():
        print(write_urdf(urdf, out_dir / name))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else URDF_DIR)
