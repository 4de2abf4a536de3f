"""Atlas kind ``mechanism`` (freefloat.app.atlas.mechanism_maps) through the engine: the 5R's task
map agrees with its closed-form workspace and its loci are singular by SVD, joint-space maps
come from --axes naming actuated joints, the scenes' mode is the one their start assembles in,
map points are reached by a simulated motion (mechanism_reach), and bad targets or axes are
refused by name."""

from __future__ import annotations

import json

import numpy as np
import pytest

from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.kinds import KINDS, Options
from freefloat.app.atlas.mechanism_reach import drive_to, targets
from freefloat.app.atlas.mechanism_targets import scene_of, setup_of
from freefloat.errors import InvalidArgument, UnknownName
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.maps import five_bar_exact
from freefloat.parallel.maps.modes import assembly_label, working_label
from freefloat.parallel.maps.solve import wrap


def test_the_kind_is_registered():
    """``freefloat atlas mechanism`` names this kind's module."""
    assert KINDS["mechanism"].load().__name__.endswith("mechanism_maps")


@pytest.mark.slow
def test_five_bar_task_map_through_the_engine(tmp_path):
    """A 21 x 21 task map of the 5R: every point agrees with the annuli, the type I points sit on
    the circles and both loci's blocks are singular by SVD, the scenes' mode is the outward-elbow
    start's label, and the data, summary and figure are written."""
    done = run_atlas("mechanism", "five_bar", Options(grid=21), tmp_path / "a")
    s = done.summary["summary"] if "summary" in done.summary else done.summary
    p = FiveBarParameters()
    start = np.array([0.07, 0.17])
    assert s["scene_mode"] == str(working_label(five_bar(p), five_bar(p).assemble(start, elbow_guess(p, start))))
    assert s["disagree_with_annuli"] == 0
    np.testing.assert_array_equal(done.result["found"].any(axis=1), five_bar_exact.contains(p, done.grid.points()))
    assert s["type_I_points"] > 0 and s["type_II_points"] > 0
    assert s["type_I_ratio_max"] < 1e-4 and s["type_II_ratio_max"] < 1e-6
    assert s["type_I_distance_to_circles_max"] < 1e-9
    names = {path.name for path in done.written}
    assert {"atlas.npz", "summary.json", "modes.png"} <= names
    assert json.loads((tmp_path / "a" / "summary.json").read_text())


@pytest.mark.slow
def test_joint_space_map_from_actuated_axes(tmp_path):
    """--axes c1_joint1,c2_joint1 maps both assembly modes over the actuated joints; the scenes'
    mode is the sign of their start's direct block."""
    done = run_atlas("mechanism", "five_bar", Options(grid=15, axes=("c1_joint1", "c2_joint1")), tmp_path / "j")
    s = done.summary["summary"] if "summary" in done.summary else done.summary
    p = FiveBarParameters()
    start = np.array([0.07, 0.17])
    assert s["space"] == "joint" and s["modes"] == ["+", "-"]
    assert s["scene_mode"] == str(assembly_label(five_bar(p), five_bar(p).assemble(start, elbow_guess(p, start))))
    assert done.result["found"].shape == (15 * 15, 2) and done.result["found"].any()


@pytest.mark.slow
def test_rsu_ppap_plane_holds_y_at_the_scenes_start(tmp_path):
    """The 2RSU+PPaP's default plane (x, z) holds y at the scenes' start, and the start's own
    grid neighbourhood has the scenes' mode."""
    done = run_atlas("mechanism", "rsu_ppap", Options(grid=5), tmp_path / "r")
    s = done.summary["summary"] if "summary" in done.summary else done.summary
    assert s["held"] == {"y": 0.0} and s["scene_mode"] in s["modes"]
    assert s["per_mode"][s["scene_mode"]] > 0


@pytest.mark.slow
def test_three_axes_give_slices_a_scatter_and_a_meshcat_page(tmp_path):
    """A 3-D grid of the 2RSU+PPaP writes slices, a 3-D scatter and a self-contained meshcat page
    (of the point cloud of the scenes' mode about the mechanism)."""
    done = run_atlas("mechanism", "rsu_ppap", Options(grid=3, axes=("x", "y", "z")), tmp_path / "c")
    names = {path.name for path in done.written}
    assert {"slices.png", "workspace_3d.png", "workspace.html"} <= names
    assert (tmp_path / "c" / "workspace.html").read_text().rstrip().endswith("</html>")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["five_bar", "rsu_ppap"])
def test_workspace_points_are_reached_by_a_simulated_motion(name):
    """Three map points in the scenes' working mode within 3 cm of the scenes' start are reached
    by the plant (Orsino's coupled chains on the one loop, RKMK4) under computed torque along a
    quintic line from the start (freefloat.app.atlas.mechanism_reach): it ends there, in the same
    working mode, at the map's actuated joints (angles modulo 2 pi)."""
    mech = setup_of(name).nominal
    mode = str(working_label(mech, scene_of(name)[1]))
    points, expected = targets(name, 3, seed=3, half=0.03)
    for target, q_map in zip(points, expected):
        arrival = drive_to(name, target)
        assert arrival.status == "completed" and arrival.mode == mode
        np.testing.assert_allclose(arrival.q[: mech.p], target, atol=1e-6)
        np.testing.assert_allclose(wrap(mech, arrival.q - q_map)[mech.actuated], 0.0, atol=1e-6)


@pytest.mark.parametrize("target, axes, error, match", [
    ("six_bar", None, UnknownName, "five_bar"),
    ("five_bar", ("x", "z"), InvalidArgument, "platform coordinates"),
    ("five_bar", ("x", "c1_joint1"), InvalidArgument, "actuated joints"),
])
def test_bad_targets_and_axes_are_named(tmp_path, target, axes, error, match):
    """An unknown mechanism lists the known ones; axes mixing spaces or naming no coordinate are refused."""
    with pytest.raises(error, match=match):
        run_atlas("mechanism", target, Options(axes=axes), tmp_path / "x")
