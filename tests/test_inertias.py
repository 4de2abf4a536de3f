"""Inertias no rigid body has: the bodies that break I1 + I2 >= I3 are found, the balanced copy
satisfies it and keeps the rest of the robot, and a scene can run on that copy."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from freefloat import InvalidArgument, load_robot
from freefloat.app.runner import simulate
from freefloat.app.scenes import load_scene
from freefloat.robot.inertias import balanced, triangle_violations

from .conftest import scene_variant


def _four_arm(**kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot("four_arm_planar", visuals=False, **kwargs)


def test_the_dissertation_robot_breaks_the_inequality_in_16_bodies():
    """Every arm link of the four-arm robot (the dissertation's numbers) breaks it; the base does not."""
    names = [name for name, _ in triangle_violations(_four_arm().model)]
    assert len(names) == 16 and all(name.startswith("arm") for name in names)


def test_the_balanced_copy_satisfies_it_and_keeps_mass_com_and_the_rest():
    """Balanced: no violation left, masses and first moments equal, principal axes kept, unchanged
    bodies bit-equal, and each raise is the half deficit over the least moment."""
    model = _four_arm().model
    copy, raised = balanced(model)
    assert not triangle_violations(copy, tol=-1e-12) and set(raised) == {n for n, _ in triangle_violations(model)}
    for j in range(1, model.njoints):
        old, new = model.inertias[j], copy.inertias[j]
        assert new.mass == old.mass and np.array_equal(new.lever, old.lever)
        if model.names[j] not in raised:
            assert np.array_equal(new.inertia, old.inertia)
            continue
        before, after = np.linalg.eigvalsh(old.inertia), np.linalg.eigvalsh(new.inertia)
        assert after[2] == pytest.approx(before[2], rel=1e-12)
        assert after[0] / before[0] - 1 == pytest.approx(raised[model.names[j]], rel=1e-6)


def test_load_robot_balanced_is_that_copy_without_the_note():
    """``load_robot(inertias="balanced")`` loads the balanced inertias and no triangle note."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot("four_arm_planar", visuals=False, inertias="balanced")
    assert not [w for w in caught if "I1 + I2 >= I3" in str(w.message)]
    expected, _ = balanced(_four_arm().model)
    for j in range(1, robot.model.njoints):
        assert np.array_equal(robot.model.inertias[j].inertia, expected.inertias[j].inertia)


def test_an_unknown_inertias_choice_is_refused_naming_the_choices():
    with pytest.raises(InvalidArgument, match="'inertias' must be one of as_given, balanced, got 'physical'"):
        load_robot("four_arm_planar", visuals=False, inertias="physical")


def test_a_scene_runs_the_balanced_robot_conserving_momentum_and_energy(tmp_path):
    """The tumbling scene with ``inertias = "balanced"``: a different robot (the base turns
    otherwise than on the printed inertias), with its momentum and energy conserved."""
    runs = {}
    for inertias in ("as_given", "balanced"):
        path = scene_variant(tmp_path / f"{inertias}.toml", "tumbling", robot={"inertias": inertias},
                             simulation={"duration": 0.2}, output={"figures": False, "html": False})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs[inertias] = simulate(load_scene(path)).summary
    assert runs["balanced"]["momentum_drift_max"] < 1e-12 and runs["balanced"]["energy_drift_max"] < 1e-10
    assert runs["balanced"]["base_rotation_max"] != pytest.approx(runs["as_given"]["base_rotation_max"], rel=1e-6)
