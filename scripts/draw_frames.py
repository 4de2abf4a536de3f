"""Draw the frames and points of docs/conventions.md on the UR5 dual-arm satellite, moved and
turned away from the origin so that every frame shows: the inertial frame, the base link frame, the base CoM frame (r0, R0), the
joint axes and the end-effector link frames. Writes docs/img/frames.png."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from freefloat import load_robot
from freefloat.app.viz.figures import skeleton
from freefloat.paths import URDF_DIR

OUT = Path(__file__).resolve().parents[1] / "docs" / "img" / "frames.png"


def axes(ax, origin: np.ndarray, rotation: np.ndarray, length: float, label: str, width: float = 1.5) -> None:
    """x, y, z of a frame as red, green, blue arrows, labelled at the origin."""
    for i, color in enumerate(("#d62728", "#2ca02c", "#1f77b4")):
        ax.quiver(*origin, *(length * rotation[:, i]), color=color, linewidth=width, arrow_length_ratio=0.15)
    ax.text(*(origin + 0.15 * length), label, fontsize=9)


def main() -> None:
    robot = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)
    model, data = robot.model, robot.model.createData()
    q = robot.neutral()
    q[:3] = [0.7, 0.5, 0.3]
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(0.2, -0.1, 0.6)).coeffs()
    q[7:] = np.tile(np.radians([20.0, -60.0, 90.0, -30.0, 40.0, 0.0]), 2)[: robot.n_joints]
    pin.framesForwardKinematics(model, data, q)
    fig = Figure(figsize=(8.0, 6.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    for segment in skeleton(robot, q):
        ax.plot(*segment.T, color="#505050", linewidth=2.5)
    axes(ax, np.zeros(3), np.eye(3), 0.3, "inertial frame")
    com = data.oMf[model.getFrameId("base_com")]
    axes(ax, com.translation, com.rotation, 0.4, "base CoM frame: r0, R0 (= base link here)", width=2.5)
    for j in range(2, model.njoints):
        ax.quiver(*data.oMi[j].translation, *(0.15 * data.oMi[j].rotation[:, 2]), color="#ff7f0e", linewidth=1.2)
    for name, frame_id in zip(robot.end_effectors, robot.end_effector_frame_ids):
        axes(ax, data.oMf[frame_id].translation, data.oMf[frame_id].rotation, 0.2, f"end-effector {name}")
    ax.plot([], [], color="#ff7f0e", label="joint axes (z of each joint frame)")
    ax.plot([], [], color="#505050", label="links (joint origins to children)")
    ax.legend(loc="upper left", fontsize=9)
    ax.set(xlabel="x (m)", ylabel="y (m)", zlabel="z (m)", title="Frames and points (UR5 dual-arm satellite, base moved and turned)")
    limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
    centre, half = limits.mean(axis=1), (limits[:, 1] - limits[:, 0]).max() / 2
    ax.set(xlim3d=(centre[0] - half, centre[0] + half), ylim3d=(centre[1] - half, centre[1] + half),
           zlim3d=(centre[2] - half, centre[2] + half))
    ax.view_init(elev=35, azim=-60)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=100)
    print("wrote", OUT)


if __name__ == "__main__":
    main()
