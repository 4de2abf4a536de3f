"""A batch's bands and seeded draws: within the stated bands, different per run and seed, the
same for the same run whatever else the batch holds, and bad bands named."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from freefloat import FreefloatError
from freefloat.app import runner
from freefloat.app.batch.bands import MAX_RUNS, Band, parse_band
from freefloat.app.batch.variations import SEED_LIMIT, plan_runs, run_seeds
from freefloat.app.experiments.robot_run import joint_table
from freefloat.app.scenes import find_scene, load_scene

from .conftest import random_robots, scene_variant


def prepared(name: str):
    """The built-in scene ``name`` and its prepared nominal (loader notes silenced)."""
    scene = find_scene(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return scene, runner.prepare(scene)


@pytest.fixture(scope="module")
def tumbling():
    """The tumbling scene (free base, torque-free)."""
    return prepared("tumbling")


@pytest.fixture(scope="module")
def planar():
    """The default scene (planar base, computed torque)."""
    return prepared("four_arm_joint_space")


def test_each_run_draws_within_its_bands(tumbling):
    """Base rates, base velocity, joint angles and rates stay within +-width of the scene's values,
    mass factors within 1 +- width."""
    scene, nominal = tumbling
    bands = [Band("base_rate", 2.0), Band("base_velocity", 0.01), Band("joint_angle", 3.0), Band("joint_rate", 1.0),
             Band("mass", 0.1)]
    for plan in plan_runs(scene, nominal, bands, 5, seed=7):
        start = plan.scene.initial
        assert np.all(np.abs(np.subtract(start.base_angular_velocity, scene.initial.base_angular_velocity)) <= 2.0)
        assert np.all(np.abs(np.subtract(start.base_linear_velocity, scene.initial.base_linear_velocity)) <= 0.01)
        assert set(start.joint_positions) == set(nominal.robot.joint_names)
        assert all(abs(v) <= 3.0 for v in start.joint_positions.values())  # tumbling starts at zero
        assert all(abs(v) <= 1.0 for v in start.joint_velocities.values())
        assert all(0.9 <= f <= 1.1 for f in plan.masses.values()) and len(plan.masses) == nominal.robot.model.njoints - 1
        assert plan.varied["initial.base_angular_velocity[0]"] == start.base_angular_velocity[0]


def test_a_planar_base_varies_only_in_its_plane(planar):
    """On a planar base, the rate varies about z only and the velocity along x and y only."""
    scene, nominal = planar
    plan = plan_runs(scene, nominal, [Band("base_rate", 5.0), Band("base_velocity", 0.1)], 1, seed=0)[0]
    w, v = plan.scene.initial.base_angular_velocity, plan.scene.initial.base_linear_velocity
    assert w[0] == w[1] == 0.0 and w[2] != 0.0
    assert v[2] == 0.0 and v[0] != 0.0 and v[1] != 0.0


def test_joint_angles_vary_about_the_scenes_start(planar):
    """Joint starts given per arm in the scene are varied per joint about those values."""
    scene, nominal = planar
    plan = plan_runs(scene, nominal, [Band("joint_angle", 1.0)], 1, seed=3)[0]
    start = joint_table(nominal.robot, scene.initial.joint_positions, 1.0, "initial.joint_positions")
    varied = np.array([plan.scene.initial.joint_positions[name] for name in nominal.robot.joint_names])
    assert 0 < np.abs(varied - start).max() <= 1.0
    assert varied[nominal.robot.joint_names.index("arm2_joint1")] == pytest.approx(90.0, abs=1.0)


def test_different_runs_and_seeds_draw_different_starts(tumbling):
    """Runs of one batch differ from each other and from the same run under another seed."""
    scene, nominal = tumbling
    first = plan_runs(scene, nominal, [Band("base_rate", 2.0)], 3, seed=0)
    other = plan_runs(scene, nominal, [Band("base_rate", 2.0)], 3, seed=1)
    rates = {plan.scene.initial.base_angular_velocity for plan in first + other}
    assert len(rates) == 6


def test_each_run_has_its_own_seed_and_a_row_s_seed_reruns_that_row(tumbling):
    """Every run has its own seed (run 0's is the batch's; they were all the batch's); a batch
    whose --seed is a row's seed draws that row's values first, and the rows after it next."""
    scene, nominal = tumbling
    bands = [Band("base_rate", 2.0), Band("joint_rate", 0.5)]
    batch = plan_runs(scene, nominal, bands, 5, seed=11)
    seeds = [plan.seed for plan in batch]
    assert seeds[0] == 11 and len(set(seeds)) == 5 and all(0 <= s < SEED_LIMIT for s in seeds[1:])
    again = plan_runs(scene, nominal, bands, 2, seed=seeds[3])
    assert [p.varied for p in again] == [batch[3].varied, batch[4].varied]
    assert [p.seed for p in again] == seeds[3:5] == run_seeds(seeds[3], 2)


def test_a_run_draws_the_same_whatever_the_batch_size_or_other_keys(tumbling):
    """Run 2 gets the same values in a batch of 3 or of 5, and adding a key changes no other key."""
    scene, nominal = tumbling
    alone = plan_runs(scene, nominal, [Band("base_rate", 2.0)], 3, seed=4)[2]
    more = plan_runs(scene, nominal, [Band("mass", 0.2), Band("base_rate", 2.0)], 5, seed=4)[2]
    assert alone.scene.initial.base_angular_velocity == more.scene.initial.base_angular_velocity


def test_mechanism_platform_starts_vary_about_the_reference(tmp_path):
    """The 5R's start varies about the reference at t = 0 when the scene gives none."""
    scene = load_scene(scene_variant(tmp_path / "m.toml", "five_bar_computed_torque", simulation={"duration": 0.01}))
    nominal = runner.prepare(scene)
    plan = plan_runs(scene, nominal, [Band("platform", 0.002), Band("platform_rate", 0.01)], 1, seed=0)[0]
    center = nominal.controller.reference(0.0)
    assert 0 < np.abs(np.subtract(plan.scene.initial.platform, center)).max() <= 0.002
    assert 0 < np.abs(plan.scene.initial.platform_velocity).max() <= 0.01


@given(case=random_robots(max_links=6))
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_random_robots_get_every_joint_varied_within_the_band(tmp_path_factory, case):
    """On random trees every movable joint gets its own start within the band."""
    import dataclasses

    seed, text = case
    path = tmp_path_factory.mktemp("r") / "robot.urdf"
    path.write_text(text)
    scene = find_scene("tumbling")
    scene = dataclasses.replace(scene, robot=dataclasses.replace(scene.robot, urdf=str(path), end_effectors=None))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nominal = runner.prepare(scene)
    plan = plan_runs(scene, nominal, [Band("joint_angle", 0.5)], 1, seed=seed % 1000)[0]
    values = plan.scene.initial.joint_positions
    assert set(values) == set(nominal.robot.joint_names)
    assert all(abs(v) <= 0.5 for v in values.values())


@pytest.mark.parametrize("text, message", [
    ("foo=1", "unknown key 'foo'"), ("base_rate", "expected KEY=WIDTH"), ("base_rate=x", "is not a number"),
    ("base_rate=-1", "finite number >= 0"), ("joint_rate=nan", "finite number >= 0"), ("mass=1.5", "width < 1"),
    ("mass=100%", "width < 1"),
])
def test_bad_bands_are_named(text, message):
    """A band that is malformed, unknown or out of range is an error naming --vary and the text."""
    with pytest.raises(FreefloatError, match=f"--vary '{text}'.*{message}"):
        parse_band(text)


def test_a_mass_band_reads_a_percentage():
    """mass=10% is a width of 0.1."""
    assert parse_band("mass=10%") == Band("mass", 0.1)


@pytest.mark.parametrize("scene_name, band, message", [
    ("tumbling", Band("platform", 0.1), "band platform: not a key of joint_space scene"),
    ("five_bar_sliding_mode", Band("base_rate", 1.0), "band base_rate: not a key of mechanism scene"),
    ("capture_planar", Band("mass", 0.1), "band mass: scene 'capture_planar' is a capture scene"),
])
def test_keys_the_scene_cannot_take_are_refused(scene_name, band, message):
    """A key of the other scene family, or mass on a capture, is refused naming the band and the
    key (``--vary`` on the command line)."""
    scene = find_scene(scene_name)
    with pytest.raises(FreefloatError, match=message):
        plan_runs(scene, None, [band], 1, 0)


def test_runs_below_one_and_negative_seeds_are_refused(tumbling):
    """runs 0 and seed -1 are errors naming the argument, as the Python call or the command line
    (``--runs``, ``--seed``) spells it."""
    from freefloat.errors import command_line

    scene, nominal = tumbling
    with pytest.raises(FreefloatError, match="^runs must be from 1 to .*, got 0"):
        plan_runs(scene, nominal, [], 0, 0)
    with pytest.raises(FreefloatError, match="^seed must be >= 0"):
        plan_runs(scene, nominal, [], 1, -1)
    with pytest.raises(FreefloatError, match="^--seed must be >= 0"), command_line():
        plan_runs(scene, nominal, [], 1, -1)


def test_a_key_given_twice_is_refused(tumbling):
    """Two bands for one key are an error naming it."""
    scene, nominal = tumbling
    with pytest.raises(FreefloatError, match="band base_rate: given twice"):
        plan_runs(scene, nominal, [Band("base_rate", 1.0), Band("base_rate", 2.0)], 1, 0)


def test_a_batch_of_a_trillion_runs_is_refused_up_front(tumbling):
    """--runs 10**12 is refused at once naming the bound (planning every run grew memory until it
    ran out)."""
    scene, nominal = tumbling
    with pytest.raises(FreefloatError, match=f"runs must be from 1 to {MAX_RUNS}, got 1000000000000"):
        plan_runs(scene, nominal, [], 10**12, 0)


def test_mass_on_a_scene_with_wheels_is_refused():
    """--vary mass on a scene with [[wheels]] is refused naming the band and the wheels."""
    from freefloat.app.batch import Band
    from freefloat.app.batch.variations import check_bands
    from freefloat.app.scenes import find_scene
    from freefloat.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=r"mass: scene 'satellite_wheels' has \[\[wheels\]\]"):
        check_bands(find_scene("satellite_wheels"), [Band("mass", 0.1)])
