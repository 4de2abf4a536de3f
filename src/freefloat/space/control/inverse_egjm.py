"""Joint rates from end-effector rates through the E-GJM (dissertation eqs 133, 138), guarded.

``qdot = J*{k}^+ (xdot_E{k} - J0E{k} H0^-1 M)`` for the task rows k. Near a singularity (the
stretched arms of the dissertation's initial posture) the pseudo-inverse blows up; the solver
reports the condition number of ``J*{k}``, warns above ``warn_cond``, and either refuses above
``max_cond`` or, with ``damping > 0``, uses damped least squares
``qdot = J^T (J J^T + lambda^2 I)^-1 (...)``, which stays bounded at the cost of a residual.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ...dynamics.gjm import GJMState
from ...errors import SingularityError


class IllConditionedWarning(UserWarning):
    """An E-GJM inversion above the warning threshold of its condition number."""


@dataclass(frozen=True)
class InverseEGJM:
    """The guarded inversion of the E-GJM rows ``rows``.

    Attributes:
        rows: stacked task rows (see :func:`freefloat.space.detumbling.task_rows`).
        damping: lambda of damped least squares (0: plain pseudo-inverse).
        warn_cond: warn when cond(J*{k}) exceeds this (1e6: about 6 of 16 digits lost).
        max_cond: refuse (SingularityError) when it exceeds this and damping is 0 (1e10).
    """

    rows: np.ndarray
    damping: float = 0.0
    warn_cond: float = 1e6
    max_cond: float = 1e10

    def condition(self, state: GJMState) -> float:
        """Condition number of ``J*{k}`` (ratio of extreme singular values; inf when rank-deficient)."""
        sv = np.linalg.svd(state.Jstar[self.rows], compute_uv=False)
        return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")

    def joint_rates(self, state: GJMState, xdot: np.ndarray) -> np.ndarray:
        """``qdot`` (n,) giving end-effector rates ``xdot`` (len(rows),) under the state's momentum.

        ``xdot`` holds the selected rows of the stacked [v_E; w_E] of the end-effector frame
        origins, inertial frame, in ``robot.end_effectors`` order.

        Raises:
            SingularityError: cond(J*{k}) above ``max_cond`` with no damping; the message gives
                the condition number and the joint configuration.
        """
        J = state.Jstar[self.rows]
        target = xdot - state.J0E[self.rows] @ np.linalg.solve(state.H0, state.momentum_base)
        cond = self.condition(state)
        if cond > self.warn_cond:
            if self.damping == 0.0 and cond > self.max_cond:
                raise SingularityError(
                    f"E-GJM rows {self.rows.tolist()} are singular (condition number {cond:.3g} > {self.max_cond:g}) "
                    f"in the configuration with end-effectors at {np.round(state.ee_position, 4).tolist()} m; "
                    "move away from the singularity or set damping > 0"
                )
            warnings.warn(f"E-GJM inversion ill-conditioned (condition number {cond:.3g})", IllConditionedWarning, stacklevel=2)
        if self.damping > 0.0:
            return J.T @ np.linalg.solve(J @ J.T + self.damping**2 * np.eye(len(self.rows)), target)
        return np.linalg.pinv(J) @ target
