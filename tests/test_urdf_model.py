"""The standard-library URDF reader against yourdfpy (the reference; still installed for writing
URDFs): the same links, masses, inertias, origins, joint types, axes, limits and mimics on every
robot freefloat knows by name and on random trees; malformed files refused naming the file, the
link or joint, the element and the attribute."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
from hypothesis import given, settings

from freefloat import RobotModelError
from freefloat.robot.catalog import robots
from freefloat.robot.urdf_checks import read_urdf
from freefloat.robot.urdf_model import parse_urdf

from .conftest import load_text, random_robots

#: Every URDF the catalog names: freefloat's own (urdf/) and example-robot-data's (talos, ur5, solo...).
FILES = sorted(set(robots().values()))
LIMIT_FIELDS = ("lower", "upper", "effort", "velocity")


def reference(path: Path) -> yourdfpy.Robot:
    return yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False).robot


def assert_same(ours, theirs) -> None:
    """Links and joints of our parse equal yourdfpy's, to 1e-15 (yourdfpy's None origin is the
    identity)."""
    def pose(origin):
        return np.eye(4) if origin is None else origin

    assert [link.name for link in ours.links] == [link.name for link in theirs.links]
    for link, ref in zip(ours.links, theirs.links):
        assert (link.inertial is None) == (ref.inertial is None), link.name
        if ref.inertial is not None:
            assert link.inertial.mass == ref.inertial.mass, link.name
            np.testing.assert_allclose(link.inertial.origin, pose(ref.inertial.origin), rtol=0, atol=1e-15)
            np.testing.assert_allclose(link.inertial.inertia, ref.inertial.inertia, rtol=0, atol=1e-15)
    assert [joint.name for joint in ours.joints] == [joint.name for joint in theirs.joints]
    for joint, ref in zip(ours.joints, theirs.joints):
        assert (joint.type, joint.parent, joint.child) == (ref.type, ref.parent, ref.child), joint.name
        np.testing.assert_allclose(joint.origin, pose(ref.origin), rtol=0, atol=1e-15)
        np.testing.assert_array_equal(joint.axis, ref.axis)
        assert (joint.limit is None) == (ref.limit is None), joint.name
        if ref.limit is not None:
            assert [getattr(joint.limit, f) for f in LIMIT_FIELDS] == [getattr(ref.limit, f) for f in LIMIT_FIELDS]
        assert (joint.mimic is None) == (ref.mimic is None), joint.name
        if ref.mimic is not None:
            assert (joint.mimic.joint, joint.mimic.multiplier, joint.mimic.offset) == (
                ref.mimic.joint, ref.mimic.multiplier, ref.mimic.offset)
        assert (joint.dynamics is None) == (ref.dynamics is None), joint.name
        if ref.dynamics is not None:  # yourdfpy keeps the text, None where left out (0 here: urdfdom's reading)
            assert (joint.dynamics.damping, joint.dynamics.friction) == (
                float(ref.dynamics.damping or 0.0), float(ref.dynamics.friction or 0.0)), joint.name


@pytest.mark.parametrize("path", FILES, ids=[f"{p.parent.parent.name}/{p.stem}" for p in FILES])
def test_every_known_robot_reads_as_yourdfpy_reads_it(path):
    """Each catalog robot (talos_full_v2's 100 links among them) parses as yourdfpy parses it; a
    file yourdfpy cannot read (ur3.urdf: an empty <robot> without a name) we refuse too."""
    try:
        theirs = reference(path)
    except Exception:  # noqa: BLE001  (yourdfpy raises KeyError, AttributeError ... on broken files)
        with pytest.raises(RobotModelError, match=str(path)):
            parse_urdf(path, read_urdf(path))
        return
    assert_same(parse_urdf(path, read_urdf(path)), theirs)


@settings(max_examples=25, deadline=None)
@given(random_robots())
def test_random_trees_read_as_yourdfpy_reads_them(tmp_path_factory, case):
    """Random trees with rotated joint and inertial frames, random axes and limits."""
    path = tmp_path_factory.mktemp("r") / "robot.urdf"
    path.write_text(case[1])
    assert_same(parse_urdf(path, read_urdf(path)), reference(path))


def test_defaults_are_yourdfpy_s(tmp_path):
    """What a file leaves out: no <inertial> (None), no <origin> or no rpy (identity rotation), no
    <axis> ((1, 0, 0)), a <limit> without lower/upper (None), a <mimic> without multiplier and
    offset (1, 0)."""
    path = tmp_path / "sparse.urdf"
    path.write_text(
        '<robot name="s"><link name="a"/><link name="b"><inertial><origin xyz="0.1 0.2 0.3"/><mass value="2"/>'
        '<inertia ixx="1" ixy="0.1" ixz="0.2" iyy="2" iyz="0.3" izz="3"/></inertial></link><link name="c"/>'
        '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin rpy="0.1 0.2 0.3"/>'
        '<limit effort="1" velocity="2"/><mimic joint="j1"/></joint></robot>')
    ours = parse_urdf(path, read_urdf(path))
    assert_same(ours, reference(path))
    assert ours.links[0].inertial is None and ours.joints[1].limit.lower is None
    np.testing.assert_array_equal(ours.joints[0].axis, [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(ours.joints[0].origin, np.eye(4))


def test_parsed_models_cannot_be_changed():
    """Fields cannot be reassigned and the poses, inertias and axes are read-only arrays."""
    path = robots()["four_arm_planar"]
    model = parse_urdf(path, read_urdf(path))
    link = next(link for link in model.links if link.inertial is not None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        link.inertial.mass = 0.0
    for array in (link.inertial.origin, link.inertial.inertia, model.joints[0].origin, model.joints[0].axis):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


LINK = ('<link name="{n}"><inertial><origin xyz="{o}"/><mass value="{m}"/>'
        '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>')


def two_links(joint_type="revolute", axis='<axis xyz="0 0 1"/>', mass="2", origin="0 0 0", parent='<parent link="a"/>'):
    """Two links on one joint, parts given as URDF text."""
    return (f'<robot name="t">{LINK.format(n="a", o="0 0 0", m="1")}{LINK.format(n="b", o=origin, m=mass)}'
            f'<joint name="j1" type="{joint_type}">{parent}<child link="b"/>{axis}'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')


@pytest.mark.parametrize(("text", "message"), [
    (two_links(mass="heavy"), "link 'b' <mass value=\"heavy\">: 'heavy' is not a number"),
    (two_links(origin="0 0"), "link 'b' <origin xyz=\"0 0\">: 2 numbers; 3 expected"),
    (two_links(axis='<axis xyz="0 0 z"/>'), "joint 'j1' <axis xyz=\"0 0 z\">: not three numbers"),
    (two_links(axis="<axis/>"), "joint 'j1' <axis>: no 'xyz' attribute"),
    (two_links(joint_type="hinge"), "joint 'j1' <joint type=\"hinge\">: 'hinge' is no URDF joint type"),
    (two_links(parent=""), "joint 'j1' <joint>: no <parent>"),
    (two_links(parent="<parent/>"), "joint 'j1' <parent>: no 'link' attribute"),
    (two_links().replace('<mass value="2"/>', "<mass/>"), "link 'b' <mass>: no 'value' attribute"),
    (two_links().replace('<mass value="2"/>', ""), "link 'b' <inertial>: no <mass>"),
    (two_links().replace('ixy="0" ixz="0" iyz="0"/></inertial></link><joint', 'ixy="0" ixz="0"/></inertial></link><joint'),
     "link 'b' <inertia>: no 'iyz' attribute"),
    (two_links().replace('<link name="b">', "<link>"), "a <link>: no 'name' attribute"),
    (two_links().replace('<joint name="j1"', "<joint"), "a <joint>: no 'name' attribute"),
    (two_links().replace('type="revolute"', ""), "joint 'j1' <joint>: no 'type' attribute"),
    (two_links().replace('<robot name="t">', "<robot>"), "the <robot>: no 'name' attribute"),
    (two_links(axis='<axis xyz="0 0 1"/><dynamics damping="-0.1"/>'),
     "joint 'j1' <dynamics damping=\"-0.1\">: negative: friction dissipates energy"),
    (two_links(axis='<axis xyz="0 0 1"/><dynamics friction="soft"/>'),
     "joint 'j1' <dynamics friction=\"soft\">: 'soft' is not a number"),
    ("<urdf></urdf>", "the root element is <urdf>, not <robot>"),
])
def test_malformed_files_are_refused_naming_file_element_and_attribute(tmp_path, text, message):
    """Missing attributes, bad numbers, vectors of other than three numbers, unknown joint types,
    a negative <dynamics> coefficient and a bare <axis> (urdfdom reads a zero axis, yourdfpy (1, 0, 0)) are refused by the loader
    naming the file and the place."""
    with pytest.raises(RobotModelError) as err:
        load_text(tmp_path, text, visuals=False)
    assert str(err.value).startswith(f"{tmp_path / 'robot.urdf'}: ") and message in str(err.value)

