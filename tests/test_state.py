"""Public functions refuse a state of the wrong size, not finite, or off the unit quaternion,
naming the argument (a zero quaternion was read as the identity; a long q was cut silently)."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import gjm, load_robot
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.models import make_model
from freefloat.dynamics.simulation import run
from freefloat.errors import InvalidArgument
from freefloat.paths import URDF_DIR


@pytest.fixture(scope="module")
def robot():
    return load_robot(URDF_DIR / "two_arm_planar.urdf", visuals=False)


def states(robot):
    """(q, v, message) of bad states: too long, NaN, a zero and a non-unit quaternion."""
    q, v = robot.neutral(), np.zeros(robot.model.nv)
    zero_quaternion = q.copy()
    zero_quaternion[3:7] = 0.0
    scaled = q.copy()
    scaled[3:7] *= 2.0
    nan_v = v.copy()
    nan_v[2] = np.nan
    return [(np.append(q, 0.0), v, r"q must have shape"), (q, nan_v, r"v has non-finite entries at \[2\]"),
            (zero_quaternion, v, "off norm 1"), (scaled, v, "off norm 1"), (q, v[:-1], "v must have shape")]


@pytest.mark.parametrize("case", range(5))
def test_gjm_compute_and_derivatives_refuse_bad_states(robot, case):
    """gjm.compute and gjm.derivatives raise InvalidArgument naming q or v."""
    q, v, message = states(robot)[case]
    for function in (gjm.compute, gjm.derivatives):
        with pytest.raises(InvalidArgument, match=message):
            function(robot, q, v)


@pytest.mark.parametrize("case", range(5))
def test_run_refuses_bad_initial_states(robot, case):
    """run() refuses them before the loop (it used to report 'diverged' or run a frozen base)."""
    q, v, message = states(robot)[case]
    with pytest.raises(InvalidArgument, match=message):
        run(robot, q, v, 0.01, 1e-3, make_integrator("rkmk4", robot.model), make_model("exact", robot))


@pytest.mark.parametrize(("duration", "period", "named"), [(1.0, 0.0, "control_period"), (0.0, 1e-3, "duration"),
                                                     (float("nan"), 1e-3, "duration")])
def test_run_refuses_periods_and_durations_that_are_not_positive(robot, duration, period, named):
    """control_period = 0 is an error naming it, not a ZeroDivisionError; so is a duration of 0
    or NaN."""
    with pytest.raises(InvalidArgument, match=f"'{named}' must be"):
        run(robot, robot.neutral(), np.zeros(robot.model.nv), duration, period,
            make_integrator("rkmk4", robot.model), make_model("exact", robot))
