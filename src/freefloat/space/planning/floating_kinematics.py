r"""Free-floating kinematics at conserved momentum: the base moves as the joints make it.

With no external wrench the total momentum ``[P; L_o]`` (about the inertial origin) is constant,
and so is the centroidal momentum ``h_G = [P; L_o - c x P]`` (``c`` the system CoM). The base
velocity follows from the joint rates through Pinocchio's centroidal momentum matrix
``A_G = [A_b, A_j]``:

.. math:: A_b\, v_b = h_G - A_j \dot q,

the same motion as the GJM's ``x0dot = J0 qdot + H0^-1 M`` (eq 71) in Pinocchio's local base
velocity. A planner integrates it over its time grid (:func:`rollout`, the engine's integrators
on this first-order system) to know where the base, and so the end-effector, will be.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from ...dynamics import flow, gjm
from ...dynamics.gjm import GJMState
from ...robot.conventions import PLANAR_ROWS, cross3, momentum_about_origin
from ...robot.robot import Robot

#: Joint rates of a plan (n,) from time (s) and configuration (nq,).
Rates = Callable[[float, np.ndarray], np.ndarray]
#: The integrator of the roll-outs (a fixed-step one of the registry: one step per grid interval).
INTEGRATOR = "rkmk4"


class FloatingKinematics:
    """The base velocity that joint rates give a robot of constant total momentum.

    Args:
        robot: a free-floating robot (free or planar base).
        momentum_origin: the conserved ``[P; L about the inertial origin]``, inertial frame (6,).
    """

    def __init__(self, robot: Robot, momentum_origin: np.ndarray):
        self.robot = robot
        self.momentum_origin = np.asarray(momentum_origin, float)
        self._zero = np.zeros(robot.model.nv)
        self._gjm = gjm.model_of(robot)  # unchecked per call: the roll-out makes its own states
        self._data = robot.model.createData()
        self._rows = np.arange(6) if robot.base == "free" else PLANAR_ROWS

    @classmethod
    def at_state(cls, robot: Robot, q: np.ndarray, v: np.ndarray) -> FloatingKinematics:
        """The kinematics with the momentum of the state (q, v) (Pinocchio's centroidal momentum)."""
        return cls(robot, momentum_about_origin(robot.model, robot.model.createData(), q, v))

    def matrices(self, q: np.ndarray) -> GJMState:
        """The GJM quantities at configuration q (nq,) (joint rates zero: matrices only)."""
        return self._gjm.compute(q, self._zero)

    def momentum_base(self, state: GJMState) -> np.ndarray:
        """``M = [P; L about the base CoM]`` (6,), inertial frame, at the state's configuration."""
        P, L = self.momentum_origin[:3], self.momentum_origin[3:]
        return np.concatenate((P, L - cross3(state.kinematics.r0, P)))

    def velocity(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """Pinocchio's velocity (nv,) with joint rates ``qdot`` (n,) at configuration ``q`` (nq,)."""
        model, data, nb, rows = self.robot.model, self._data, self.robot.n_base, self._rows
        A = pin.computeCentroidalMap(model, data, q)
        P = self.momentum_origin[:3]
        h = np.concatenate((P, self.momentum_origin[3:] - cross3(data.com[0], P)))
        return np.concatenate((np.linalg.solve(A[rows, :nb], h[rows] - A[rows, nb:] @ qdot), qdot))


def stage_times(times: np.ndarray) -> np.ndarray:
    """Every time :func:`rollout` asks the rates for on the grid ``times``, computed as it
    computes them (:func:`freefloat.dynamics.flow.stage_times`)."""
    return flow.stage_times(times, INTEGRATOR)


def rollout(kin: FloatingKinematics, q0: np.ndarray, rates: Rates, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Configurations and velocities on the grid ``times`` (N,): the first-order system
    ``q' = kin.velocity(q, rates(t, q))`` stepped by the engine's :data:`INTEGRATOR`
    (:func:`freefloat.dynamics.flow.rollout`, RKMK4 on the configuration Lie group, one step per
    grid interval).

    Returns:
        ``(qs, vs)``: (N, nq) and (N, nv); ``vs[k]`` is the velocity at ``qs[k]`` with
        ``rates(times[k], qs[k])``.
    """
    return flow.rollout(lambda t, q: kin.velocity(q, rates(t, q)), kin.robot.model, q0, times, INTEGRATOR)
