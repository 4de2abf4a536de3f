"""Conservation laws of a run with external wrenches: the momentum balanced against the impulse
of the wrenches (and of gravity), the energy against their work, the centre of mass against the
motion they cause.

A run without external wrench conserves its momentum, and :mod:`.metrics` reports how far it
drifts. With wrenches (a capture impulse modelled as a torque pulse, say) the momentum changes by
the impulse applied, so what can be checked is the balance

.. math::
    h(t) - h(t_0) - \\int_{t_0}^{t} \\sum_i \\begin{bmatrix} f_i \\\\ r_i \\times f_i + n_i
    \\end{bmatrix} s_i(\\tau)\\,d\\tau, \\qquad
    E(t) - E(t_0) - W_\\tau(t) - \\int_{t_0}^{t} \\sum_i s_i (f_i \\cdot \\dot r_i + n_i \\cdot
    \\omega_i)\\,d\\tau,

with ``h = [P; L about the inertial origin]``, ``f_i``, ``n_i`` the inertial force and torque of
wrench ``i`` at the CoM ``r_i`` of its link (angular velocity ``omega_i``), ``s_i`` its profile
and ``W_tau`` the joint torques' work. The integrals are taken as the loop applies the wrenches
(:mod:`.simulation`, ``cpp/sim/wrench_field.hpp``): the profile sampled at the start of each
control period ``t_0 + j h`` and held over it. So the linear impulse and the impulse of the
torques are exact sums. The moment of a force (``r_i`` moves during a period) and the work use
the recorded states: ``r_i`` between two rows is the cubic with the recorded positions and
velocities at both ends (Hermite), integrated exactly (for one period,
``h (r_j + r_{j+1}) / 2 + h^2 (v_j - v_{j+1}) / 12``, error O(h^5)); the work of a force is
``f . (r_{j+1} - r_j)``, exact when every period is recorded; the work of a torque ``n . int w
dt`` with ``int w dt = log(R_{j+1} R_j^T) + h^2 / 12 w_j x w_{j+1}`` (Magnus' expansion to
third order; exact for a rotation about a fixed axis, as on planar robots), the rotation
between two rows split evenly over their periods.

A field of the environment (:class:`~.wrenches.WrenchField`, of time and state, which the loop
evaluates at every stage's own time) is integrated from the recorded rows by the trapezoidal rule: its total ``wrench`` for the impulse, the power of its
joint ``forces`` at the joints' velocities for the work (second order in the row spacing; exact
for the linear impulse of a constant force). A field whose wrench the rule would integrate badly
(thrusts that switch at every period) gives its own impulse and work from the rows,
``impulse(t, q, v)`` -> (N, 6) and ``work(t, q, v)`` -> (N,)
(:meth:`freefloat.space.thrusters.ThrusterSet.impulse`), which replace the rule's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..robot.robot import Robot
from .telemetry import Telemetry
from .wrenches import ExternalWrench, WrenchField, WrenchProfiles, field_power


def free_com_motion(telemetry: Telemetry, robot: Robot) -> np.ndarray:
    """System-CoM path that momentum conservation demands without external wrenches (N, 3):
    ``com(0) + t P(0) / m + g t^2 / 2`` (inertial frame, m)."""
    tel = telemetry
    t = tel.t - tel.t[0]
    mass = pin.computeTotalMass(robot.model)
    return tel.com[0] + np.outer(t, tel.momentum[0, :3] / mass) + 0.5 * np.outer(t**2, robot.model.gravity.linear)


class Applied(NamedTuple):
    """What the external wrenches and gravity applied from ``t[0]`` to each sample.

    Attributes:
        impulse: ``[int F dt; int (r x F + n) dt]``, linear impulse (N s) and angular impulse
            about the inertial origin (N m s), inertial frame (N, 6); gravity included.
        work: work of the external wrenches, J (N,); gravity's is in the potential energy.
        com_shift: ``int_{t0}^{t} int F dt dt' / m``, how far the forces (not gravity, which
            :func:`free_com_motion` has) move the system CoM, m (N, 3).
    """

    impulse: np.ndarray
    work: np.ndarray
    com_shift: np.ndarray


class Balance(NamedTuple):
    """Residuals of the conservation laws at each sample (what the loop got wrong).

    Attributes:
        momentum: ``h(t) - h(t0) - impulse(t)``, kg m/s and kg m^2/s (N, 6).
        energy: ``E(t) - E(t0) - W_tau(t) - W_ext(t)``, J (N,).
        com: system CoM minus its motion under the momentum at t0, gravity and the forces, m (N, 3).
        applied: the impulse and work the residuals are balanced against.
    """

    momentum: np.ndarray
    energy: np.ndarray
    com: np.ndarray
    applied: Applied


def profile_scales(wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench], times: np.ndarray) -> np.ndarray:
    """Every wrench's profile at ``times`` (n,): 0 outside [start, end), the linear rise, then 1
    (:meth:`ExternalWrench.scale`, vectorised); (n, k)."""
    t = np.asarray(times, float)[:, None]
    start, end, rise = (np.array([getattr(w, key) for w in wrenches], float) for key in ("start", "end", "rise"))
    ramp = np.minimum(1.0, (t - start) / np.where(rise > 0.0, rise, 1.0))
    return np.where((start <= t) & (t < end), np.where(rise > 0.0, ramp, 1.0), 0.0)


def applied(robot: Robot, telemetry: Telemetry, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench],
            control_period: float, environment: Sequence[WrenchField] = ()) -> Applied:
    """The impulse and work of ``wrenches`` and gravity over a run, as the loop applied them
    (module docstring).

    Args:
        robot: the robot the telemetry was recorded on (the full robot of a locked run).
        telemetry: the run; its rows lie on the control grid ``t[0] + j control_period``.
        wrenches: the run's external wrenches.
        control_period: s.
        environment: the run's wrench fields (:func:`field_applied`).
    """
    done = _profiles_applied(robot, telemetry, wrenches, control_period)
    if not environment or len(telemetry.t) == 0:
        return done
    more = field_applied(robot, telemetry, environment)
    return Applied(*(a + b for a, b in zip(done, more)))


def field_applied(robot: Robot, telemetry: Telemetry, environment: Sequence[WrenchField]) -> Applied:
    """The impulse, work and CoM shift of wrench fields over a run (trapezoidal rule over the
    rows: module docstring), each field evaluated at a row's own time and state, as the loop's
    integrator stages see it."""
    tel, model = telemetry, robot.model
    data = model.createData()
    rows = len(tel.t)
    own = [f for f in environment if hasattr(f, "impulse")]
    ruled = [f for f in environment if not hasattr(f, "impulse")]
    total, power = np.zeros((rows, 6)), np.zeros(rows)
    for row in range(rows if ruled else 0):
        t, q, v = tel.t[row], tel.q[row], tel.v[row]
        pin.forwardKinematics(model, data, q, v)
        for field in ruled:
            forces = field.forces(t, q, v)
            if forces is not None:
                total[row] += field.wrench(t, q, v)
                power[row] += field_power(model, data, forces)
    gaps = np.diff(tel.t)[:, None]
    impulse = np.vstack((np.zeros(6), np.cumsum(0.5 * gaps * (total[1:] + total[:-1]), axis=0)))
    work = np.concatenate(([0.0], np.cumsum(0.5 * gaps[:, 0] * (power[1:] + power[:-1]))))
    for field in own:
        impulse += field.impulse(tel.t, tel.q, tel.v)
        work += field.work(tel.t, tel.q, tel.v)
    linear = impulse[:, :3]
    shift = np.vstack((np.zeros(3), np.cumsum(0.5 * gaps * (linear[1:] + linear[:-1]), axis=0)))
    return Applied(impulse, work, shift / pin.computeTotalMass(model))


def _profiles_applied(robot: Robot, telemetry: Telemetry, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench],
                      control_period: float) -> Applied:
    """:func:`applied` of the profiles and gravity."""
    tel, h = telemetry, control_period
    t0, rows = tel.t[0], len(tel.t)
    row_period = np.rint((tel.t - t0) / h).astype(int)
    n = int(row_period[-1])
    mass = pin.computeTotalMass(robot.model)
    gravity = robot.model.gravity.linear
    since = tel.t - t0
    impulse = np.zeros((rows, 6))
    impulse[:, :3] = mass * np.outer(since, gravity)
    moment = np.cross(tel.com, mass * gravity)  # angular impulse of gravity: trapezoidal rule
    impulse[1:, 3:] = np.cumsum(0.5 * (moment[1:] + moment[:-1]) * np.diff(since)[:, None], axis=0)
    work, shift = np.zeros(rows), np.zeros((rows, 3))
    if not wrenches or n == 0:
        return Applied(impulse, work, shift)
    joints, coms, forces, torques, *_ = WrenchProfiles(robot, wrenches).profiles()
    periods = np.arange(n)
    scales = profile_scales(wrenches, t0 + periods * h)  # (n, k), as the loop samples them
    on = scales.any(axis=1)
    # Row interval of each period and where the period's ends fall in it, as fractions of it.
    k = np.searchsorted(row_period, periods, side="right") - 1
    span = (row_period[k + 1] - row_period[k]).astype(float)
    a, b = (periods - row_period[k]) / span, (periods + 1 - row_period[k]) / span
    needed = np.unique(np.concatenate((k[on], k[on] + 1)))
    position, velocity, spin = np.zeros((3, rows, len(joints), 3))
    rotation = np.tile(np.eye(3), (rows, len(joints), 1, 1))
    model, data = robot.model, robot.model.createData()
    for row in needed:
        pin.forwardKinematics(model, data, tel.q[row], tel.v[row])
        for i, (joint, com) in enumerate(zip(joints, coms)):
            placement, twist = data.oMi[joint], data.v[joint]  # twist: joint frame, at its origin
            position[row, i] = placement.act(com)
            velocity[row, i] = placement.rotation @ (twist.linear + np.cross(twist.angular, com))
            rotation[row, i] = placement.rotation
            spin[row, i] = placement.rotation @ twist.angular
    turn = np.zeros((rows, len(joints), 3))  # int w dt from row r to r + 1, inertial frame (Magnus)
    gaps = np.diff(tel.t)
    for row in needed[needed + 1 < rows]:
        for i in range(len(joints)):
            turn[row, i] = (pin.log3(rotation[row + 1, i] @ rotation[row, i].T)
                            + gaps[row] ** 2 / 12 * np.cross(spin[row, i], spin[row + 1, i]))
    duration = (span * h)[:, None, None]
    ends = (position[k], duration * velocity[k], position[k + 1], duration * velocity[k + 1])
    start, end = (sum(c[:, None, None] * e for c, e in zip(_hermite(s), ends)) for s in (a, b))
    weights = zip(_hermite_integral(a), _hermite_integral(b))
    mean = sum((c1 - c0)[:, None, None] * e for (c0, c1), e in zip(weights, ends)) / (b - a)[:, None, None]
    f, tq = scales[:, :, None] * forces, scales[:, :, None] * torques  # (n, k, 3)
    per_period = np.zeros((n, 6))
    per_period[:, :3] = h * f.sum(axis=1)
    per_period[:, 3:] = h * (np.cross(mean, f) + tq).sum(axis=1)
    period_work = (np.einsum("nki,nki->n", f, end - start)
                   + np.einsum("nki,nki->n", tq, (b - a)[:, None, None] * turn[k]))
    cumulative = np.vstack((np.zeros(6), np.cumsum(per_period, axis=0)))  # at the period boundaries
    impulse += cumulative[row_period]
    work = np.concatenate(([0.0], np.cumsum(period_work)))[row_period]
    linear = cumulative[:, :3]  # piecewise linear in t: the trapezoidal rule integrates it exactly
    integral = np.vstack((np.zeros(3), np.cumsum(0.5 * h * (linear[1:] + linear[:-1]), axis=0)))
    return Applied(impulse, work, integral[row_period] / mass)


def _hermite(s: np.ndarray) -> tuple[np.ndarray, ...]:
    """Cubic Hermite basis at ``s`` in [0, 1] (n,): weights of p0, d0, p1, d1 (d: the
    derivative times the interval)."""
    return 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2


def _hermite_integral(s: np.ndarray) -> tuple[np.ndarray, ...]:
    """Integrals from 0 to ``s`` of :func:`_hermite`'s basis (n,)."""
    return (s**4 / 2 - s**3 + s, s**4 / 4 - 2 * s**3 / 3 + s**2 / 2, -(s**4) / 2 + s**3, s**4 / 4 - s**3 / 3)


def balance(robot: Robot, telemetry: Telemetry, wrenches: tuple[ExternalWrench, ...] | list[ExternalWrench],
            control_period: float, environment: Sequence[WrenchField] = ()) -> Balance:
    """The residuals of momentum, energy and CoM motion against what ``wrenches``, the
    ``environment``'s fields and gravity applied (:func:`applied`); zero for an exact integration."""
    tel = telemetry
    done = applied(robot, tel, wrenches, control_period, environment)
    return Balance(momentum=tel.momentum - tel.momentum[0] - done.impulse,
                   energy=tel.energy - tel.energy[0] - tel.work - done.work,
                   com=tel.com - free_com_motion(tel, robot) - done.com_shift, applied=done)
