"""The default output folder of a run, batch or bench: ``runs/<name>-<time>``."""

from __future__ import annotations

import re
import time
from pathlib import Path

#: Longest scene-derived part of a default output folder's name.
MAX_FOLDER_NAME = 80


def default_folder(scene_name: str) -> Path:
    """``runs/<scene name>-<time>``, the name reduced to one safe path component (a scene name
    such as ``../../x`` or ``/abs`` cannot write elsewhere) of at most :data:`MAX_FOLDER_NAME`
    characters (a file system refuses longer names), numbered on a clash."""
    safe = re.sub(r"[^A-Za-z0-9._-]+", "_", scene_name)[:MAX_FOLDER_NAME].strip("._") or "scene"
    base = Path("runs") / f"{safe}-{time.strftime('%Y%m%d-%H%M%S')}"
    folder, n = base, 1
    while folder.exists():
        n += 1
        folder = base.with_name(f"{base.name}-{n}")
    return folder
