"""Atlas kind capture_envelope: each mapped point's outcome is the planned scene's own verdict at
that meeting point, and a graspable point is grasped in a simulated run through the one loop."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from freefloat.app.atlas.capture_envelope import OUTCOMES
from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.kinds import Options
from freefloat.errors import InvalidArgument, SceneError

from .conftest import scene_variant

WORDS = {"reach": "out of reach", "joint_rate": "joint rate limit", "torque": "torque limit"}


@pytest.fixture(scope="module")
def envelope(tmp_path_factory):
    """A 3 x 3 envelope of a short capture_planned_planar (1 s approach, 60-step grid)."""
    folder = tmp_path_factory.mktemp("envelope")
    scene = scene_variant(folder / "s.toml", "capture_planned_planar", target={"contact_time": 1.0},
                          approach={"steps": 60}, simulation={"duration": 0.02},
                          output={"figures": False, "html": False})
    return scene, run_atlas("capture_envelope", str(scene), Options(grid=3), folder / "out")


@pytest.mark.slow
def test_every_outcome_is_the_scenes_own_verdict_at_that_point(envelope):
    """Preparing the scene with each mapped reach succeeds exactly where the map says graspable,
    and is refused for the reason the map names elsewhere."""
    from freefloat.app.runner import prepare
    from freefloat.app.scenes import load_scene

    path, atlas = envelope
    scene = load_scene(path)
    outcomes = atlas.result["outcome"]
    assert (outcomes == 0).any() and (outcomes != 0).any()
    for point, outcome in zip(atlas.grid.points(), outcomes):
        variant = dataclasses.replace(scene, approach=dataclasses.replace(scene.approach, reach=(*point, 0.0)))
        if outcome == 0:
            assert prepare(variant).plan is not None
        else:
            with pytest.raises(SceneError, match=WORDS[OUTCOMES[outcome]]):
                prepare(variant)


@pytest.mark.slow
def test_a_graspable_point_is_grasped_in_a_simulated_run(envelope):
    """The graspable point farthest from the hand's start, run as the scene through the one loop:
    the hand meets the grasp point at the contact time within the contact tolerance."""
    from freefloat.app.runner import simulate
    from freefloat.app.scenes import load_scene

    path, atlas = envelope
    points = atlas.grid.points()[atlas.result["outcome"] == 0]
    point = points[np.argmax(np.linalg.norm(points, axis=1))]
    scene = load_scene(path)
    s = simulate(dataclasses.replace(scene, approach=dataclasses.replace(scene.approach, reach=(*point, 0.0)))).summary
    assert s["impact_time"] == pytest.approx(scene.target.contact_time)
    assert s["grasp_position_mismatch"] < scene.target.tolerance
    assert atlas.summary["summary"]["graspable"] == int((atlas.result["outcome"] == 0).sum())


def test_a_scene_without_an_approach_or_bad_axes_is_refused(tmp_path):
    """capture_planar has no [approach]: refused by name; --axes must be two of x, y, z."""
    with pytest.raises(SceneError, match="not a one-hand capture with an \\[approach\\]"):
        run_atlas("capture_envelope", "capture_planar", Options(grid=3), tmp_path / "a")
    with pytest.raises(InvalidArgument, match="two distinct coordinates"):
        run_atlas("capture_envelope", "capture_planned_planar", Options(grid=3, axes=("x", "w")), tmp_path / "b")


def test_the_default_envelope_is_journaled_in_chunks_of_a_few_plans():
    """The 11 x 11 envelope is cut into chunks of at most 16 points on one worker (a few seconds of
    plans each), not one chunk of 121 that an interrupt would lose whole."""
    from freefloat.app.atlas import capture_envelope
    from freefloat.app.atlas.engine import chunk_size
    from freefloat.app.atlas.grid import Axis, Grid

    grid = Grid((Axis("x", -1, 1, capture_envelope.POINTS, "m"), Axis("y", -1, 1, capture_envelope.POINTS, "m")))
    size = chunk_size(grid, 1, capture_envelope.MIN_CHUNK)
    assert size <= 16 and len(grid.chunks(size)) >= 8


@pytest.mark.slow
def test_every_unit_names_a_key_of_the_summary(envelope):
    """SUMMARY_UNITS (what the terminal prints after a value) names keys the summary has."""
    from freefloat.app.atlas import capture_envelope

    assert set(capture_envelope.SUMMARY_UNITS) <= set(envelope[1].summary["summary"])
