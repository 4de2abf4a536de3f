"""Environment fields by name: the built-in wrench profile in both scene spellings, and a field
(the example's constant wrench, a WrenchField evaluated at every stage) against the same wrench
as a profile (applied by the loop's own profile path)."""

from __future__ import annotations

import tomllib

import numpy as np

import freefloat
from freefloat.app.environments import ENVIRONMENTS
from freefloat.app.scenes import builtin_scenes, parse_scene
from freefloat.dynamics.metrics import summarize
from freefloat.dynamics.wrenches import ExternalWrench

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
