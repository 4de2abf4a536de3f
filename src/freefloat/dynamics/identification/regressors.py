"""Pinocchio's regressors, stacked over samples: what the measurements are linear in.

Joint torques (Pinocchio's ``computeJointTorqueRegressor``):

.. math:: \\tau(q, \\dot q, \\ddot q) = Y(q, \\dot q, \\ddot q)\\, \\pi,

``Y`` (nv, 10 (njoints - 1)), ``pi`` the tree's parameters
(:func:`~.parameters.model_parameters`). Momentum about the inertial origin, inertial axes: each
body's spatial momentum ``I_j v_j`` in its joint frame is Pinocchio's ``bodyRegressor(0, v_j)``
times its ten parameters (the body regressor of ``I a + v x* I v`` at ``v = 0``, ``a = v_j``),
carried to the origin by the dual action of the joint's pose ``oM_j``:

.. math:: h = \\begin{bmatrix} P \\\\ L_O \\end{bmatrix}
          = \\sum_j {}^{O}X_j^{*}\\, Y_b(0, v_j)\\, \\pi_j = Y_h(q, \\dot q)\\, \\pi .
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import BadShape


def torque_regressor(model: pin.Model, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                     data: pin.Data | None = None) -> np.ndarray:
    """The joint-torque regressor stacked over N samples, sample-major (N nv, 10 (njoints - 1)):
    rows ``k nv .. (k + 1) nv - 1`` are sample k's ``Y(q_k, v_k, a_k)``.

    Args:
        q: configurations (N, nq); v, a: velocities and accelerations (N, nv), Pinocchio's.

    Raises:
        BadShape: for arrays of other shapes.
    """
    q, v, a = _samples(model, q, v, a)
    data = model.createData() if data is None else data
    return np.vstack([pin.computeJointTorqueRegressor(model, data, qk, vk, ak) for qk, vk, ak in zip(q, v, a)])


def body_momentum_regressor(placement: pin.SE3, velocity: pin.Motion) -> np.ndarray:
    """(6, 10): ``[P; L_O]`` of one body, about the inertial origin in inertial axes, from its ten
    parameters in its own frame; ``placement`` is the frame's pose ``oM_b`` and ``velocity`` its
    twist in its own frame (Pinocchio's LOCAL)."""
    return placement.toDualActionMatrix() @ pin.bodyRegressor(pin.Motion.Zero(), velocity)


def momentum_regressor(model: pin.Model, q: np.ndarray, v: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """``Y_h`` (6, 10 (njoints - 1)) at one state (q (nq,), v (nv,)): the momentum
    ``[P; L about the inertial origin]``, inertial axes, is ``Y_h pi`` (module docstring)."""
    data = model.createData() if data is None else data
    pin.forwardKinematics(model, data, q, v)
    return np.hstack([body_momentum_regressor(data.oMi[j], data.v[j]) for j in range(1, model.njoints)])


def _samples(model: pin.Model, q: np.ndarray, *rates: np.ndarray) -> tuple[np.ndarray, ...]:
    """``q`` (N, nq) and each rate (N, nv) as float arrays of one N.

    Raises:
        BadShape: naming the array of the wrong shape.
    """
    q = np.atleast_2d(np.asarray(q, float))
    out = [q]
    if q.shape[1:] != (model.nq,):
        raise BadShape(f"regressor samples: q must have shape (N, {model.nq}) for {model.name}, got {q.shape}")
    for name, rate in zip(("v", "a"), rates):
        rate = np.atleast_2d(np.asarray(rate, float))
        if rate.shape != (len(q), model.nv):
            raise BadShape(f"regressor samples: {name} must have shape ({len(q)}, {model.nv}) like q's "
                           f"{len(q)} samples, got {rate.shape}")
        out.append(rate)
    return tuple(out)
