"""Loading URDFs as floating-base robots: structure, physics checks, SPART files, errors."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from hypothesis import given, settings

from freefloat import RobotModelError, load_robot
from freefloat.robot.loading import BASE_COM_FRAME, FreefloatWarning

from .conftest import REPO, load_text, random_robots, robot_from_case

LINK = '<link name="{n}"><inertial><mass value="{m}"/><inertia ixx="{i}" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
JOINT = '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'


def urdf(links: list[tuple[str, float, float]], joints: list[tuple[str, str, str]]) -> str:
    body = [LINK.format(n=n, m=m, i=i) for n, m, i in links] + [JOINT.format(n=n, p=p, c=c) for n, p, c in joints]
    return '<robot name="t">' + "".join(body) + "</robot>"


def parsed_case(factory, case):
    """The robot of a drawn case and yourdfpy's independent parse of the same file."""
    robot, _ = robot_from_case(factory, case)
    return robot, yourdfpy.URDF.load(str(robot.urdf_path), build_scene_graph=False, load_meshes=False)


@pytest.mark.parametrize("name", ["SC_3DoF", "ManiSat_2Arm_2_2", "2_iiwa_base", "kuka_iiwa"])
def test_spart_files_load_with_one_note_per_problem(spart_dir, name):
    """SPART's URDFs load; missing limits and missing meshes are each reported once."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(spart_dir / "urdf" / f"{name}.urdf")
    notes = [str(w.message) for w in caught if issubclass(w.category, FreefloatWarning)]
    assert len([n for n in notes if "<limit>" in n]) == (1 if name in ("SC_3DoF", "ManiSat_2Arm_2_2") else 0)
    assert len([n for n in notes if "mesh" in n]) == (1 if "iiwa" in name else 0)
    assert robot.model.joints[1].shortname() == "JointModelFreeFlyer"


def test_spart_joint_order_matches_spart(spart_dir):
    """Pinocchio's joint order on the dual-iiwa satellite equals SPART's q_names."""
    import json

    ref = json.loads((spart_dir / "out" / "two_iiwa_base.json").read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(spart_dir / "urdf" / "2_iiwa_base.urdf")
    assert list(robot.joint_names) == ref["q_names"]


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_total_mass_equals_urdf_masses(tmp_path_factory, case):
    """Fixed joints are merged, not dropped: Pinocchio's total mass equals the URDF's sum."""
    robot, parsed = parsed_case(tmp_path_factory, case)
    assert pin.computeTotalMass(robot.model) == pytest.approx(sum(l.inertial.mass for l in parsed.robot.links), rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_base_com_frame_is_the_base_link_inertial_origin(tmp_path_factory, case):
    """The base reference frame is the root link's <inertial> origin, position and rotation."""
    robot, parsed = parsed_case(tmp_path_factory, case)
    origin = parsed.link_map["base"].inertial.origin
    frame = robot.model.frames[robot.model.getFrameId(BASE_COM_FRAME)]
    assert frame.parentJoint == 1
    np.testing.assert_allclose(frame.placement.homogeneous, origin, atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_arms_run_from_base_to_each_leaf(tmp_path_factory, case):
    """Each arm lists exactly the movable joints on the path from the base to its end-effector."""
    robot, parsed = parsed_case(tmp_path_factory, case)
    by_child = {j.child: j for j in parsed.robot.joints}
    for arm in robot.arms:
        path, link = [], arm.end_effector
        while link in by_child:
            joint = by_child[link]
            if joint.type != "fixed":
                path.append(joint.name)
            link = joint.parent
        assert list(arm.joints) == path[::-1]
        assert len(arm.v_indices) == len(path)


def test_four_arm_robot_has_four_arms_of_four_joints():
    """The dissertation's four-arm robot loads with end-effectors arm1..arm4, 4 joints each."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf")
    assert robot.end_effectors == ("arm1_ee", "arm2_ee", "arm3_ee", "arm4_ee")
    assert [len(a.joints) for a in robot.arms] == [4, 4, 4, 4]


def test_planar_base_has_three_base_coordinates():
    """A planar base adds x, y, yaw: nv = joints + 3."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", base="planar")
    assert (robot.model.nv, robot.n_base, robot.model.joints[1].shortname()) == (19, 3, "JointModelPlanar")


def test_gravity_is_zero_by_default():
    """Space scenes: the loaded model has no gravity unless asked for."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf")
    assert np.all(robot.model.gravity.vector == 0.0)


def test_named_end_effectors_are_used_in_order():
    """Named end-effectors replace the leaves, in the caller's order."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", end_effectors=["arm3_link4", "arm1_ee"])
    assert robot.end_effectors == ("arm3_link4", "arm1_ee")
    assert robot.arms[0].joints == tuple(f"arm3_joint{i}" for i in range(1, 5))


@pytest.mark.parametrize(
    ("links", "joints", "names"),
    [
        ([("a", 1, 1), ("b", 1, 1), ("c", 1, 1)], [("j1", "a", "b")], ["2 roots", "a", "c"]),
        ([("a", 1, 1), ("b", 1, 1), ("c", 1, 1)], [("j1", "a", "b"), ("j2", "c", "b")], ["loop", "'b'", "j1", "j2"]),
        ([("a", 1, 1), ("b", 1, 1)], [("j1", "zz", "b")], ["j1", "zz", "does not exist"]),
        ([("a", 1, 1), ("b", -2, 1)], [("j1", "a", "b")], ["'b'", "mass -2"]),
        ([("a", 1, 1), ("b", 1, -1)], [("j1", "a", "b")], ["'b'", "not positive definite"]),
        ([("a", 1, 1), ("b", 1, 1), ("c", 1, 1)], [("j1", "b", "c"), ("j2", "c", "b")], ["loop"]),
    ],
    ids=["two-roots", "two-parents", "missing-parent", "negative-mass", "indefinite-inertia", "cycle"],
)
def test_bad_trees_are_rejected_naming_the_culprit(tmp_path, links, joints, names):
    """A file that cannot be a floating-base tree fails with a message naming link or joint."""
    with pytest.raises(RobotModelError) as err:
        load_text(tmp_path, urdf(links, joints))
    for name in names:
        assert name in str(err.value)
    assert "robot.urdf" in str(err.value)


def test_unknown_end_effector_is_rejected(tmp_path):
    """Naming an end-effector that is not a link fails with the link list."""
    with pytest.raises(RobotModelError, match="end-effector 'hand' is not a link"):
        load_text(tmp_path, urdf([("a", 1, 1), ("b", 1, 1)], [("j1", "a", "b")]), end_effectors=["hand"])


def test_missing_file_is_rejected(tmp_path):
    """A path that does not exist fails with the path."""
    with pytest.raises(RobotModelError, match="no such URDF"):
        load_robot(tmp_path / "nothing.urdf")


def _one_mesh_missing(folder: Path) -> Path:
    """A two-link URDF in ``folder``: link a's mesh is there (a copy of UR5's base.stl), link b's
    (gone.stl) is not."""
    from freefloat.robot.loading import example_robot_data_share

    stl = example_robot_data_share() / "example-robot-data/robots/ur_description/meshes/ur5/collision/base.stl"
    (folder / "there.stl").write_bytes(stl.read_bytes())
    text = urdf([("a", 1, 1), ("b", 1, 1)], [("j1", "a", "b")])
    for link, mesh in (("a", "there.stl"), ("b", "gone.stl")):
        text = text.replace(f'<link name="{link}">',
                            f'<link name="{link}"><visual><geometry><mesh filename="{mesh}"/></geometry></visual>')
    (folder / "robot.urdf").write_text(text)
    return folder / "robot.urdf"


def test_a_missing_mesh_costs_only_its_own_visual(tmp_path):
    """One mesh file missing: one warning naming the link and the file; the dynamics load and the
    other link keeps its mesh."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(_one_mesh_missing(tmp_path))
    assert robot.model.nv == 7 and robot.visual_model is not None
    assert [Path(g.meshPath).name for g in robot.visual_model.geometryObjects] == ["there.stl"]
    (note,) = [str(w.message) for w in caught if "gone.stl" in str(w.message)]
    assert "link 'b'" in note and str(tmp_path) in note
    assert robot.missing_meshes == (("b", "gone.stl"),)


def test_a_missing_mesh_is_noted_without_building_visuals(tmp_path):
    """``visuals=False`` (what ``freefloat info`` loads) still notes the missing mesh."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(_one_mesh_missing(tmp_path), visuals=False)
    assert any("link 'b': 'gone.stl'" in note for note in robot.warnings)
    assert robot.visual_model is None and robot.missing_meshes == (("b", "gone.stl"),)


def test_example_robot_data_meshes_resolve():
    """package:// meshes of example-robot-data resolve through the installed data."""
    from freefloat.robot.loading import example_robot_data_share

    ur5 = example_robot_data_share() / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(ur5)
    assert not [w for w in caught if "mesh" in str(w.message)]
    assert robot.visual_model is not None and robot.visual_model.ngeoms > 0


@pytest.mark.slow
def test_package_paths_with_three_slashes_resolve():
    """talos' 'package:///talos_data/...' meshes resolve (Pinocchio's own loader finds all 53)."""
    from freefloat.robot.loading import example_robot_data_share

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(example_robot_data_share() / "example-robot-data" / "robots" / "talos_data" / "robots"
                           / "talos_full_v2.urdf")
    assert robot.visual_model is not None and robot.visual_model.ngeoms == 53


def test_an_unreadable_mesh_loads_the_robot_without_visuals(tmp_path):
    """A mesh file the mesh library cannot read gives a note and a robot without visuals."""
    (tmp_path / "broken.stl").write_bytes(b"solid x\nthis is not an STL file\n" * 3)
    text = (REPO / "urdf" / "two_arm_planar.urdf").read_text()
    text = text.replace("</link>", '<visual><geometry><mesh filename="broken.stl"/></geometry></visual></link>', 1)
    path = tmp_path / "r.urdf"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(path)
    assert robot.model.nv > 0 and robot.visual_model is None
    assert any("meshes could not be read" in str(w.message) and "\n" not in str(w.message) for w in caught)


def test_a_gripper_counts_as_one_end_effector():
    """Panda's two fingers and its TCP give one end-effector, the TCP, and a well-conditioned GJM
    (all three leaves gave a condition number of 6e16)."""
    import numpy as np

    from freefloat import gjm

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        panda = load_robot("panda", visuals=False)
    assert panda.end_effectors == ("panda_hand_tcp",)
    q = panda.neutral()
    q[7:14] = [0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.5]
    state = gjm.compute(panda, q, np.zeros(panda.model.nv))
    assert np.linalg.cond(state.Jstar[:, :7]) < 1e3


def test_arms_branching_at_the_base_stay_separate_end_effectors():
    """Leaves that branch at the base (the four-arm robot's arms) are not merged."""
    robot = load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)
    assert robot.end_effectors == ("arm1_ee", "arm2_ee", "arm3_ee", "arm4_ee")


@pytest.mark.parametrize("gravity", [(0.0, 0.0, float("nan")), (0.0, -9.81), ("down", 0, 0)])
def test_a_gravity_that_is_not_three_finite_numbers_is_refused(gravity):
    """load_robot refuses a NaN, two-component or non-numeric gravity, naming the argument."""
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match="'gravity' must be three finite numbers"):
        load_robot(REPO / "urdf" / "two_arm_planar.urdf", gravity=gravity, visuals=False)


@pytest.mark.parametrize("path, gravity, message", [(1.5, (0.0, 0.0, 0.0), "'path' must be a URDF file"),
                                                    (None, (0.0, 0.0, 0.0), "'path' must be a URDF file"),
                                                    ("ur5", (0.0, 0.0, 1e300), "'gravity' must be three finite")])
def test_load_robot_refuses_a_path_or_gravity_that_is_none(path, gravity, message):
    """A path that is no path (a TypeError from pathlib) and a gravity of 1e300 are refused
    naming them."""
    from freefloat import InvalidArgument

    with pytest.raises(InvalidArgument, match=message):
        load_robot(path, gravity=gravity, visuals=False)



def test_a_mimic_joint_is_loaded_with_a_note_that_it_is_not_enforced(tmp_path):
    """A <mimic> joint is loaded as an independent joint, and the loader says so naming it."""
    link = ('<link name="{0}"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" '
            'iyz="0"/></inertial></link>')
    joint = ('<joint name="{0}" type="revolute"><parent link="{1}"/><child link="{2}"/><axis xyz="0 0 1"/>'
             '<limit lower="-1" upper="1" effort="1" velocity="1"/>{3}</joint>')
    text = ('<robot name="m">' + "".join(link.format(n) for n in ("base", "a", "b"))
            + joint.format("j1", "base", "a", "") + joint.format("j2", "a", "b", '<mimic joint="j1"/>') + "</robot>")
    (tmp_path / "m.urdf").write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(tmp_path / "m.urdf")
    notes = [str(w.message) for w in caught if issubclass(w.category, FreefloatWarning)]
    assert robot.n_joints == 2
    assert any("'j2' (<mimic joint=\"j1\">) are loaded as independent joints" in n for n in notes), notes
