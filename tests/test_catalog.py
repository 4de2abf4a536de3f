"""Robots by name: freefloat's own and example-robot-data's."""

from __future__ import annotations

import warnings

import pytest

from freefloat import RobotModelError, load_robot
from freefloat.errors import FreefloatNote
from freefloat.paths import URDF_DIR
from freefloat.robot.catalog import find_robot, is_name, robots


def test_names_find_the_files():
    """Stems, stems without _robot, and the talos alias name the files they should."""
    assert find_robot("four_arm_planar") == URDF_DIR / "four_arm_planar.urdf"
    assert find_robot("ur5").name == "ur5_robot.urdf" and find_robot("solo12").name == "solo12.urdf"
    assert find_robot("talos").name == "talos_reduced.urdf"
    assert set(robots()) >= {"panda", "ur5", "solo12", "talos", "romeo", "dual_arm_satellite"}


def test_load_robot_takes_a_name():
    """load_robot('ur5') loads example-robot-data's UR5 (6 joints on a free base)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot("ur5", visuals=False)
    assert robot.n_joints == 6 and robot.urdf_path.name == "ur5_robot.urdf"


def test_unknown_names_suggest_the_nearest_ones():
    """A mistyped name is refused with the nearest known names first, and the list cut to a few
    names that says where to see them all (it listed about 80)."""
    with pytest.raises(RobotModelError, match=r"'ur55' is neither .*; did you mean 'ur5'\?") as ur:
        find_robot("ur55")
    with pytest.raises(RobotModelError, match=r"did you mean 'talos'") as talos:
        find_robot("talso")
    for error in (ur, talos):
        assert "more, listed by freefloat robots" in str(error.value) and len(str(error.value)) < 450


def test_an_alias_says_which_file_it_picked():
    """'talos' names one of several TALOS files: a note says which, and names the others."""
    with pytest.warns(FreefloatNote, match=r"robot 'talos' is talos_reduced\.urdf \(others: .*talos_full_v2"):
        picked = find_robot("talos")
    assert picked.name == "talos_reduced.urdf"


def test_paths_are_not_names():
    """Anything with a folder or a suffix is a path, not a name."""
    assert is_name("ur5") and not is_name("ur5.urdf") and not is_name("robots/ur5")
