"""Tests of freefloat.app.viz.mechanism_page: a mechanism run's page, the linkage drawn bar by bar
between the joint centres, the closure points and the platform."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat.app.viz.mechanism_page import closure_markers, linkage_bars, write_mechanism_html
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.five_bar import elbow_guess

from .conftest import REPO
from .pages import animation as _animation
from .pages import objects as _objects
from .pages import packets as _packets

ROOT = "/meshcat/freefloat"


@pytest.fixture(scope="module")
def five_bar():
    return load_closed_chain(REPO / "urdf" / "five_bar.closure.toml")


def test_closure_points_meet_on_an_assembled_mechanism_and_part_on_a_broken_one(five_bar):
    """Both points of the 5R's closure coincide (1e-9 m) at an assembled configuration and are
    apart when a joint is moved off it."""
    from freefloat.parallel.five_bar import FiveBarParameters

    point = np.array([0.07, 0.17])
    q = five_bar.mechanism.assemble(point, elbow_guess(FiveBarParameters(), point))
    tree_q = np.array([five_bar.pinocchio_q(q), five_bar.pinocchio_q(q + np.r_[0.0, 0.0, 0.1, 0.0, 0.0, 0.0])])
    first, second = (m.positions for m in closure_markers(five_bar, tree_q))
    assert np.linalg.norm(first[0] - second[0]) < 1e-9 and np.linalg.norm(first[1] - second[1]) > 1e-3


def _bars(page) -> dict[str, np.ndarray]:
    """{bar name: its two ends at every key frame (K, 2, 3)} read back from a page: each bar is a
    unit cylinder along its node's y axis, placed by the position, quaternion and scale tracks."""
    out = {}
    for path, tracks in _animation(_packets(page)).items():
        if path.startswith(f"{ROOT}/bars/"):
            ends = []
            keys = zip(tracks[".position"], tracks[".quaternion"], tracks[".scale"])
            for (_, middle), (_, quaternion), (_, scale) in keys:
                half = pin.Quaternion(np.array(quaternion)).matrix() @ [0.0, scale[1] / 2, 0.0]
                ends.append([np.array(middle) - half, np.array(middle) + half])
            out[path.removeprefix(f"{ROOT}/bars/")] = np.array(ends)
    return out


def _matching(bars: dict[str, np.ndarray], a: np.ndarray, b: np.ndarray) -> list[str]:
    """The bars joining a (K, 3) and b (K, 3) at every key frame, either way round (1e-9 m)."""
    def joins(ends: np.ndarray, p: np.ndarray, r: np.ndarray) -> bool:
        return np.abs(ends[:, 0] - p).max() < 1e-9 and np.abs(ends[:, 1] - r).max() < 1e-9

    return [name for name, ends in bars.items() if joins(ends, a, b) or joins(ends, b, a)]


def test_five_bar_page_draws_two_arms_from_the_pivots_to_the_end_effector(five_bar, tmp_path):
    """The 5R's page has exactly four bars, one per link: pivot (+-l0, 0) to elbow and elbow to
    the end-effector (x, y) for each arm, the elbows computed here from the DH data (chain 2's
    base mirrored by diag(-1, 1, -1): its angles turn the other way in x) at every key frame of a
    run around a circle."""
    from freefloat.parallel.five_bar import FiveBarParameters

    p = FiveBarParameters()
    t = np.linspace(0.0, 1.0, 11)
    points = np.column_stack((0.03 * np.cos(2 * np.pi * t), 0.17 + 0.03 * np.sin(2 * np.pi * t)))
    q = np.array([five_bar.mechanism.assemble(x, elbow_guess(p, x)) for x in points])  # [x, y, q11, q12, q21, q22]
    bars = _bars(write_mechanism_html(five_bar, t, q, tmp_path / "five_bar.html", fps=10.0))
    tip = np.column_stack((q[:, :2], np.zeros(len(t))))
    for side, (first, second) in ((+1, (q[:, 2], q[:, 3])), (-1, (q[:, 4], q[:, 5]))):
        pivot = np.tile([side * p.l0, 0.0, 0.0], (len(t), 1))
        elbow = pivot + p.l1 * np.column_stack((side * np.cos(first), np.sin(first), np.zeros(len(t))))
        distal = np.column_stack((side * np.cos(first + second), np.sin(first + second), np.zeros(len(t))))
        np.testing.assert_allclose(elbow + p.l2 * distal, tip, atol=1e-9)  # assembled
        assert len(_matching(bars, pivot, elbow)) == 1 and len(_matching(bars, elbow, tip)) == 1
    assert len(bars) == 4


def test_rsu_ppap_page_draws_cranks_and_rods_to_the_platform(tmp_path):
    """Each RSU leg of the 2RSU+PPaP's page has a crank bar from its pivot (data file) turned by
    the crank angle about y, and a rod bar from the crank tip to the platform centre q# plus the
    leg's attachment offset; the platform is drawn as bars from q# to both attachments."""
    from freefloat.parallel.registry import REGISTRY
    from freefloat.parallel.rsu_ppap import CLOSURE, load_data

    data, setup = load_data(), REGISTRY["rsu_ppap"].build(CLOSURE, "nominal")
    t = np.linspace(0.0, 1.0, 6)
    home = np.array(data["home"])
    centres = home + np.column_stack((0.04 * np.cos(2 * np.pi * t), 0.03 * np.sin(2 * np.pi * t), 0.02 * t))
    q = np.array([setup.plant.assemble(x, setup.guess(x)) for x in centres])
    bars = _bars(write_mechanism_html(setup.display, t, q, tmp_path / "rsu_ppap.html", fps=5.0))
    rsu = data["rsu"]
    for leg in range(2):
        crank = q[:, 3 + 6 * leg]  # q = [q#; rsu1 (crank, s1, s2, s3, u1, u2); rsu2 (...); ppap (...)]
        pivot = np.tile(rsu["pivot"][leg], (len(t), 1))
        arm = np.multiply(rsu["crank"][leg], rsu["crank_length"])  # the crank at zero angle
        tip = pivot + np.array([pin.exp3(np.array([0.0, a, 0.0])) @ arm for a in crank])
        attach = q[:, :3] + data["platform"]["attach"][leg]
        np.testing.assert_allclose(np.linalg.norm(attach - tip, axis=1), rsu["rod_length"], atol=1e-9)  # assembled
        assert len(_matching(bars, pivot, tip)) == 1 and len(_matching(bars, tip, attach)) == 1
        assert len(_matching(bars, q[:, :3], attach)) == 1


def test_mechanism_page_draws_no_link_geometry_of_the_urdf(five_bar, tmp_path):
    """Only the base comes from the URDF (the 5R's bar between its pivots, half transparent): its
    fat link cylinders and end-effector spheres are not drawn; the platform path and the
    reference path are."""
    from freefloat.parallel.five_bar import FiveBarParameters

    point = np.array([0.0, 0.17])
    q = np.tile(five_bar.mechanism.assemble(point, elbow_guess(FiveBarParameters(), point)), (3, 1))
    page = write_mechanism_html(five_bar, np.arange(3.0), q, tmp_path / "page.html", fps=1.0, reference=q[:, :2])
    drawn = _objects(page)
    geometry = [path for path in drawn if path.startswith(ROOT) and path.split("/")[3] not in
                ("bars", "markers", "paths", "lines")]
    assert geometry == [f"{ROOT}/base/base_link_0"]
    assert drawn[geometry[0]]["materials"][0]["opacity"] == 0.5
    assert f"{ROOT}/paths/platform" in drawn and f"{ROOT}/lines/platform_reference" in drawn


def test_page_carries_the_linkage_with_the_base(five_bar, tmp_path):
    """On a moving base every bar of the page is the fixed-base bar carried by the base's
    placement at that sample (moved and turned)."""
    from freefloat.parallel.five_bar import FiveBarParameters

    point = np.array([0.05, 0.16])
    q = np.tile(five_bar.mechanism.assemble(point, elbow_guess(FiveBarParameters(), point)), (3, 1))
    poses = [pin.SE3(pin.exp3(np.array([0.0, 0.0, yaw])), np.array([0.1 * yaw, -0.2, 0.0])) for yaw in (0.0, 0.4, 1.1)]
    page = write_mechanism_html(five_bar, np.arange(3.0), q, tmp_path / "page.html", fps=1.0,
                                base=np.array([m.homogeneous for m in poses]))
    drawn = _bars(page)
    for bar in linkage_bars(five_bar, np.array([five_bar.pinocchio_q(qk) for qk in q])):
        carried = [np.array([m.act(bar.start[k]), m.act(bar.end[k])]) for k, m in enumerate(poses)]
        np.testing.assert_allclose(drawn[bar.name], carried, atol=1e-9)
