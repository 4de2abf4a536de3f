"""Computed torque on a planned joint path, for the one loop (dissertation eqs 136-137)."""

from __future__ import annotations

from ..control.computed_torque import ComputedTorque


class PlanTracking(ComputedTorque):
    """:class:`~freefloat.space.control.ComputedTorque` on a plan's
    :class:`~freefloat.space.planning.JointPath` (``trajectory(t) -> (q_d, qdot_d, qddot_d)``).
    The compiled loop knows quintic references only, so this law runs in Python."""

    def compiled_law(self) -> None:
        """None: the Python law (see the class docstring)."""
        return None
