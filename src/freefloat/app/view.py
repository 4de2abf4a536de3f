"""``freefloat view RUN_DIR``: reopen a saved run's meshcat page, rebuilt from the run's telemetry
when the run was written without one (``--no-html``).

A robot run records its robot (URDF, base, end-effectors) in ``summary.json`` and its
configurations in ``telemetry.npz``, which is all the page needs. Capture and mechanism runs draw
more than the recorded robot (the target before the grasp, the closed chains), so their page is
written by the run itself and not rebuilt here.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

from ..dynamics.telemetry import Telemetry
from ..errors import RunFolderError, spelled
from ..robot.loading import load_robot
from .viz.meshcat_html import write_trajectory_html

PAGE = "trajectory.html"


def run_page(run_dir: str | Path, fps: float = 30.0) -> Path:
    """The run's ``trajectory.html``, written from ``summary.json`` and ``telemetry.npz`` at
    ``fps`` frames per simulated second when the folder has none.

    Raises:
        RunFolderError: naming the folder when it holds no run, or when its page cannot be
            rebuilt (a capture or mechanism run written with ``--no-html``).
    """
    run_dir = Path(run_dir)
    page = run_dir / PAGE
    if page.is_file():
        return page
    summary_file, telemetry_file = run_dir / "summary.json", run_dir / "telemetry.npz"
    if not (summary_file.is_file() and telemetry_file.is_file()):
        raise RunFolderError(f"'{run_dir}' is not a run folder: it has no {PAGE}, summary.json or telemetry.npz")
    summary = json.loads(summary_file.read_text())
    if "robot" not in summary or "impact_time" in summary:
        raise RunFolderError(f"'{run_dir}' has no {PAGE}, and only a robot run's page can be rebuilt; "
                             f"run the scene again {spelled('with [output] html = true', 'without --no-html')}")
    described = summary["robot"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the run already reported the loader's notes
        robot = load_robot(described["urdf"], base=described["base"], end_effectors=described["end_effectors"])
    telemetry = Telemetry.load(telemetry_file)
    return write_trajectory_html(robot, telemetry.t, telemetry.q, page, fps=fps)
