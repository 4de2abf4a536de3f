"""MJCF export: MuJoCo builds the same multibody system as Pinocchio (mass matrices), and inertias
that break the triangle inequality are balanced, with a warning, on both sides."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings

from freefloat import RobotModelError, load_robot
from freefloat.lab.bench.in_mujoco.mjcf import (
    InertiaBalanceWarning,
    balanced_model,
    mjcf,
    mjcf_from_model,
)
from freefloat.lab.bench.in_mujoco.state import to_mujoco, velocity_map
from freefloat.robot.inertias import triangle_violations

from .conftest import load_text, random_robots, random_state, robot_from_case


def _robot(name: str, base: str = "free"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot(name, base=base, visuals=False)


def _mass_matrix_gap(model: pin.Model, q: np.ndarray, v: np.ndarray) -> float:
    """max |S^T M_pin S - M_mujoco| / max |M_mujoco| at (q, v), MuJoCo's model from the MJCF."""
    mj = mujoco.MjModel.from_xml_string(mjcf_from_model(model))
    data = mujoco.MjData(mj)
    data.qpos[:], data.qvel[:] = to_mujoco(q, v)
    mujoco.mj_forward(mj, data)
    m_mj = np.zeros((mj.nv, mj.nv))
    mujoco.mj_fullM(mj, data, m_mj)
    m_pin = pin.crba(model, model.createData(), q)
    m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
    s = velocity_map(q, model.nv)
    return float(np.abs(s.T @ m_pin @ s - m_mj).max() / np.abs(m_mj).max())


def test_mass_matrices_agree_on_the_dual_arm_satellite():
    """On the UR5 dual-arm satellite MuJoCo's mass matrix equals Pinocchio's (mapped) to 1e-12."""
    robot = _robot("dual_arm_satellite")
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, v = random_state(robot, rng)
        assert _mass_matrix_gap(robot.model, q, v) < 1e-12


@settings(max_examples=15, deadline=None)
@given(case=random_robots(max_links=6))
def test_mass_matrices_agree_on_random_robots(tmp_path_factory, case):
    """On random trees (inertias that satisfy the triangle inequality, unaligned axes, prismatic
    and fixed joints) the mapped mass matrices agree to 1e-12."""
    robot, rng = robot_from_case(tmp_path_factory, case)
    assert not triangle_violations(robot.model)
    q, v = random_state(robot, rng)
    assert _mass_matrix_gap(robot.model, q, v) < 1e-12


def test_mujoco_refuses_the_four_arm_robot_as_it_stands():
    """The four-arm robot's link inertias break the triangle inequality and MuJoCo refuses them."""
    model = _robot("four_arm_planar").model
    assert len(triangle_violations(model)) == 16
    with pytest.raises(ValueError, match="inertia"):
        mujoco.MjModel.from_xml_string(mjcf_from_model(model))


def test_balanced_copy_warns_and_satisfies_the_inequality():
    """Balancing warns naming the bodies, leaves no violation, keeps masses and CoMs, and moves
    each changed moment by under 10 %."""
    model = _robot("four_arm_planar").model
    with pytest.warns(InertiaBalanceWarning, match="arm1_joint1"):
        balanced = balanced_model(model)
    assert not triangle_violations(balanced, tol=-1e-12)
    for j in range(1, model.njoints):
        old, new = model.inertias[j], balanced.inertias[j]
        assert new.mass == old.mass and np.array_equal(new.lever, old.lever)
        assert np.abs(new.inertia - old.inertia).max() <= 0.1 * np.abs(old.inertia).max()
    mujoco.MjModel.from_xml_string(mjcf_from_model(balanced))


def test_balanced_copy_of_the_four_arm_robot_matches_mujoco():
    """On the balanced four-arm copy the mapped mass matrices agree to 1e-12."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InertiaBalanceWarning)
        model = balanced_model(_robot("four_arm_planar").model)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    assert _mass_matrix_gap(model, q, np.zeros(model.nv)) < 1e-12


def test_balancing_leaves_valid_inertias_bit_equal():
    """A robot whose inertias are valid is copied unchanged and without a warning."""
    model = _robot("dual_arm_satellite").model
    with warnings.catch_warnings():
        warnings.simplefilter("error", InertiaBalanceWarning)
        balanced = balanced_model(model)
    assert all(np.array_equal(balanced.inertias[j].matrix(), model.inertias[j].matrix())
               for j in range(model.njoints))


def test_planar_base_is_refused_naming_the_file():
    """A planar-base robot has no MuJoCo free joint: the error names the URDF and the base."""
    with pytest.raises(RobotModelError, match="two_arm_planar.urdf.*base='free'"):
        mjcf(_robot("two_arm_planar", base="planar"))


def test_continuous_joint_is_refused_naming_it(tmp_path):
    """A continuous joint ((cos, sin) in Pinocchio) has no MuJoCo hinge here: the error names it."""
    inertial = '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
    text = (f'<robot name="r"><link name="base">{inertial}</link><link name="l1">{inertial}</link>'
            '<joint name="spin &amp; roll" type="continuous"><parent link="base"/><child link="l1"/>'
            '<axis xyz="0 0 1"/></joint></robot>')
    robot = load_text(tmp_path, text)
    with pytest.raises(RobotModelError, match="joint 'spin & roll'"):
        mjcf(robot)
