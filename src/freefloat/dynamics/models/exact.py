"""The exact reference: Pinocchio's articulated-body algorithm (ABA)."""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ...robot.robot import Robot
from .base import checked


def joint_space_dynamics(robot: Robot, data: pin.Data, q: np.ndarray, v: np.ndarray):
    """Exact joint-space dynamics with the base eliminated through the base rows.

    With ``M = [[M_bb, M_bq], [M_qb, M_qq]]`` and nonlinear effects ``b = [b_b; b_q]`` (CRBA and
    RNEA), the free base (no base wrench) gives ``tau = H* qddot + c*`` with

    .. math:: H^* = M_{qq} - M_{qb} M_{bb}^{-1} M_{bq}, \\qquad c^* = b_q - M_{qb} M_{bb}^{-1} b_b.

    ``H*`` equals the dissertation's generalized inertia (eq 92) for any base parametrisation.

    Returns:
        ``(H_star, c_star)``: (n, n) and (n,), joint order of the Pinocchio model.
    """
    nb = robot.n_base
    M = pin.crba(robot.model, data, q)
    b = pin.nonLinearEffects(robot.model, data, q, v)
    coupling = np.linalg.solve(M[:nb, :nb], np.column_stack((M[:nb, nb:], b[:nb])))
    H_star = M[nb:, nb:] - M[nb:, :nb] @ coupling[:, :-1]
    c_star = b[nb:] - M[nb:, :nb] @ coupling[:, -1]
    return H_star, c_star


class ExactModel:
    """Exact forward dynamics by Pinocchio ABA (Featherstone), O(n).

    Args:
        robot: the robot; a private ``pin.Data`` is allocated on first use (at nv 134 it takes
            25 ms and tens of MiB, which a run in the compiled loop never needs).
    """

    name = "exact"

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model = robot.model

    @functools.cached_property
    def data(self) -> pin.Data:
        """The model's private ``pin.Data``."""
        return self.model.createData()

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H*, c*)`` with ``tau = H* qddot + c*``: the exact joint-space dynamics (n, n), (n,)."""
        return joint_space_dynamics(self.robot, self.data, q, v)

    @checked
    def acceleration(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        fext: Sequence[pin.Force] | None = None,
    ) -> np.ndarray:
        if fext is None:
            return pin.aba(self.model, self.data, q, v, tau)
        return pin.aba(self.model, self.data, q, v, tau, fext)
