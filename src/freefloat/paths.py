"""Where freefloat finds its built-in robots and scenes."""

from __future__ import annotations

from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
#: Built-in scenes (TOML), shipped inside the package.
SCENES_DIR = PACKAGE_DIR / "app" / "scenes"
#: The repository's generated URDFs (``urdf/`` at the top of a clone; editable install).
URDF_DIR = PACKAGE_DIR.parents[1] / "urdf"
