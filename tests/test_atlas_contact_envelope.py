"""Atlas kind ``contact_envelope``: a capture by contact mapped by approach speed and stiffness;
each point's outcome is the scene's own run at those settings."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import freefloat
from freefloat.app.atlas.engine import run_atlas
from freefloat.app.atlas.kinds import Options
from freefloat.app.experiments.contact_capture import OUTCOMES, at_approach
from freefloat.app.scenes import find_scene
from freefloat.errors import InvalidArgument, SceneError


@pytest.fixture(scope="module")
def envelope(tmp_path_factory):
    """contact_capture mapped on a 2 x 2 grid (the corners of the default plane)."""
    return run_atlas("contact_envelope", "contact_capture", Options(grid=2), tmp_path_factory.mktemp("atlas") / "map")


@pytest.mark.slow
def test_the_map_is_written_with_its_summary_and_figure(envelope):
    """The folder holds the data, the summary's outcome counts and the figure; the axes span half
    to ten times the latch speed and a tenth to a hundred times the scene's stiffness."""
    names = {p.name for p in envelope.written}
    assert {"atlas.npz", "summary.json", "contact_envelope.png"} <= names
    speed, stiffness = envelope.grid.axes
    assert (speed.low, speed.high) == pytest.approx((0.01, 0.2))
    assert (stiffness.low, stiffness.high) == pytest.approx((3.0, 6.0))
    counts = [envelope.summary["summary"][name] for name in OUTCOMES]
    assert sum(counts) == 4 and envelope.result["outcome"].shape == (4,)
    assert (envelope.folder / "contact_envelope.png").stat().st_size > 10_000


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 3])
def test_a_point_agrees_with_the_scene_run_at_its_settings(envelope, index):
    """At the slow soft corner (latched) and the fast stiff corner (rebound) the map's outcome and
    peak force are those of the whole scene run at that speed and stiffness."""
    speed, log_stiffness = envelope.grid.points()[index]
    scene = at_approach(find_scene("contact_capture"), float(speed), 10.0 ** float(log_stiffness))
    scene = dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False, html=False))
    summary = freefloat.simulate(scene).summary
    outcome = OUTCOMES[envelope.result["outcome"][index]]
    assert outcome == ("latched", "rebound")[index // 3]
    assert summary["captured"] == (outcome == "latched") and summary["rebound"] == (outcome == "rebound")
    if outcome == "latched":
        assert summary["latch_time"] == pytest.approx(envelope.result["latch_time"][index], abs=1e-12)
    else:
        assert np.isnan(envelope.result["latch_time"][index])
    # the peak force is the largest at a period end: the map stops at its decision, after the peak
    assert summary["contact_peak_force"] == pytest.approx(envelope.result["peak_force"][index], rel=1e-9)


def test_an_interrupted_point_interrupts_the_chunk():
    """A stop request (Ctrl-C, SIGTERM) during a point raises KeyboardInterrupt instead of
    recording the cut run's outcome, so the engine journals no unfinished chunk."""
    from freefloat.app.atlas import contact_envelope
    from freefloat.dynamics.stop_request import stopping

    context = contact_envelope.prepare("contact_capture", Options())
    with stopping(), pytest.raises(KeyboardInterrupt):
        contact_envelope.evaluate(context, np.array([[0.01, 4.0]]))


def test_a_scene_without_a_latch_is_refused():
    """A scene that is not a capture by contact is refused naming it."""
    with pytest.raises(SceneError, match="'tumbling' is not a capture by contact"):
        run_atlas("contact_envelope", "tumbling", Options(), None)


def test_an_option_it_does_not_take_is_refused():
    """``--axes`` is not an option of this kind."""
    with pytest.raises(InvalidArgument, match="does not take --axes"):
        run_atlas("contact_envelope", "contact_capture", Options(axes=("x", "y")), None)


@pytest.mark.slow
def test_every_unit_names_a_key_of_the_summary(envelope):
    """SUMMARY_UNITS (what the terminal prints after a value) names keys the summary has."""
    from freefloat.app.atlas import contact_envelope

    assert set(contact_envelope.SUMMARY_UNITS) <= set(envelope.summary["summary"])
