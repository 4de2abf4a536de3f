"""The printed multi-arm numerical model that sums every arm's joint equations (dissertation sec
3.7.1, eqs 109-115, the operator ``I_n``), kept as a named variant to compare with the literature.

Each arm ``j`` (``m`` joints) has its own joint equation (eq 113), the rows of the exact one:

.. math:: H^*_j \\ddot q = \\tau_j + Q_j - c_j, \\qquad H^* = H_m - H_{0m}^T H_0^{-1} H_{0m}.

The printed form adds them (``I_n^T = [1 ... 1]``, here ``S = I_n^T \\otimes 1_m``, (m, N)):

.. math:: S H^* \\ddot q = S (\\tau + Q - c),

``m`` equations for the ``N = n m`` joint accelerations, and then inverts
``H_m - I_n^T H_{0m}^T H_0^{-1} H_{0m} = S H^*`` as if it were square. With one arm ``S = 1`` and
the form is the exact one; with ``n >= 2`` arms the sum holds for the exact accelerations but does
not determine them. :func:`summed_arms_acceleration` reads the printed inverse as the only inverse
an ``m x N`` matrix has, the minimum-norm (pseudo-inverse) solution, and the base row as eq 112.
The per-arm terms are the exact ones (``standard_corrected``), so the difference from the exact
dynamics is the summation's alone.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ...robot.conventions import local_base_acceleration
from ...robot.robot import Robot
from .underactuated import UnderactuatedGJM


def summing_operator(robot: Robot) -> np.ndarray:
    """``S = I_n^T (x) 1_m`` (m, N): row k adds joint k of every arm (joints in ``robot.n_joints``
    order, each arm from the base outwards).

    Raises:
        InvalidArgument: when the arms differ in length or do not partition the joints (eq 113
            needs arms of equal length that share no joint).
    """
    arms, nb = robot.arms, robot.n_base
    lengths = {arm.end_effector: len(arm.joints) for arm in arms}
    if len(set(lengths.values())) != 1:
        raise InvalidArgument(f"the summed multi-arm form (eqs 109-115) needs arms of equal length; got joints per "
                              f"arm {lengths}")
    columns = np.concatenate([arm.v_indices for arm in arms]) - nb
    if sorted(columns.tolist()) != list(range(robot.n_joints)):
        raise InvalidArgument("the summed multi-arm form (eqs 109-115) needs arms that share no joint and cover "
                              f"every joint; arms {[arm.end_effector for arm in arms]} of {robot.n_joints} joints do not")
    m = len(arms[0].joints)
    S = np.zeros((m, robot.n_joints))
    for arm in arms:
        S[np.arange(m), arm.v_indices - nb] = 1.0
    return S


def summed_arms_acceleration(robot: Robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                             fext: Sequence[pin.Force] | None = None) -> np.ndarray:
    """Forward dynamics of the printed summed form (module docstring), Pinocchio's convention.

    Args:
        q, v, tau: configuration (nq,), velocity (nv,) and generalized forces (nv,, base rows
            ignored), as :meth:`~freefloat.models.DynamicsModel.acceleration`.
        fext: one wrench per Pinocchio joint, or None.

    Returns:
        ``a`` (nv,): the base acceleration of eq 112 at the minimum-norm ``qddot`` of the summed
        joint equations.
    """
    model = UnderactuatedGJM(robot, full_hdot=True, corrected_c0=True, backend="numpy")
    terms = model.terms(q, v, fext)
    H, c = model.joint_space(terms)
    S = summing_operator(robot)
    nb = robot.n_base
    qddot = np.linalg.lstsq(S @ H, S @ (tau[nb:] + terms.Q_q - c), rcond=None)[0]
    return np.concatenate((local_base_acceleration(robot, q, v, model.base_acceleration(terms, qddot)), qddot))


__all__ = ["summed_arms_acceleration", "summing_operator"]
