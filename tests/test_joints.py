"""Actuated joint positions as one number per joint, continuous joints included."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
from hypothesis import given, settings

from freefloat.robot.joints import JointCoordinates, prismatic_columns, slides

from .conftest import load_text, random_trees

URDF = """<robot name="c">
<link name="base"><inertial><mass value="5"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="a"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="wheel" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
<joint name="slide" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_continuous_joint_reads_as_an_angle(tmp_path):
    """A continuous joint (cos, sin in q) reads back as the angle Pinocchio integrated to."""
    robot = load_text(tmp_path, URDF)
    assert (robot.model.nq, robot.model.nv) == (10, 8)
    coords = JointCoordinates(robot)
    q = pin.integrate(robot.model, robot.neutral(), np.array([0, 0, 0, 0, 0, 0, 2.5, 0.3]))
    np.testing.assert_allclose(coords.get(q), [2.5, 0.3], atol=1e-14)


def test_set_then_get_is_the_identity_within_pi(tmp_path):
    """Writing joint positions and reading them back returns them (angles within (-pi, pi])."""
    robot = load_text(tmp_path, URDF)
    coords = JointCoordinates(robot)
    q = robot.neutral()
    coords.set(q, np.array([-3.0, -0.7]))
    np.testing.assert_allclose(coords.get(q), [-3.0, -0.7], atol=1e-14)
    np.testing.assert_allclose(q[7:9], [np.cos(-3.0), np.sin(-3.0)])


@settings(max_examples=25, deadline=None)
@given(case=random_trees())
def test_the_sliding_columns_are_the_urdf_s_prismatic_joints(tmp_path_factory, case):
    """Each joint velocity column is marked sliding exactly when the URDF declares its joint
    prismatic, on general axes (PrismaticUnaligned) and on the axes of its frame (PX, PY, PZ,
    which the robot runs' angle scales once took for revolute)."""
    _, text, base = case  # a robot's base floats: a drawn fixed base is taken free
    robot = load_text(tmp_path_factory.mktemp("r"), text, base="planar" if base == "planar" else "free")
    declared = {joint.get("name"): joint.get("type") for joint in ET.fromstring(text).iter("joint")}
    model, mask = robot.model, prismatic_columns(robot)
    for j in range(2, model.njoints):
        start = model.idx_vs[j] - robot.n_base
        assert mask[start:start + model.nvs[j]].all() == (declared[model.names[j]] == "prismatic")
    assert slides(pin.JointModelPX()) and not slides(pin.JointModelPlanar()) and not slides(pin.JointModelRZ())
