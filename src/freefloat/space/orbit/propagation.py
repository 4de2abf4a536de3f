"""Time-dependent fields integrated with their exact stage times, on freefloat's adaptive
Dormand-Prince 5(4) in the Munthe-Kaas chart.

A field of time and state such as :class:`.field.OrbitField` needs t at every stage. Here the
time is carried as one more coordinate: the model gains a prismatic "clock" joint whose velocity
is 1 and acceleration 0, so its coordinate is t exactly at every stage (the chart is a vector
space along it). The engine's loop gives its stages the same times through a
:class:`~freefloat.dynamics.integrators.TimeVarying` acceleration instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
import pinocchio as pin

from ...dynamics.integrators import DormandPrince45
from ...robot.robot import Robot

__all__ = ["TimeField", "propagate"]


class TimeField(Protocol):
    """A wrench field of time and state (DESIGN-37's ``WrenchField``)."""

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> list[pin.Force] | None: ...


def clocked(model: pin.Model) -> pin.Model:
    """A copy of ``model`` with a last, massless prismatic joint on the universe (the clock):
    configuration [q; t], velocity [v; 1]."""
    out = pin.Model(model)
    out.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "orbit_clock")
    return out


def propagate(robot: Robot | pin.Model, fields: Sequence[TimeField], q0: np.ndarray, v0: np.ndarray,
              times: np.ndarray, start_time: float = 0.0, rtol: float = 1e-12, atol: float = 1e-12
              ) -> tuple[np.ndarray, np.ndarray]:
    """Free motion (no joint torques) of ``robot`` under ``fields`` (summed), sampled at ``times``.

    Args:
        robot: the robot or its Pinocchio model (its gravity applies too: keep it zero in orbit).
        fields: wrench fields ``forces(t, q, v)``.
        q0: configuration at ``start_time`` (nq,).
        v0: velocity at ``start_time`` (nv,), Pinocchio's local convention.
        times: sample times after ``start_time``, s, increasing from 0 (k,).
        start_time: simulation time of ``times[0] = 0``, s (the fields see ``start_time + s``).
        rtol: relative tolerance of dopri5.
        atol: absolute tolerance of dopri5.

    Returns:
        q (k, nq) and v (k, nv) at ``times`` (dense output between accepted steps).
    """
    model = robot.model if isinstance(robot, Robot) else robot
    data, zero = model.createData(), np.zeros(model.nv)

    def acceleration(qc: np.ndarray, vc: np.ndarray) -> np.ndarray:
        q, v, t = qc[:-1], vc[:-1], start_time + qc[-1]
        total = [pin.Force.Zero() for _ in range(model.njoints)]
        for field in fields:
            for j, f in enumerate(field.forces(t, q, v) or ()):
                total[j] += f
        return np.append(pin.aba(model, data, q, v, zero, total), 0.0)

    integrator = DormandPrince45(clocked(model), rtol=rtol, atol=atol)
    Q, V = integrator.solve(acceleration, np.append(q0, 0.0), np.append(v0, 1.0), np.asarray(times, dtype=float))
    return Q[:, :-1], V[:, :-1]
