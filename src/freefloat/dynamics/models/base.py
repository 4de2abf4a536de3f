"""What a dynamics model is: accelerations from state, torques and external wrenches."""

from __future__ import annotations

from typing import Protocol, Sequence

import numpy as np
import pinocchio as pin


class DynamicsModel(Protocol):
    """Forward dynamics of a free-floating robot.

    Attributes:
        name: registry name of the variant.
    """

    name: str

    def acceleration(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        fext: Sequence[pin.Force] | None = None,
    ) -> np.ndarray:
        """Generalized acceleration (nv,), Pinocchio convention (base part: derivative of the
        base-link local twist).

        Args:
            q: configuration (nq,).
            v: velocity (nv,).
            tau: generalized forces (nv,); zero on the base rows of a free-floating robot.
            fext: one wrench ``pin.Force`` [f; n] per Pinocchio joint (njoints): joint-frame axes,
                moment about the joint-frame origin; or None.
        """
        ...

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c)`` with ``tau = H qddot + c`` for the actuated joints (n, n), (n,): the model
        as a computed-torque controller sees it. Models with an internal state (``nidc``) also
        have ``end_period(q, v, dt)``, called once per control period with the period's start
        state."""
        ...
