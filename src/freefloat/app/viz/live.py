"""A live meshcat viewer for ``freefloat simulate --view``: the robot shown as the run is
computed (each telemetry chunk as it is checkpointed), then the whole run replayed.

It starts meshcat's own server on loopback, as Pinocchio's ``MeshcatVisualizer`` does, and
draws the robot's visual geometry through it.
"""

from __future__ import annotations

import contextlib
import io
import time

import numpy as np
import pinocchio as pin

from ...dynamics.telemetry import Telemetry
from ...robot.robot import Robot


class LiveView:
    """A meshcat server showing one robot.

    Args:
        robot: the robot whose Pinocchio configurations will be shown (its visual geometry is
            drawn; a robot without one shows nothing but the grid).
    """

    def __init__(self, robot: Robot):
        import meshcat
        from pinocchio.visualize import MeshcatVisualizer

        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL; the caller says where it is
            self.viewer = meshcat.Visualizer()
        geometry = robot.visual_model if robot.visual_model is not None else pin.GeometryModel()
        self.visualizer = MeshcatVisualizer(robot.model, geometry, geometry)
        self.visualizer.initViewer(viewer=self.viewer)
        self.visualizer.loadViewerModel()
        self.model = robot.model

    @property
    def url(self) -> str:
        """Where a browser shows the viewer (loopback)."""
        return self.viewer.url()

    def show(self, chunk: Telemetry) -> None:
        """Show the last configuration of a telemetry chunk."""
        if len(chunk.t):
            self.visualizer.display(chunk.q[-1])

    def replay(self, t: np.ndarray, q: np.ndarray, fps: float = 30.0, speed: float = 1.0) -> None:
        """Play configurations ``q`` (N, nq) at times ``t`` (N,) s, at ``speed`` x real time and
        ``fps`` frames per second of simulated time."""
        if len(t) < 2:
            return
        ticks = np.arange(t[0], t[-1] + 1e-12, 1.0 / fps)
        shown = np.unique(np.searchsorted(t, ticks).clip(0, len(t) - 1))
        start = time.perf_counter()
        for i in shown:
            time.sleep(max(0.0, (t[i] - t[0]) / speed - (time.perf_counter() - start)))
            self.visualizer.display(q[i])

    def close(self) -> None:
        """Stop the meshcat server."""
        process = getattr(self.viewer.window, "server_proc", None)
        if process is not None:
            process.kill()
            process.wait()
