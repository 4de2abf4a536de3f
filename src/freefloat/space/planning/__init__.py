"""Pre-capture planning (dissertation sec 3.8, the pre-capture phase): bring an end-effector onto a
tumbling target's grasp point at the grasp instant with the grasp point's velocity, disturbing the
base attitude as little as possible, within joint-rate and torque limits.

``grasp_motion`` (where the grasp point will be), ``request`` (what is asked, the limits),
``floating_kinematics`` (the base motion the joints cause at conserved momentum),
``reaction_null_space`` (the minimum-norm and reaction-null-space rate laws), ``resolved_rate``
(a task-space quintic followed by a rate law), ``optimised`` (a polynomial joint path minimising
the base rotation by SLSQP), ``plan`` (the joint path, its evaluation and its checks) and
``tracking`` (computed torque on the plan, for the one loop). :data:`PLANNERS` maps each method
name to its planner; :func:`plan_approach` runs one and checks the result.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import InfeasiblePlan, UnknownName
from .grasp_motion import GraspMotion
from .plan import JointPath, Plan, check, evaluate
from .reaction_null_space import RATE_LAWS, TaskRows
from .request import ApproachRequest, Limits


def _resolved_rate(name: str) -> Callable[[ApproachRequest], JointPath]:
    """The planner that follows the task quintic with the rate law ``name`` (its module, and
    scipy.interpolate with it, imported when it first plans)."""

    def plan(request: ApproachRequest) -> JointPath:
        from .resolved_rate import resolved_rate_path

        return resolved_rate_path(request, RATE_LAWS[name])

    return plan


def _optimised(request: ApproachRequest) -> JointPath:
    """The SLSQP-optimised path with its default settings (:func:`.optimised.optimised_path`)."""
    from .optimised import optimised_path

    return optimised_path(request)


#: Approach planners by method name: each turns a request into a joint path.
PLANNERS: dict[str, Callable[[ApproachRequest], JointPath]] = {
    "min_norm": _resolved_rate("min_norm"),
    "null_space": _resolved_rate("null_space"),
    "optimised": _optimised,
}


def planned_path(request: ApproachRequest, method: str) -> Plan:
    """The evaluated, unchecked plan of ``method`` (see :data:`PLANNERS`).

    Raises:
        UnknownName: for a method not in :data:`PLANNERS`.
        InfeasiblePlan: when the planner's linear algebra fails on the way (a singular path that
            diverged: reason ``"reach"``).
    """
    if method not in PLANNERS:
        raise UnknownName("approach method", method, PLANNERS)
    try:
        with np.errstate(all="ignore"):  # a diverging path is judged by plan.check, not by warnings
            return evaluate(request, PLANNERS[method](request), method)
    except np.linalg.LinAlgError as exc:
        raise InfeasiblePlan(f"approach ({method}): the grasp point is out of reach: the plan diverged ({exc}) before "
                             f"t = {request.duration:.4g} s, the path meeting a singularity", "reach") from exc


def plan_approach(request: ApproachRequest, method: str = "null_space") -> Plan:
    """The checked plan of ``method`` (see :data:`PLANNERS`).

    Raises:
        UnknownName: for a method not in :data:`PLANNERS`.
        InfeasiblePlan: when the plan diverges, misses the grasp or breaks a limit
            (:func:`.plan.check`).
    """
    return check(planned_path(request, method), request)


__all__ = ["PLANNERS", "ApproachRequest", "GraspMotion", "JointPath", "Limits", "Plan", "TaskRows", "check",
           "evaluate", "plan_approach", "planned_path"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
