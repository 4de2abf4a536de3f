"""The guarded E-GJM inversion: exact away from singularities, loud or damped near them."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from freefloat import gjm, load_robot
from freefloat.errors import SingularityError
from freefloat.robot.joints import JointCoordinates
from freefloat.space.control.inverse_egjm import IllConditionedWarning, InverseEGJM
from freefloat.space.detumbling import task_rows

from .conftest import REPO

PLANAR_ROWS = [(f"arm{i}_ee", c) for i in range(1, 5) for c in ("vx", "vy", "wz")]


@pytest.fixture(scope="module")
def robot():
    return load_robot(REPO / "urdf" / "four_arm_planar.urdf", visuals=False)


def table4_state(robot, offset_deg: float):
    """Table 4's posture (arms stretched) with every joint offset by ``offset_deg``."""
    q = robot.neutral()
    angles = np.full(16, np.radians(offset_deg))
    angles[[4, 12]] += np.pi / 2  # arms 2 and 4: joint 1 at 90 deg
    JointCoordinates(robot).set(q, angles)
    return q


def test_inversion_reproduces_the_end_effector_rates(robot):
    """Away from singularities, J* qdot + J0E H0^-1 M equals the requested rates (eq 133)."""
    rng = np.random.default_rng(0)
    q = table4_state(robot, 20.0)
    v = np.concatenate((np.zeros(6), rng.normal(size=16)))
    state = gjm.compute(robot, q, v)
    inverse = InverseEGJM(task_rows(robot, PLANAR_ROWS))
    xdot = rng.normal(size=12)
    qdot = inverse.joint_rates(state, xdot)
    achieved = state.Jstar[inverse.rows] @ qdot + state.J0E[inverse.rows] @ np.linalg.solve(state.H0, state.momentum_base)
    np.testing.assert_allclose(achieved, xdot, atol=1e-10)


def test_condition_number_grows_toward_the_stretched_posture(robot):
    """cond(J*) at offsets 1, 0.1, 0 deg: finite and growing, then singular (the figs 38-40 study)."""
    inverse = InverseEGJM(task_rows(robot, PLANAR_ROWS))
    conds = [inverse.condition(gjm.compute(robot, table4_state(robot, d), np.zeros(22))) for d in (1.0, 0.1, 0.0)]
    assert conds[0] < conds[1] and conds[2] > 1e12


def test_singular_inversion_is_refused_with_the_condition_number(robot):
    """At the stretched posture the plain inversion raises, naming the condition number."""
    inverse = InverseEGJM(task_rows(robot, PLANAR_ROWS))
    state = gjm.compute(robot, table4_state(robot, 0.0), np.zeros(22))
    with pytest.raises(SingularityError, match="condition number"):
        inverse.joint_rates(state, np.ones(12))


def test_damped_inversion_stays_bounded_and_warns(robot):
    """With damping the rates stay bounded at the singularity, and a warning says why."""
    inverse = InverseEGJM(task_rows(robot, PLANAR_ROWS), damping=1e-2)
    state = gjm.compute(robot, table4_state(robot, 0.0), np.zeros(22))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        qdot = inverse.joint_rates(state, np.ones(12))
    assert np.abs(qdot).max() < 1e3 and any(issubclass(w.category, IllConditionedWarning) for w in caught)
