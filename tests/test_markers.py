"""Tests of freefloat.app.viz.markers: the points a page follows."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from hypothesis import given, settings

from freefloat.app.viz.markers import robot_markers

from .conftest import random_robots, random_state, robot_from_case


@settings(max_examples=15, deadline=None)
@given(random_robots(max_links=6))
def test_robot_markers_match_pinocchio(tmp_path_factory, case):
    """Base CoM, system CoM and end-effector origins equal Pinocchio's at random configurations."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    q = np.array([random_state(robot, rng)[0] for _ in range(3)])
    markers = {m.name: m.positions for m in robot_markers(robot, q)}
    model, data = robot.model, robot.model.createData()
    for k, qk in enumerate(q):
        np.testing.assert_allclose(markers["system_com"][k], pin.centerOfMass(model, data, qk), atol=1e-12)
        pin.framesForwardKinematics(model, data, qk)
        base = data.oMi[1].act(model.inertias[1].lever)
        np.testing.assert_allclose(markers["base_com"][k], base, atol=1e-12)
        for name, frame in zip(robot.end_effectors, robot.end_effector_frame_ids):
            np.testing.assert_allclose(markers[f"end_effector_{name}"][k], data.oMf[frame].translation, atol=1e-12)
