"""A plant whose actuators are DC motors (:mod:`freefloat.dynamics.motors`): the efforts the loop
holds are the motors' terminal voltages, and their currents are states.

Each motor's charge ``q_e`` (C) and current ``i = dq_e/dt`` (A) are one more coordinate pair of
the plant, so the state is ``q = [q_m; q_e]``, ``v = [v_m; i]`` on the mechanical plant's space
times R^k, and the "acceleration" of a charge is

.. math:: \\frac{di}{dt} = \\frac{V - R i - k_e N \\dot q_a}{L},

``qdot_a`` the motor's joint rate; the mechanical plant takes the efforts ``N k_t i``. The
registry's integrators step the whole state with no change (on R^k they are the classical
schemes), and ``q_e`` comes for free: over a control period with ``V`` held, the electrical energy
drawn is exactly ``V (q_e(t + h) - q_e(t))``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ..motors import DCMotor
from .vector_space import vector_space


def with_coordinates(space: pin.Model, k: int) -> pin.Model:
    """``space`` times R^k: a vector space's R^(n + k) (shared, :func:`vector_space`), else a copy of
    the model with ``k`` prismatic joints on the universe after its own (their coordinates last)."""
    joints = list(space.joints)[1:]
    if space.nq == space.nv and all(j.shortname() == "JointModelPX" for j in joints):
        return vector_space(space.nq + k)
    out = pin.Model(space)
    for i in range(k):
        out.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), f"charge_{i}")
    return out


class MotorDrivenPlant:
    """A plant (closed chain or tree) driven by one DC motor per actuator.

    Args:
        plant: the mechanical plant, its efforts the motors' joint efforts (k,). The rotors'
            armature and the drive trains' friction belong to it (:func:`~freefloat.dynamics.motors.add_armature`,
            :meth:`~freefloat.dynamics.motors.DCMotor.friction`).
        motors: the motors (k,), actuator order (:meth:`DCMotor.stack`).
        rates: velocity index, in the mechanical plant's ``v``, of each motor's joint (k,).

    Raises:
        InvalidArgument: when the motors, the rates and the plant's efforts differ in number, or a
            rate index is out of range.
    """

    name = "motor_driven"

    def __init__(self, plant: Any, motors: DCMotor, rates: Sequence[int]):
        self.plant, self.motors = plant, DCMotor.stack([motors[i] for i in range(len(motors))])
        self.rates = np.asarray(rates, dtype=int)
        k, nv = len(self.motors), plant.space.nv
        if not (k == len(self.rates) == plant.n_efforts) or not all(0 <= i < nv for i in self.rates):
            raise InvalidArgument(f"motor-driven plant: {k} motors, {len(self.rates)} joint rates (indices "
                                  f"{self.rates.tolist()}, within [0, {nv})) and {plant.n_efforts} plant efforts must "
                                  "agree")
        self.nq, self.nv = plant.space.nq, nv
        self.space = with_coordinates(plant.space, k)
        self.n_efforts, self.max_drift = k, plant.max_drift

    def split(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(q_m, v_m, charges, currents)`` of a state (..., nq), (..., nv)."""
        return q[..., : self.nq], v[..., : self.nv], q[..., self.nq:], v[..., self.nv:]

    def joint_rates(self, v: np.ndarray) -> np.ndarray:
        """The motors' joint rates (..., k) in a state's ``v`` (..., nv)."""
        return v[..., self.rates]

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``[mechanical acceleration; di/dt]`` (nv,) under terminal voltages ``u`` (k,), V."""
        q_m, v_m, _, current = self.split(q, v)
        a = np.empty(len(v))
        a[: self.nv] = self.plant.acceleration(q_m, v_m, self.motors.effort(current))
        a[self.nv:] = self.motors.current_rate(u, current, v_m[self.rates])
        return a

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """The mechanical plant's constraint residuals."""
        return self.plant.drift(q[: self.nq])
