"""A torque law driven through DC motors: the voltages a motor-driven plant
(:class:`~freefloat.dynamics.plants.motor_driven.MotorDrivenPlant`) takes, from the joint efforts
a mechanical law asks for (thesis proposal sec 9, items 10-11).

The law (sliding mode, computed torque, any controller of the loop) sees the mechanical state
and asks efforts ``tau_d`` (k,); the drive turns them into currents by its nominal motor model
and holds them with a proportional-integral current loop of rate ``omega_c`` (1/s) on the
measured current ``i``, the back-EMF fed forward:

.. math::
    i_d = \\mathrm{clip}\\left(\\frac{\\tau_d}{\\hat N \\hat k_t}, \\pm i_{max}\\right), \\qquad
    V = \\mathrm{clip}\\left(\\hat k_e \\hat N \\dot q_a + \\hat L \\omega_c (i_d - i) + z,
    \\pm V_{max}\\right), \\qquad \\dot z = \\hat R \\omega_c (i_d - i).

The integral's zero cancels the winding's pole ``R / L`` (the "technical optimum" of current
loops): with exact parameters ``I / I_d = omega_c / (s + omega_c)``, the current follows ``i_d``
with time constant ``1 / omega_c``; with errors the integral still brings the current to ``i_d``
at rest (``z`` takes the resistive drop ``R i`` and any back-EMF error), so the effort is
``(k_t / k^_t) tau_d``: the one motor error left for the gain design
(:mod:`freefloat.parallel.drive_gain_design`). Digitally the drive runs once per control period
``T`` (``z`` by forward Euler; not integrated while the voltage is clipped: anti-windup), so it
must be called once per period in order, as the loop calls a held law (not per stage).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InvalidArgument
from .motors import DCMotor


class VoltageDrive:
    """Voltages (k,) for a motor-driven plant from a mechanical law's efforts.

    Args:
        law: a controller of the mechanical plant (``torque(t, q_m, v_m)`` -> efforts (k,),
            ``reference(t)``).
        plant: the :class:`~freefloat.dynamics.plants.motor_driven.MotorDrivenPlant` (its
            coordinate sizes and the motors' joint rates).
        motors: the drive's model of the motors (k,), e.g. the data file's nominal ones (the
            plant's may differ).
        bandwidth: the current loop's rate ``omega_c``, 1/s (> 0).
        period: the control period ``T`` the loop calls :meth:`torque` at, s (> 0).

    Raises:
        InvalidArgument: for a bandwidth or period that is not positive, or motors of another
            number than the plant's.
    """

    def __init__(self, law: Any, plant: Any, motors: DCMotor, bandwidth: float, period: float):
        for name, value in (("bandwidth", bandwidth), ("period", period)):
            if not (np.isfinite(value) and value > 0.0):
                raise InvalidArgument(f"voltage drive: '{name}' must be positive, got {value}")
        if len(motors) != plant.n_efforts:
            raise InvalidArgument(f"voltage drive: {len(motors)} motors for a plant of {plant.n_efforts}")
        self.law, self.plant, self.bandwidth, self.period = law, plant, float(bandwidth), float(period)
        self.motors = DCMotor.stack([motors[i] for i in range(len(motors))])
        self.integral = np.zeros(len(motors))

    def currents(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The currents the law asks for, ``i_d`` (k,), A (clipped to the current limits)."""
        q_m, v_m, _, _ = self.plant.split(q, v)
        m = self.motors
        wanted = np.asarray(self.law.torque(t, q_m, v_m), dtype=float) / (m.gear_ratio * m.torque_constant)
        return np.clip(wanted, -m.current_limit, m.current_limit)

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The terminal voltages (k,), V, at time ``t`` and plant state ``(q, v)`` (the loop's
        controller interface: the plant's efforts are voltages); advances the integral by one
        period."""
        m = self.motors
        error = self.currents(t, q, v) - self.plant.split(q, v)[3]
        voltage = m.back_emf(self.plant.joint_rates(v)) + m.inductance * self.bandwidth * error + self.integral
        applied = m.applied(voltage)
        self.integral += np.where(applied == voltage, self.period * self.bandwidth * m.resistance * error, 0.0)
        return applied

    def reference(self, t: float) -> np.ndarray | None:
        """The law's reference at ``t``."""
        return self.law.reference(t)
