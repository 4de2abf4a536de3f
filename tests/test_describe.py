"""Tests of freefloat.robot.describe: what ``freefloat info`` prints about a robot."""

from __future__ import annotations

from freefloat.app.cli import main
from freefloat.paths import URDF_DIR


def test_info_warns_about_a_missing_mesh_naming_its_link_and_file(tmp_path, capsys):
    """A URDF whose link names a mesh file that is not there: ``freefloat info`` lists the
    warning with the link and the file, as ``simulate`` would warn."""
    text = (URDF_DIR / "two_arm_planar.urdf").read_text()
    text = text.replace('<link name="arm1_link2">',
                        '<link name="arm1_link2"><visual><geometry><mesh filename="meshes/gone.stl"/></geometry></visual>', 1)
    assert "gone.stl" in text
    (tmp_path / "robot.urdf").write_text(text)
    assert main(["info", str(tmp_path / "robot.urdf")]) == 0
    warnings = capsys.readouterr().out.split("  warnings:")[-1]
    assert "link 'arm1_link2': 'meshes/gone.stl'" in warnings
