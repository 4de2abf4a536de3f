"""freefloat.robot.builders against the committed files, the dissertation's numbers and DH algebra."""

from __future__ import annotations

import importlib.metadata
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from freefloat.errors import RobotModelError
from freefloat.robot.builders import (
    ArmSpec,
    LinkSpec,
    RobotSpec,
    build_urdf,
    dual_arm_satellite,
    four_arm_planar,
    two_arm_planar,
    urdf_xml,
    write_urdf,
)
from freefloat.robot.loading import load_robot

URDF_DIR = Path(__file__).resolve().parents[1] / "urdf"

# Dissertation (seed 000), sec 4.2.1, typed in by hand: the reference the builders must meet.
LENGTHS = (0.5, 2.5, 2.5, 0.5)
LINK_MASS = 2.0
LINK_INERTIA = (0.065, 0.0321, 0.0277)
BASE_MASS = 10.0
BASE_INERTIA = (0.5667, 0.5667, 0.0667)
# Table 4 posture (deg, joints 1-4) and the end-effector positions it gives (sec 5.1, m).
TABLE4 = {"arm1": (0, 0, 0, 0), "arm2": (90, 0, 0, 0), "arm3": (0, 0, 0, 0), "arm4": (90, 0, 0, 0)}
TABLE4_EE = {
    "arm1": (7.75, 0, 0),
    "arm2": (0, 7.75, 0),
    "arm3": (-7.75, 0, 0),
    "arm4": (0, -7.75, 0),
}


@pytest.fixture(scope="module")
def four_arm():
    return load_robot(URDF_DIR / "four_arm_planar.urdf")


@pytest.fixture(scope="module")
def satellite():
    return load_robot(URDF_DIR / "dual_arm_satellite.urdf")


def _set_joints(model: pin.Model, q: np.ndarray, angles: dict[str, float]) -> np.ndarray:
    for name, angle in angles.items():
        q[model.joints[model.getJointId(name)].idx_q] = angle
    return q


def _frame_positions(robot, q: np.ndarray) -> np.ndarray:
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return np.array([data.oMf[i].translation for i in robot.end_effector_frame_ids])


@pytest.mark.parametrize(
    ("filename", "build"),
    [
        ("four_arm_planar.urdf", lambda: build_urdf(four_arm_planar())),
        ("two_arm_planar.urdf", lambda: build_urdf(two_arm_planar())),
        ("dual_arm_satellite.urdf", dual_arm_satellite),
    ],
)
def test_committed_urdf_equals_regenerated(filename, build):
    """Regenerating a URDF in memory gives exactly the committed file's text."""
    assert urdf_xml(build()) == (URDF_DIR / filename).read_text(encoding="utf-8")


def test_write_urdf_is_byte_identical_across_runs(tmp_path):
    """Writing the same spec twice gives the same bytes."""
    first = write_urdf(four_arm_planar(), tmp_path / "a.urdf").read_bytes()
    assert write_urdf(four_arm_planar(), tmp_path / "b.urdf").read_bytes() == first


def test_table4_posture_puts_end_effectors_on_the_half_axes(four_arm):
    """Table 4's joint angles put the end-effectors at (+-7.75, 0) and (0, +-7.75), arm1..arm4."""
    assert four_arm.end_effectors == ("arm1_ee", "arm2_ee", "arm3_ee", "arm4_ee")
    angles = {
        f"{arm}_joint{i}": math.radians(deg)
        for arm, degs in TABLE4.items()
        for i, deg in enumerate(degs, start=1)
    }
    q = _set_joints(four_arm.model, four_arm.neutral(), angles)
    expected = np.array([TABLE4_EE[arm] for arm in TABLE4], dtype=float)
    np.testing.assert_allclose(_frame_positions(four_arm, q), expected, atol=1e-9)


def test_two_arm_zero_posture_stretches_arms_along_x():
    """The two-arm robot at zero joint angles has its end-effectors at (7.75, 0) and (-7.75, 0)."""
    robot = load_robot(URDF_DIR / "two_arm_planar.urdf")
    assert robot.end_effectors == ("arm1_ee", "arm2_ee")
    np.testing.assert_allclose(
        _frame_positions(robot, robot.neutral()), [[7.75, 0, 0], [-7.75, 0, 0]], atol=1e-9
    )


@pytest.mark.parametrize(
    ("filename", "n_arms"), [("four_arm_planar.urdf", 4), ("two_arm_planar.urdf", 2)]
)
def test_total_mass_is_base_plus_links(filename, n_arms):
    """The Pinocchio model's total mass is the base plus 2 kg per link of every arm."""
    robot = load_robot(URDF_DIR / filename)
    expected = BASE_MASS + n_arms * len(LENGTHS) * LINK_MASS
    assert pin.computeTotalMass(robot.model) == pytest.approx(expected, abs=1e-12)


def test_link_inertias_match_dissertation(four_arm):
    """Every arm body in Pinocchio has 2 kg, a mid-link CoM and the printed principal inertias."""
    model = four_arm.model
    for arm in four_arm.arms:
        for joint, length in zip(arm.joints, LENGTHS, strict=True):
            inertia = model.inertias[model.getJointId(joint)]
            assert inertia.mass == pytest.approx(LINK_MASS, abs=1e-12), joint
            np.testing.assert_allclose(inertia.lever, [length / 2, 0, 0], atol=1e-12, err_msg=joint)
            np.testing.assert_allclose(
                inertia.inertia, np.diag(LINK_INERTIA), atol=1e-12, err_msg=joint
            )


def test_base_inertia_matches_dissertation(four_arm):
    """The floating body carries 10 kg, its CoM at the base origin, and the printed inertias."""
    base = four_arm.model.inertias[1]
    assert base.mass == pytest.approx(BASE_MASS, abs=1e-12)
    np.testing.assert_allclose(base.lever, np.zeros(3), atol=1e-12)
    np.testing.assert_allclose(base.inertia, np.diag(BASE_INERTIA), atol=1e-12)


@pytest.mark.slow
def test_satellite_has_two_tools_twelve_joints_and_meshes(satellite):
    """The satellite loads with end-effectors left_tool0 and right_tool0, 12 joints and visuals."""
    assert satellite.end_effectors == ("left_tool0", "right_tool0")
    assert satellite.n_joints == 12 and len(satellite.joint_names) == 12
    assert [len(arm.joints) for arm in satellite.arms] == [6, 6]
    assert satellite.visual_model is not None and satellite.visual_model.ngeoms > 0


@pytest.mark.slow
def test_satellite_mass_is_bus_plus_two_original_ur5(satellite):
    """The satellite's mass is the 500 kg bus plus twice the mass of example-robot-data's UR5."""
    share = importlib.metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share")
    ur5 = pin.buildModelFromUrdf(
        str(Path(str(share)) / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"),
        pin.JointModelFreeFlyer(),  # so that base_link's mass is not lost to the universe
    )
    expected = 500.0 + 2 * pin.computeTotalMass(ur5)
    assert pin.computeTotalMass(satellite.model) == pytest.approx(expected, abs=1e-9)


def test_satellite_bus_is_a_homogeneous_cube():
    """The bus link has 500 kg and the inertia m a^2 / 6 of a homogeneous 1 m cube at its centre."""
    bus = (
        ET.parse(URDF_DIR / "dual_arm_satellite.urdf").getroot().find("link[@name='bus']/inertial")
    )
    assert float(bus.find("mass").get("value")) == 500.0
    assert bus.find("origin").get("xyz").split() == ["0", "0", "0"]
    inertia = bus.find("inertia")
    for key, value in (
        ("ixx", 500 / 6),
        ("iyy", 500 / 6),
        ("izz", 500 / 6),
        ("ixy", 0),
        ("ixz", 0),
        ("iyz", 0),
    ):
        assert float(inertia.get(key)) == pytest.approx(value, abs=1e-9), key


@pytest.mark.slow
def test_satellite_arms_are_mounted_on_the_plus_x_face(satellite):
    """Each arm base sits at (0.5, +-0.3, 0) m on the bus with its z axis along the bus's +x."""
    model = satellite.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, satellite.neutral())
    for side, y in (("left", 0.3), ("right", -0.3)):
        placement = data.oMf[model.getFrameId(f"{side}_base_link")]
        np.testing.assert_allclose(placement.translation, [0.5, y, 0.0], atol=1e-12)
        np.testing.assert_allclose(placement.rotation[:, 2], [1.0, 0.0, 0.0], atol=1e-12)


def _dh(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard DH matrix Rz(theta) Tz(d) Tx(a) Rx(alpha), written out."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0, sa, ca, d],
            [0, 0, 0, 1],
        ]
    )


def test_from_dh_end_effector_matches_dh_product(tmp_path):
    """A PUMA-like arm built from DH rows puts its end-effector where the DH product does."""
    a = (0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0)
    alpha = (math.pi / 2, 0.0, -math.pi / 2, math.pi / 2, -math.pi / 2, 0.0)
    d = (0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0563)
    theta = (0.1, -0.2, 0.3, 0.0, 0.5, -0.4)
    pivot_xyz, pivot_rpy = (0.2, -0.1, 0.3), (0.1, 0.2, 0.3)
    arm = ArmSpec.from_dh(
        "puma",
        a,
        alpha,
        d,
        theta,
        [1.0] * 6,
        [(0.01, 0.01, 0.01)] * 6,
        pivot_xyz=pivot_xyz,
        pivot_rpy=pivot_rpy,
    )
    spec = RobotSpec("dh_robot", 5.0, (0.1, 0.1, 0.1), (0.0, 0.0, 0.0), (0.3, 0.3, 0.3), (arm,))
    robot = load_robot(write_urdf(spec, tmp_path / "dh.urdf"))
    q_arm = np.array([0.3, -0.7, 1.1, 0.4, -0.9, 2.0])
    q = _set_joints(
        robot.model, robot.neutral(), {f"puma_joint{i}": v for i, v in enumerate(q_arm, 1)}
    )
    expected = np.eye(4)
    expected[:3, :3], expected[:3, 3] = pin.rpy.rpyToMatrix(*pivot_rpy), pivot_xyz
    for row in zip(q_arm + np.array(theta), d, a, alpha, strict=True):
        expected = expected @ _dh(*row)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    np.testing.assert_allclose(
        data.oMf[robot.model.getFrameId("puma_ee")].homogeneous, expected, atol=1e-10
    )


def _link(length: float = 1.0, mass: float = 1.0) -> LinkSpec:
    return LinkSpec(length, mass, (0.1, 0.1, 0.1))


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (
            lambda: ArmSpec("left", (0, 0, 0), (0, 0, 0), (_link(), _link(mass=-1.0))),
            ("left", "left_link2", "mass"),
        ),
        (
            lambda: ArmSpec("right", (0, 0, 0), (0, 0, 0), (_link(length=0.0),)),
            ("right", "right_link1", "zero length"),
        ),
        (lambda: ArmSpec("empty", (0, 0, 0), (0, 0, 0), ()), ("empty", "no links")),
        (
            lambda: RobotSpec(
                "bot",
                -1.0,
                (1, 1, 1),
                (0, 0, 0),
                (1, 1, 1),
                (ArmSpec("a", (0, 0, 0), (0, 0, 0), (_link(),)),),
            ),
            ("bot", "base", "mass"),
        ),
    ],
    ids=["negative-mass", "zero-length", "empty-arm", "negative-base-mass"],
)
def test_bad_spec_raises_naming_the_culprit(make, words):
    """A physically impossible spec raises RobotModelError naming the arm and link at fault."""
    with pytest.raises(RobotModelError) as error:
        make()
    for word in words:
        assert word in str(error.value)
