"""Environment fields by name: the built-in wrench profile in both scene spellings, a field
(the example's constant wrench, a WrenchField evaluated at every stage) against the same wrench
as a profile (applied by the loop's own profile path), and the built-in orbit: its keys' checks
and its scene's measured libration period."""

from __future__ import annotations

import dataclasses
import re
import tomllib

import numpy as np
import pytest

import freefloat
from freefloat import SceneError
from freefloat.app.environments import ENVIRONMENTS, EnvironmentSpec
from freefloat.app.experiments import summary_units
from freefloat.app.scenes import builtin_scenes, find_scene, parse_scene
from freefloat.dynamics.metrics import summarize
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.paths import URDF_DIR
from freefloat.space.orbit.libration import pendulum_period

from .conftest import REPO

FORCE, TORQUE = (3.0, -2.0, 1.0), (0.0, 0.5, -0.2)


def test_wrenches_tables_are_the_wrench_profile_field():
    """A scene's [[wrenches]] table and the same keys as [[environment]] kind = "wrench_profile"
    give the same scene."""
    path = builtin_scenes()["detumble_impulse_baseline"]
    raw = tomllib.loads(path.read_text())
    old = parse_scene(raw, path)
    raw["environment"] = [{"kind": "wrench_profile", **table} for table in raw.pop("wrenches")]
    new = parse_scene(raw, path)
    assert new == old and [e.kind for e in new.environment] == ["wrench_profile"]
    assert new.wrenches[0].torque == (0.0, 0.0, 500.0)


def test_a_field_applies_what_the_same_profile_applies():
    """A constant wrench as a field (evaluated per stage in Python) and as a profile give the same
    run to round-off, and balances that agree to the field's trapezoidal rule."""
    module = freefloat.use(REPO / "examples" / "constant_wrench.py")
    robot = freefloat.load_robot(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf", visuals=False)
    field = ENVIRONMENTS["constant_wrench"].build(robot, module.ConstantWrenchSettings("arm2_link3", FORCE, TORQUE))
    q0, v0 = robot.neutral(), np.zeros(robot.model.nv)
    v0[3:6] = (0.1, -0.2, 0.3)
    as_field = freefloat.run(robot, q0, v0, 0.3, 1e-3, environment=(field,), backend="python").telemetry
    profile = (ExternalWrench("arm2_link3", FORCE, TORQUE),)
    as_profile = freefloat.run(robot, q0, v0, 0.3, 1e-3, wrenches=profile, backend="python").telemetry
    np.testing.assert_allclose(as_field.q, as_profile.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(as_field.v, as_profile.v, rtol=0, atol=1e-11)
    by_field, by_profile = summarize(as_field, robot, (), 1e-3, (field,)), summarize(as_profile, robot, profile, 1e-3)
    # the field's integrals are trapezoidal (second order: 5e-8 here), the profile's exact sums
    np.testing.assert_allclose(by_field["external_impulse"][:3], by_profile["external_impulse"][:3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(by_field["external_impulse"], by_profile["external_impulse"], rtol=0, atol=1e-6)
    assert abs(by_field["external_work"] - by_profile["external_work"]) < 1e-6
    assert by_field["momentum_balance_max"] < 1e-6 and by_field["energy_balance_max"] < 1e-6


class Swelling:
    """A field that scales another by sin(w t): F(t) = F0 sin(w t), wrench and forces alike."""

    def __init__(self, field, w: float):
        self.field, self.w = field, w

    def forces(self, t, q, v):
        return [f * float(np.sin(self.w * t)) for f in self.field.forces(t, q, v)]

    def wrench(self, t, q, v):
        return np.sin(self.w * t) * self.field.wrench(t, q, v)


@pytest.mark.parametrize("integrator", ["rkmk4", "dopri5"])
def test_a_field_sees_each_stage_s_own_time(integrator):
    """A force F0 sin(w t) on an arm link of the free-floating robot changes its linear momentum by
    F0 (cos(w t0) - cos(w t1)) / w: RKMK4's error falls 16x when the control period halves from
    0.05 s (w h = 0.5), dopri5's is within 1e-9 of F0 / w, as the loop hands the field every
    stage's own time (with the period's start time both missed by 0.375 and 0.194 of F0 / w)."""
    module = freefloat.use(REPO / "examples" / "constant_wrench.py")
    robot = freefloat.load_robot(REPO / "src" / "freefloat" / "urdf" / "four_arm_planar.urdf", visuals=False)
    w, t0, t1 = 10.0, 0.1, 0.4
    field = Swelling(ENVIRONMENTS["constant_wrench"].build(robot, module.ConstantWrenchSettings("arm2_link3", FORCE,
                                                                                                 TORQUE)), w)
    q0, v0 = robot.neutral(), np.zeros(robot.model.nv)
    v0[3:6] = (0.1, -0.2, 0.3)
    impulse = np.array(FORCE) * (np.cos(w * t0) - np.cos(w * t1)) / w
    errors = []
    for period in (0.05, 0.025):
        tel = freefloat.run(robot, q0, v0, t1 - t0, period, integrator, environment=(field,), start_time=t0).telemetry
        errors.append(np.linalg.norm(tel.momentum[-1, :3] - tel.momentum[0, :3] - impulse) * w / np.linalg.norm(FORCE))
    if integrator == "rkmk4":
        assert 13.0 < errors[0] / errors[1] < 19.0
    else:
        assert max(errors) < 1e-9


@pytest.mark.slow
def test_the_orbit_libration_scene_measures_the_closed_form_period():
    """The built-in orbit_libration scene, run as a user runs it, reports a libration period
    within 0.5 % of n sqrt(3 (Iy - Ix) / Iz) (the aerospace axes' n sqrt(3 (Ix - Iz) / Iy)) and
    within 1e-6 of the 5 deg pendulum's elliptic-integral value, ends with its CoM on the
    reference point, and balances momentum and energy against what the field applied (the loop
    gives the field each stage's time: with the period's start, 0.275 and a third of the work)."""
    scene = find_scene("orbit_libration")
    outcome = freefloat.simulate(dataclasses.replace(scene, output=dataclasses.replace(scene.output, figures=False,
                                                                                         html=False)))
    orbit = scene.environment[0].settings.orbit()
    inertia = freefloat.load_robot(URDF_DIR / scene.robot.urdf, end_effectors=(), visuals=False).model.inertias[1].inertia
    ix, iy, iz = np.diag(inertia)
    closed = 2.0 * np.pi / (orbit.mean_motion * np.sqrt(3.0 * (iy - ix) / iz))
    pendulum = pendulum_period(orbit, (ix, iy, iz), np.radians(scene.initial.base_rpy[2]))
    measured = outcome.summary["libration_period"]
    assert abs(measured / closed - 1.0) < 5e-3 and abs(measured / pendulum - 1.0) < 1e-6
    assert outcome.summary["momentum_balance_relative"] < 1e-4
    assert outcome.summary["energy_balance_max"] < 1e-4 * outcome.summary["external_work"]
    assert np.linalg.norm(outcome.summary["base_lvlh_position_final"]) < 1e-3  # m; the tidal force is zero there
    assert summary_units(scene)["libration_period"] == "s"


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"altitude": 400e3, "mean_motion": 1e-3}, "give exactly one of 'altitude' (m) and 'mean_motion'"),
        ({"phase": 0.5}, "give exactly one of 'altitude' (m) and 'mean_motion'"),
        ({"altitude": 0.0}, "'environment.altitude' must be > 0"),
        ({"altitude": float("inf")}, "'environment.altitude' must be finite"),
        ({"mean_motion": float("nan")}, "'environment.mean_motion' must be finite"),
        ({"mean_motion": 1.0}, "'mean_motion' 1.0 rad/s gives a radius"),
        ({"altitud": 400e3}, "did you mean 'altitude'?"),
    ],
)
def test_the_orbit_entry_refuses_bad_keys_by_name(keys, message):
    """Both or neither of altitude and mean_motion, a non-finite or non-positive value, an orbit
    inside the Earth and a misspelled key are refused when the scene is read, naming the key."""
    raw = tomllib.loads(builtin_scenes()["orbit_libration"].read_text())
    raw["environment"] = [{"kind": "orbit", **keys}]
    with pytest.raises(SceneError, match=re.escape(message)):
        parse_scene(raw)


def test_an_entry_that_summarises_must_give_its_units():
    """An environment entry with a summarise but no units for its keys is refused at registration
    time, naming the entry."""
    spec = ENVIRONMENTS["orbit"]
    with pytest.raises(freefloat.InvalidArgument, match="environment 'my_orbit': a summarise needs the units"):
        EnvironmentSpec("my_orbit", "", spec.settings, spec.build, spec.rules, spec.summarise)
