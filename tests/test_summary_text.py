"""Summary values as the command line prints them: 4 significant digits and the unit."""

from __future__ import annotations

import pytest

from freefloat.app.experiments import EXPERIMENTS
from freefloat.app.summary_text import shown


@pytest.mark.parametrize("value, unit, text", [
    (7.542629016347826e-08, "rad", "7.543e-08 rad"),
    (0.098, "s", "0.098 s"),
    (124.81570412524795, "J", "124.8 J"),
    ([-0.21846667294278546, -0.21846667294278607, 0.0], "m", "[-0.2185, -0.2185, 0] m"),
    ({"wheel_x": 0.06285680459929491, "wheel_y": 0.8199082102723445}, "N m s", "{wheel_x: 0.06286, wheel_y: 0.8199} N m s"),
    (None, "s", "none"),
    (False, "", "no"),
    ("exact (capture scenes simulate the exact plant)", "", "exact (capture scenes simulate the exact plant)"),
    (2000, "", "2000"),
])
def test_values_are_shown_with_4_digits_and_their_unit(value, unit, text):
    """Numbers (alone, in vectors, in tables) to 4 significant digits then the unit; None, flags and
    texts as words, without a unit."""
    assert shown(value, unit) == text


@pytest.mark.parametrize("kind", EXPERIMENTS)
def test_every_headline_key_of_every_kind_has_its_unit(kind):
    """Each key the command line may print for a kind's run has a unit in the kind's table ("" for
    a pure number or a text), from the modules that compute the keys."""
    experiment = EXPERIMENTS[kind]
    assert experiment.headline and not [key for key in experiment.headline if key not in experiment.units]


@pytest.mark.parametrize("name", ["four_arm_joint_space", "five_bar_free_base"])
def test_a_run_prints_only_keys_its_kind_declares(tmp_path, name):
    """A run's headline keys are among its kind's (so each has its unit)."""
    import warnings

    from freefloat.app.runner import simulate
    from freefloat.app.scenes import load_scene

    from .conftest import scene_variant

    scene = load_scene(scene_variant(tmp_path / "s.toml", name, simulation={"duration": 0.02},
                                     output={"figures": False, "html": False}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome = simulate(scene)
    assert set(outcome.headline) <= set(EXPERIMENTS[scene.kind].headline)
    assert [key for key in outcome.headline if key in outcome.summary]
