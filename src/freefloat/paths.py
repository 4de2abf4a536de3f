"""Where freefloat finds its built-in robots, mechanisms and scenes: inside the installed
package (``freefloat/urdf``, ``freefloat/app/scenes``), so that editable and wheel installs
alike find them. The repository's top-level ``urdf`` is a link to the same folder."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

PACKAGE_DIR = Path(str(files("freefloat")))
#: Built-in scenes (TOML).
SCENES_DIR = PACKAGE_DIR / "app" / "scenes"
#: Built-in robots and mechanisms: URDFs, closure files, the 2RSU+PPaP's data file.
URDF_DIR = PACKAGE_DIR / "urdf"
