"""Detumbling through the loop two hands close (freefloat.space.control.loop_detumbling)."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat.dynamics.closures import ClosedModel
from freefloat.space.capture import TARGET_FRAME, Target
from freefloat.space.control.loop_detumbling import LoopDetumblingController, internal_wrench
from freefloat.space.detumbling import joint_indices, task_rows

from .conftest import box_held_in_both_hands

HANDS = ("left_tool0", "right_tool0")
BOX = Target(mass=50.0, inertia=(2.0, 2.5, 3.0), grasp=(-0.25, 0.3, 0.0), position=(0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def holding():
    """The dual-arm satellite holding the box in both hands at a random posture: (merged robot,
    its loop closure, q, a velocity the loop allows)."""
    return box_held_in_both_hands(5)


def law(merged, closure, **settings):
    return LoopDetumblingController(merged, closure, TARGET_FRAME, BOX.mass, np.asarray(BOX.inertia),
                                    task_rows(merged, [(HANDS[0], "angular")]), joint_indices(merged, None), 1e-3,
                                    **settings)


@pytest.mark.parametrize("squeeze", [0.0, 35.0])
def test_the_plant_carries_the_squeeze_the_law_chose(holding, squeeze):
    """With the law's torques, the plant's closure force makes the loop's internal wrench a pure
    squeeze of the chosen size along grasp 2 -> grasp 1 (to 1e-8 N), whatever the state."""
    merged, closure, q, v = holding
    tau = law(merged, closure, baumgarte=10.0, squeeze=squeeze).torque(0.0, q, v)
    plant = ClosedModel(merged, [closure], 10.0)
    a = plant.acceleration(q, v, np.concatenate((np.zeros(6), tau)))
    along, wrench = internal_wrench(merged, closure, TARGET_FRAME, BOX.mass, np.asarray(BOX.inertia), q, v, a,
                                    plant.last.force)
    assert along == pytest.approx(squeeze, abs=1e-8)
    assert np.linalg.norm(wrench[:3]) == pytest.approx(squeeze, abs=1e-8) and np.abs(wrench[3:]).max() < 1e-8


def test_a_torque_limit_holds_and_keeps_the_squeeze(holding):
    """With a limit far under the unlimited peak, every torque is within it, and the internal wrench
    is still the chosen squeeze (the desired acceleration, not the squeeze, is given up)."""
    merged, closure, q, v = holding
    free = law(merged, closure, kd=200.0, squeeze=20.0).torque(0.0, q, v)
    limited_law = law(merged, closure, kd=200.0, squeeze=20.0, torque_limit=0.5 * np.abs(free).max())
    tau = limited_law.torque(0.0, q, v)
    plant = ClosedModel(merged, [closure])
    a = plant.acceleration(q, v, np.concatenate((np.zeros(6), tau)))
    along = internal_wrench(merged, closure, TARGET_FRAME, BOX.mass, np.asarray(BOX.inertia), q, v, a,
                            plant.last.force)[0]
    assert limited_law.log.saturated == [True]
    assert np.abs(tau).max() <= 0.5 * np.abs(free).max() * (1 + 1e-12) and along == pytest.approx(20.0, abs=1e-8)


def test_the_rates_stop_the_rows_and_keep_the_loop_closed(holding):
    """The rate solve's joint rates zero the target's angular rows (residual under 1e-12) with the
    closure's relative velocity zero under momentum conservation."""
    merged, closure, q, v = holding
    controller = law(merged, closure)
    controller.torque(0.0, q, v)
    assert controller.log.rows_residual[0] < 1e-12
