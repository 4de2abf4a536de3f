"""Robots by name: freefloat's own (``urdf/``) and example-robot-data's, so that
``load_robot("ur5")`` or ``freefloat simulate --robot solo12`` needs no path.

A name is a URDF file's stem (``solo12``, ``talos_full_v2``, ``four_arm_planar``); a stem ending
in ``_robot`` answers to the name without it too (``ur5_robot`` -> ``ur5``), and ``talos`` to
``talos_reduced``. freefloat's own robots come first.
"""

from __future__ import annotations

import functools
import importlib.metadata
from pathlib import Path

from ..errors import RobotModelError
from ..paths import URDF_DIR

#: Names that are no file's stem.
ALIASES = {"talos": "talos_reduced"}


@functools.cache
def example_robot_data_share() -> Path | None:
    """The ``share`` folder of the installed example-robot-data, for ``package://`` paths."""
    try:
        share = importlib.metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share")
    except importlib.metadata.PackageNotFoundError:
        return None
    return Path(str(share)) if Path(str(share)).is_dir() else None


@functools.cache
def robots() -> dict[str, Path]:
    """Every robot freefloat knows by name, and its URDF."""
    files = sorted(URDF_DIR.glob("*.urdf"))
    if (share := example_robot_data_share()) is not None:
        files += sorted((share / "example-robot-data" / "robots").rglob("*.urdf"))
    found: dict[str, Path] = {}
    for path in files:
        found.setdefault(path.stem, path)
        if path.stem.endswith("_robot"):
            found.setdefault(path.stem[: -len("_robot")], path)
    for alias, stem in ALIASES.items():
        if stem in found:
            found.setdefault(alias, found[stem])
    return found


def find_robot(name: str) -> Path:
    """The URDF of the robot called ``name``.

    Raises:
        RobotModelError: for an unknown name, listing the close ones (or all).
    """
    known = robots()
    if name in known:
        return known[name]
    close = [n for n in known if name.lower() in n.lower()] or list(known)
    raise RobotModelError(f"'{name}' is neither a URDF file nor a known robot; known: {', '.join(close)}")


def is_name(value: str | Path) -> bool:
    """True when ``value`` looks like a robot name rather than a path (no folder, no suffix)."""
    text = str(value)
    return "/" not in text and "\\" not in text and not Path(text).suffix
