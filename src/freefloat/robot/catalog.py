"""Robots by name: freefloat's own (``urdf/``) and example-robot-data's, so that
``load_robot("ur5")`` or ``freefloat simulate --robot solo12`` needs no path.

A name is a URDF file's stem (``solo12``, ``talos_full_v2``, ``four_arm_planar``); a stem ending
in ``_robot`` answers to the name without it too (``ur5_robot`` -> ``ur5``), and ``talos`` to
``talos_reduced`` (said in a :class:`~freefloat.errors.FreefloatNote`: example-robot-data has
several TALOS files). freefloat's own robots come first; ``freefloat robots`` lists them all.
"""

from __future__ import annotations

import functools
import importlib.metadata
import warnings
from pathlib import Path

from ..errors import FreefloatNote, RobotModelError, did_you_mean
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

    A name that is no file's stem (:data:`ALIASES`) picks one file of several: which one is said
    in a :class:`~freefloat.errors.FreefloatNote`.

    Raises:
        RobotModelError: for an unknown name, with the nearest known names
            (:func:`~freefloat.errors.did_you_mean`).
    """
    known = robots()
    if name in known:
        if name in ALIASES:
            others = [n for n in known if n.startswith(name) and known[n] != known[name]]
            warnings.warn(f"robot '{name}' is {known[name].name}" + (f" (others: {', '.join(others)})" if others else ""),
                          FreefloatNote, stacklevel=3)
        return known[name]
    raise RobotModelError(f"'{name}' is neither a URDF file nor a known robot"
                          f"{did_you_mean(name, known, 'known', 'freefloat robots')}")


def is_name(value: str | Path) -> bool:
    """True when ``value`` looks like a robot name rather than a path (no folder, no suffix)."""
    text = str(value)
    return "/" not in text and "\\" not in text and not Path(text).suffix
