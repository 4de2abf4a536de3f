"""What the report of ``freefloat reproduce all`` reads: the studies' folders (one per study,
named after it) and the provenance of the build (commit, versions, settings)."""

from __future__ import annotations

import json
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ....errors import FreefloatError, spelled
from ....paths import PACKAGE_DIR


class MissingStudy(FreefloatError):
    """An entry needs a study whose output is not in the folder (not run, or interrupted)."""


@dataclass
class Results:
    """The studies' outputs under ``root``: ``root/<study>/report.json`` and the ``.npz`` files
    a study saved there; each read once."""

    root: Path
    _cache: dict = field(default_factory=dict)

    def report(self, study: str) -> dict:
        """``<study>/report.json``.

        Raises:
            MissingStudy: naming the study when its report is not there.
        """
        key = (study, "report.json")
        if key not in self._cache:
            path = self.root / study / "report.json"
            if not path.is_file():
                raise MissingStudy(f"study '{study}' has no report in {self.root / study} (not run, or interrupted); "
                                   "rerun the same command to finish it")
            self._cache[key] = json.loads(path.read_text())
        return self._cache[key]

    def arrays(self, study: str, name: str) -> dict[str, np.ndarray]:
        """The arrays of ``<study>/<name>.npz``.

        Raises:
            MissingStudy: naming the file when it is not there.
        """
        key = (study, name)
        if key not in self._cache:
            path = self.root / study / f"{name}.npz"
            if not path.is_file():
                raise MissingStudy(f"'{path}' is missing (study '{study}' not run, interrupted, or from an older "
                                   f"freefloat); rerun with {spelled('overwrite=True', '--overwrite')} to remake it")
            with np.load(path) as data:
                self._cache[key] = {k: data[k] for k in data.files}
        return self._cache[key]


def commit() -> str:
    """The git commit of the freefloat source tree (``+ local changes`` when it differs from the
    commit), or why it is not known (installed from a wheel, git missing)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=PACKAGE_DIR, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", "."], cwd=PACKAGE_DIR,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown (not a git checkout, or git not available)"
    return head + (" + local changes to src/freefloat" if dirty else "")
