"""A capture scene with ``[identification]``: the built-in ``capture_identified`` identifies the
grasped box within the issue's aims and its own intervals, against the true box the scene
describes, then detumbles it on the identified model; bad keys are named."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from freefloat import SceneError
from freefloat.app.runner import prepare, simulate
from freefloat.app.scenes import builtin_scenes, load_scene, parse_scene

SCENE = "capture_identified"


def scene_of(name: str = SCENE, **edits: dict):
    """The built-in scene ``name`` with each ``edits`` section updated (or added), parsed."""
    raw = tomllib.loads(builtin_scenes()[name].read_text())
    for section, keys in edits.items():
        raw.setdefault(section, {}).update(keys)
    return parse_scene(raw, source=builtin_scenes()[name])


@pytest.fixture(scope="module")
def outcome():
    """capture_identified run once (10 s of manoeuvre, 1 s of detumbling)."""
    return simulate(scene_of())


@pytest.mark.slow
def test_the_box_is_identified_within_the_aims(outcome):
    """At 1 % noise after 10 s the mass is within 1 % and the inertia within 5 % (Frobenius) of
    the scene's box (50 kg, principal moments 2, 2.5, 3 kg m^2), the CoM within 1 mm of the truth,
    0.25 m from the hand (the grasp offset, closed within the scene's 1 mm tolerance)."""
    s = outcome.summary
    assert s["target_mass_true"] == pytest.approx(50.0, rel=1e-12)
    assert np.linalg.eigvalsh(np.array(s["target_inertia_true"])) == pytest.approx([2.0, 2.5, 3.0], rel=1e-9)
    assert np.linalg.norm(s["target_com_true"]) == pytest.approx(0.25, abs=1e-3)  # grasped within target.tolerance
    assert abs(s["target_mass_error"]) < 0.01 and s["target_inertia_error"] < 0.05 and s["target_com_error"] < 1e-3
    assert s["target_mass_estimate"] == pytest.approx(s["target_mass_true"] * (1 + s["target_mass_error"]), rel=1e-12)


@pytest.mark.slow
def test_the_intervals_hold_the_true_values(outcome):
    """The true mass, CoM and inertia lie within 1.5 times their 95 % half-widths of the estimate
    (the scene's seed; the study's Monte-Carlo puts 94.75 % of the ten parameters inside)."""
    s = outcome.summary
    for key in ("mass", "com", "inertia"):
        error = np.abs(np.subtract(s[f"target_{key}_estimate"], s[f"target_{key}_true"]))
        assert np.all(error <= 1.5 * np.array(s[f"target_{key}_half_width"])), key


@pytest.mark.slow
def test_detumbling_on_the_identified_model_settles(outcome):
    """The law on the identified model stops the box (below 1e-6 rad/s within 0.5 s), and the
    manoeuvre kept the momentum the identification reads to 1e-9."""
    s = outcome.summary
    assert s["settling_time"] < 0.5 and s["target_angular_velocity_final"] < 1e-6
    assert s["identification_momentum_drift"] < 1e-9 and s["identification_samples"] == 10001
    assert "identification" in outcome.extra_telemetry and outcome.status == "completed"


@pytest.mark.parametrize("edit, message", [
    ({"identification": {"joints": ["left_shoulder_pan"]}}, "'identification.joints'.*did you mean"),
    ({"identification": {"window": 100}}, r"\[identification\] 'window' must be odd"),
    ({"identification": {"noise": -0.01}}, r"\[identification\] 'noise' must be >= 0"),
    ({"identification": {"duraton": 1.0}}, "duraton.*did you mean.*duration"),
])
def test_bad_identification_keys_are_named(edit, message):
    """A wrong joint, an even window, a negative noise or a misspelt key fails naming the key."""
    with pytest.raises(SceneError, match=message):
        prepare(scene_of(**edit))


def test_identification_needs_a_target_and_a_free_base():
    """[identification] without a [target] leaves the scene to no experiment kind, and a planar base is refused
    when prepared."""
    with pytest.raises(SceneError, match="no experiment kind takes this scene"):
        prepare(scene_of("detumble_impulse_arm1_joint4", identification={}))
    with pytest.raises(SceneError, match="robot.base"):
        prepare(scene_of("capture_planar", identification={}))


def test_an_environment_is_refused_naming_its_kind(tmp_path):
    """A capture with [identification] flies in no environment: an [[environment]] is refused,
    not ignored."""
    path = tmp_path / "in_orbit.toml"
    path.write_text(builtin_scenes()["capture_identified"].read_text()
                    + '\n[[environment]]\nkind = "orbit"\naltitude = 400e3\n')
    with pytest.raises(SceneError, match="kind 'orbit' is not applied by a capture with"):
        prepare(load_scene(path))
