"""URDF checks: hostile, malformed and physically impossible files are refused or noted with the
file, link, joint and attribute named; the two URDF parsers must agree."""

from __future__ import annotations

import warnings

import pytest

from freefloat import RobotModelError, load_robot
from freefloat.errors import FreefloatNote
from freefloat.robot import urdf_checks
from freefloat.robot.loading import FreefloatWarning, example_robot_data_share
from freefloat.robot.urdf_checks import compare_parses
from freefloat.robot.urdf_model import parse_urdf

from .conftest import load_text

LINK = ('<link name="{n}"><inertial><origin xyz="{o}"/><mass value="{m}"/>'
        '<inertia ixx="{i}" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>')
JOINT = ('<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="{a}"/>'
         '<limit lower="{lo}" upper="{hi}" effort="1" velocity="1"/></joint>')


def two_link(m1="2", i1="1", o1="0 0 0", axis="0 0 1", lo="-1", hi="1", joint2="j2") -> str:
    """A base and two links on revolute joints, with the values given as URDF text."""
    links = [LINK.format(n="base", o="0 0 0", m="10", i="1"), LINK.format(n="l1", o=o1, m=m1, i=i1),
             LINK.format(n="l2", o="0 0 0", m="1", i="1")]
    joints = [JOINT.format(n="j1", p="base", c="l1", a=axis, lo=lo, hi=hi),
              JOINT.format(n=joint2, p="l1", c="l2", a="1 0 0", lo="-1", hi="1")]
    return '<robot name="t">' + "".join(links + joints) + "</robot>"


def notes_of(tmp_path, text: str) -> list[str]:
    path = tmp_path / "r.urdf"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        load_robot(path, visuals=False)
    return [str(w.message) for w in caught]


@pytest.mark.parametrize("doctype", [
    '<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',  # entity expansion
    '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>',  # external entity
])
def test_dtds_and_entities_are_refused(tmp_path, doctype):
    """A URDF declaring entities (billion laughs, XXE) is refused before any parser expands them."""
    text = two_link().replace('<robot name="t">', doctype + '<robot name="&x;">' if "SYSTEM" in doctype
                              else doctype + '<robot name="&b;">')
    with pytest.raises(RobotModelError, match="DTD or entities"):
        load_text(tmp_path, text)


@pytest.mark.parametrize(("edit", "where"), [
    (dict(m1="nan"), "link 'l1' <mass value"),
    (dict(i1="inf"), "link 'l1' <inertia ixx"),
    (dict(o1="0 nan 0"), "link 'l1' <origin xyz"),
    (dict(axis="0 0 -inf"), "joint 'j1' <axis xyz"),
    (dict(hi="nan"), "joint 'j1' <limit upper"),
])
def test_non_finite_numbers_are_named(tmp_path, edit, where):
    """NaN or inf anywhere is refused naming the link or joint, element and attribute (urdfdom
    would silently drop the inertia or the whole <inertial>)."""
    with pytest.raises(RobotModelError, match=where):
        load_text(tmp_path, two_link(**edit))


def test_duplicate_joint_names_are_refused(tmp_path):
    """Two joints of one name are refused naming it."""
    with pytest.raises(RobotModelError, match="joint 'j1' is defined 2 times"):
        load_text(tmp_path, two_link(joint2="j1"))


def test_a_mimic_joint_naming_no_joint_is_refused(tmp_path):
    """A <mimic joint="..."> that names no joint of the file is refused naming both joints."""
    text = two_link().replace('<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>',
                              '<limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j9"/></joint></robot>')
    with pytest.raises(RobotModelError, match="joint 'j2' <mimic joint=\"j9\">: no joint of that name"):
        load_text(tmp_path, text)


def test_an_over_long_link_name_is_refused(tmp_path):
    """A link name of 200 000 characters is refused up front (drawing its legend hung)."""
    text = two_link().replace('"l2"', '"' + "L" * 200_000 + '"')
    with pytest.raises(RobotModelError, match=f"200000 characters; at most {urdf_checks.MAX_NAME}"):
        load_text(tmp_path, text)


@pytest.mark.parametrize(("text", "message"), [
    (two_link()[:-40], "not well-formed XML at line 1"),
    ("<robot name='r'><link name='a'>" + "<x>" * 100_000 + "</x>" * 100_000 + "</link></robot>", "nested more than 64 levels"),
])
def test_malformed_xml_is_named(tmp_path, text, message):
    """Truncated or absurdly nested XML is refused with the place, not a parser traceback."""
    with pytest.raises(RobotModelError, match=message):
        load_text(tmp_path, text)


def test_non_utf8_files_are_refused(tmp_path):
    """Bytes that are not UTF-8 are refused naming the byte."""
    path = tmp_path / "r.urdf"
    path.write_bytes(two_link().encode("utf-16"))
    with pytest.raises(RobotModelError, match="not UTF-8"):
        load_robot(path)


def test_parsers_that_disagree_are_refused(tmp_path):
    """A body whose mass differs between Pinocchio's model and freefloat's parse is refused."""
    robot = load_text(tmp_path, two_link(), visuals=False)
    parsed = parse_urdf(robot.urdf_path, urdf_checks.read_urdf(robot.urdf_path))
    compare_parses(robot.urdf_path, robot.model, parsed)  # the loaded robot agrees
    robot.model.inertias[2].mass = 0.5 * robot.model.inertias[2].mass
    with pytest.raises(RobotModelError, match="joint 'j1' has mass 1 kg in Pinocchio's parse but 2 kg"):
        compare_parses(robot.urdf_path, robot.model, parsed)


def test_impossible_inertias_and_inverted_limits_are_noted(tmp_path):
    """Inertias that break the triangle inequality and lower > upper limits load with a note of
    at most two lines that says what to do."""
    notes = notes_of(tmp_path, two_link(i1="5", lo="1", hi="-1"))
    triangle = next(n for n in notes if "I1 + I2 >= I3" in n)
    assert "worst l1" in triangle and "check the links' <inertia>" in triangle and 'inertias = "balanced"' in triangle
    assert any("j1 have lower limit > upper limit; swap them" in n for n in notes)
    assert all(len(n.splitlines()) <= 2 for n in notes)


def test_the_dissertation_robot_s_inertias_are_a_one_line_note():
    """The built-in four-arm robot's inertias are the dissertation's on purpose: a one-line note (not
    a warning) says so, with the count and how to run a physical copy; the robot records it."""
    with pytest.warns(FreefloatWarning) as caught:
        robot = load_robot("four_arm_planar", visuals=False)
    notes = [w for w in caught if "I1 + I2 >= I3" in str(w.message)]
    assert len(notes) == 1 and notes[0].category is FreefloatNote
    note = str(notes[0].message)
    assert len(note.splitlines()) == 1 and "as the dissertation prints them" in note and "16 links" in note
    assert 'inertias = "balanced"' in note and robot.notes == (note,) and not robot.warnings


def test_a_joint_that_moves_no_mass_is_named(tmp_path):
    """A revolute joint carrying only massless links makes the mass matrix singular: named."""
    text = two_link().replace('<mass value="1"/><inertia ixx="1" iyy="1" izz="1"',
                              '<mass value="0"/><inertia ixx="0" iyy="0" izz="0"')
    assert any("joints j2 move only massless links" in n for n in notes_of(tmp_path, text))


def test_a_robot_without_mass_is_refused(tmp_path):
    """Every link massless: refused, not a LinAlgError later."""
    text = two_link(m1="0", i1="0").replace('value="10"', 'value="0"').replace('value="1"', 'value="0"')
    text = text.replace('ixx="1" iyy="1" izz="1"', 'ixx="0" iyy="0" izz="0"')
    with pytest.raises(RobotModelError, match="every link is massless"):
        load_text(tmp_path, text)


def test_a_robot_too_big_for_memory_is_refused_with_the_estimate(tmp_path, monkeypatch):
    """A model whose Pinocchio Data would not fit is refused before Pinocchio builds it."""
    monkeypatch.setattr(urdf_checks, "MEMORY_SHARE", 1e-9)
    with pytest.raises(RobotModelError, match=r"2 movable joints: a simulation would need about .* GB"):
        load_text(tmp_path, two_link())


def test_end_effectors_must_be_a_list_not_a_string(tmp_path):
    """A single string is refused (it used to be read character by character)."""
    with pytest.raises(RobotModelError, match=r"write \['l2'\]"):
        load_text(tmp_path, two_link(), end_effectors="l2")


def test_massless_root_welded_to_a_body_is_not_called_singular():
    """UR5's massless root is welded to a massive body: no singular-matrix note; romeo's 24
    massless finger joints are named."""
    share = example_robot_data_share() / "example-robot-data" / "robots"
    for name, singular in (("ur_description/urdf/ur5_robot.urdf", False), ("romeo_description/urdf/romeo.urdf", True)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            load_robot(share / name, visuals=False)
        assert any("singular" in str(w.message) and "massless" in str(w.message) for w in caught) == singular, name
