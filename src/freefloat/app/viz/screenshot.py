"""Looking at a page: render it headlessly with Chromium and measure what the picture shows.

Chromium (Debian: ``apt-get install chromium``) renders meshcat pages with its software GL
(SwiftShader). The page's fragment (see :mod:`.page_template`) pauses the animation at a time
or hides the run, so two renders of one page differ only in what is asked. Pictures are
(height, width, 3) RGB arrays in [0, 1].
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

#: Browser executables tried in turn.
BROWSERS = ("chromium", "chromium-browser", "google-chrome")
#: Picture size, px (width, height), and the height of the page's control bar at the bottom.
SIZE = (1280, 800)
CONTROL_BAR = 40
#: Virtual time Chromium gives the page before the picture, ms (above ~5000 ms it hangs).
BUDGET_MS = 4000
#: A pixel changed when one of its channels moved by more than this.
THRESHOLD = 0.05


def browser() -> str | None:
    """Path of an installed Chromium, or None."""
    return next((path for name in BROWSERS if (path := shutil.which(name))), None)


def render(page: str | Path, fragment: str = "", timeout: float = 120.0) -> np.ndarray:
    """Render ``page`` (with ``#fragment``, e.g. ``"t=1.5"`` or ``"t=0&hide"``) to a picture
    without the control bar (H, W, 3).

    Raises:
        RuntimeError: when no browser is installed, or naming the page when it renders nothing.
    """
    import matplotlib.image

    executable = browser()
    if executable is None:
        raise RuntimeError("no Chromium found (Debian: apt-get install chromium)")
    with tempfile.TemporaryDirectory() as folder:
        png = Path(folder) / "page.png"
        url = Path(page).resolve().as_uri() + (f"#{fragment}" if fragment else "")
        subprocess.run(
            [executable, "--headless", "--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
             f"--user-data-dir={folder}/profile", f"--screenshot={png}", f"--window-size={SIZE[0]},{SIZE[1]}",
             f"--virtual-time-budget={BUDGET_MS}", url],
            check=False, capture_output=True, timeout=timeout)
        if not png.is_file():
            raise RuntimeError(f"{page}: Chromium wrote no picture")
        picture = matplotlib.image.imread(png)[..., :3]
    return picture[:-CONTROL_BAR]


def changed(a: np.ndarray, b: np.ndarray) -> float:
    """Fraction of pixels that differ between two pictures of one size."""
    return float(np.mean(np.abs(a - b).max(axis=2) > THRESHOLD))


def extent(a: np.ndarray, b: np.ndarray) -> float:
    """Area of the box around the changed pixels, as a fraction of the picture (0 if none)."""
    rows, cols = np.nonzero(np.abs(a - b).max(axis=2) > THRESHOLD)
    if len(rows) == 0:
        return 0.0
    return float((np.ptp(rows) + 1) * (np.ptp(cols) + 1) / (a.shape[0] * a.shape[1]))


def look(page: str | Path, start: float, end: float) -> dict[str, float]:
    """What a page shows, comparing renders at ``start`` with the run shown and hidden, and at
    ``start`` and ``end`` (s of simulated time): ``coverage`` (fraction of the picture's pixels
    the run covers), ``extent`` (area of the box around them, fraction of the picture) and
    ``motion`` (fraction of pixels that change from ``start`` to ``end``)."""
    first, hidden = render(page, f"t={start}"), render(page, f"t={start}&hide")
    return {"coverage": changed(first, hidden), "extent": extent(first, hidden),
            "motion": changed(first, render(page, f"t={end}"))}
