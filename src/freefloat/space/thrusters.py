r"""Thrusters on the base: a wrench field whose thrusts a controller commands each control period.

Each thruster ``i`` sits at ``r_i`` in the base joint's frame (the base-link frame of a loaded
robot, m) and pushes the base along the unit vector ``d_i`` of that frame (the force on the base;
the exhaust leaves the other way) with a thrust ``0 <= F_i <= F_max``. Together they apply, at the
base joint's origin and in its frame, the wrench

.. math:: w_b = B F, \qquad B = \begin{bmatrix} d_1 & \cdots & d_k \\
          r_1 \times d_1 & \cdots & r_k \times d_k \end{bmatrix} \quad (6, k).

**Allocation.** A commanded base wrench ``w`` becomes non-negative thrusts by non-negative least
squares, ``F = argmin_{F >= 0} |B F - w|`` (Lawson-Hanson, :func:`scipy.optimize.nnls`): exact when
``w`` lies in the cone the thrusters span. When a thrust exceeds ``F_max``, every thrust is scaled
by the same factor, so the wrench keeps its direction and shrinks (the allocation is then no
longer exact, which the controller sees through its feedback).

**Pulses.** A thruster fires in pulses within a control period of ``h`` s (pulse-width
modulation); the loop holds a field's wrench over the period, so the period's impulse ``F h`` is
applied as the average thrust ``F`` over it. A valve cannot give less than its minimum impulse bit
``I_min``: an impulse below it is rounded to 0 or to ``I_min`` (whichever is nearer), the thrust
then ``I_min / h``.

**Propellant.** The mass flow of a thruster is ``F / (I_sp g_0)``, so over a run

.. math:: m_p = \frac{\sum_i \int F_i\,dt}{I_{sp}\, g_0}, \qquad
          \Delta v = I_{sp}\, g_0 \ln \frac{m_0}{m_0 - m_p},

``m_0`` the robot's mass at the start (Tsiolkovsky's rocket equation; the dynamics keep the mass
``m_0``: the propellant burnt is taken as small against it, ``Delta v`` differs from the first
order ``sum_i int F_i dt / m_0`` by a part ``m_p / (2 m_0)``).

**Impulse.** The field's inertial wrench about the origin, ``[R f_b; p x R f_b + R n_b]`` with the
base pose ``(R, p)``, changes within a period as the base turns and moves. :meth:`ThrusterSet.impulse`
integrates it per period by Simpson's rule, the base pose at the period's middle from the cubic
(Hermite) interpolation of the recorded poses and velocities at its ends (rotation: in the Lie
algebra at the first end); the system momentum changes by this impulse to the integrator's and the
rule's error (``O(h^4)`` per period); the run's balances take it (:mod:`freefloat.dynamics.balance`).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..arguments import real_number
from ..errors import InvalidArgument
from ..robot.robot import Robot

__all__ = ["G0", "SUMMARY_UNITS", "ThrusterSet", "ThrusterSettings", "cube_layout", "thruster_summary"]

#: Standard gravity, m/s^2: the specific impulse's unit conversion (I_sp g_0 is the exhaust speed).
G0 = 9.80665
#: Relative tolerance of the unit-direction check.
DIRECTION_TOLERANCE = 1e-6


def cube_layout(arm: float) -> tuple[np.ndarray, np.ndarray]:
    """Twelve thrusters in pairs at ``+-arm`` on each axis of the base frame, each pair firing both
    ways along the next axis (at ``+-arm x`` along ``+-y``, at ``+-arm y`` along ``+-z``, at
    ``+-arm z`` along ``+-x``): every force and every torque is a non-negative combination (the
    columns of ``B`` span R^6 positively). Positions (12, 3), m, and unit directions (12, 3)."""
    positions, directions = [], []
    for axis in range(3):
        along = np.eye(3)[(axis + 1) % 3]
        for side in (1.0, -1.0):
            for sense in (1.0, -1.0):
                positions.append(side * arm * np.eye(3)[axis])
                directions.append(sense * along)
    return np.array(positions), np.array(directions)


@dataclass(frozen=True)
class ThrusterSettings:
    """``[[environment]]`` keys of kind ``"thrusters"`` (SI units):

    ``positions`` (k rows of 3, m) and ``directions`` (k rows of 3, unit: the force on the base)
    in the base-link frame, both absent for the twelve-thruster layout of :func:`cube_layout` at
    ``arm`` m; ``max_thrust`` (N), ``min_impulse_bit`` (N s, 0: none) and ``specific_impulse``
    (s), the same for every thruster."""

    positions: tuple[tuple[float, ...], ...] | None = None
    directions: tuple[tuple[float, ...], ...] | None = None
    arm: float = 0.5
    max_thrust: float = 10.0
    min_impulse_bit: float = 0.0
    specific_impulse: float = 220.0

    def __post_init__(self) -> None:
        if (self.positions is None) != (self.directions is None):
            raise InvalidArgument("thrusters: give both 'positions' and 'directions' (base-link frame), or neither "
                                  "(the twelve-thruster layout at 'arm')")
        real_number("arm", self.arm, above=0.0)
        real_number("max_thrust", self.max_thrust, above=0.0)
        real_number("min_impulse_bit", self.min_impulse_bit, low=0.0)
        real_number("specific_impulse", self.specific_impulse, above=0.0)
        if self.positions is None:
            return
        positions, directions = np.array(self.positions, float), np.array(self.directions, float)
        if positions.ndim != 2 or positions.shape[1:] != (3,) or directions.shape != positions.shape:
            raise InvalidArgument(f"thrusters: 'positions' and 'directions' must be as many rows of 3 numbers, got "
                                  f"{positions.shape} and {directions.shape}")
        lengths = np.linalg.norm(directions, axis=1)
        bad = np.flatnonzero(np.abs(lengths - 1.0) > DIRECTION_TOLERANCE)
        if bad.size:
            raise InvalidArgument(f"thrusters: 'directions[{bad[0]}]' = {directions[bad[0]].tolist()} has length "
                                  f"{lengths[bad[0]]:.6g}; give unit vectors (the force's direction on the base)")

    def layout(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (k, 3), m, and unit directions (k, 3), base-link frame."""
        if self.positions is None:
            return cube_layout(self.arm)
        return np.array(self.positions, float), np.array(self.directions, float)


class ThrusterSet:
    """Thrusters on a free-flying robot's base: a :class:`freefloat.WrenchField` whose thrusts the
    controller sets at the start of each control period (:meth:`command`), held over it.

    Args:
        robot: a robot with a free-flyer base (joint 1).
        settings: the geometry and limits.

    Attributes:
        B: unit-thrust wrenches ``[d_i; r_i x d_i]`` at the base joint's origin, base frame (6, k).
        max_thrust: N. min_impulse_bit: N s. specific_impulse: s. mass: the robot's mass, kg.
        times: the start (s) of each commanded period, increasing.
        thrusts: the thrusts (N) held from each of ``times`` on, (k,) each.

    Raises:
        InvalidArgument: for a robot whose base is not free.
    """

    def __init__(self, robot: Robot, settings: ThrusterSettings):
        if robot.base != "free":
            raise InvalidArgument(f"thrusters: the robot's base is '{robot.base}'; thrusters act on a free-flyer base "
                                  "(a planar joint would take up the thrust out of its plane)")
        self.model, self.data = robot.model, robot.model.createData()
        self.positions, self.directions = settings.layout()
        self.B = np.vstack((self.directions.T, np.cross(self.positions, self.directions).T))
        self.max_thrust, self.min_impulse_bit = settings.max_thrust, settings.min_impulse_bit
        self.specific_impulse = settings.specific_impulse
        self.mass = float(pin.computeTotalMass(self.model))
        self.times: list[float] = []
        self.thrusts: list[np.ndarray] = []
        self._zero = np.zeros(len(self.positions))

    @property
    def count(self) -> int:
        """Number of thrusters k."""
        return len(self.positions)

    def allocate(self, wrench: np.ndarray) -> np.ndarray:
        """Thrusts (k,), N, ``>= 0``, for the base wrench ``wrench`` = [force; torque about the base
        joint's origin], base frame (6,): non-negative least squares on ``B``, then scaled down
        together when one exceeds ``max_thrust`` (module docstring)."""
        from scipy.optimize import nnls  # here: scipy costs every run's start 0.6 s

        thrusts, _ = nnls(self.B, np.asarray(wrench, float))
        largest = float(thrusts.max(initial=0.0))
        return thrusts * (self.max_thrust / largest) if largest > self.max_thrust else thrusts

    def pulses(self, thrusts: np.ndarray, period: float) -> np.ndarray:
        """The thrusts (k,), N, the valves give over a period of ``period`` s for the asked
        ``thrusts`` (k,): within ``[0, max_thrust]``, an impulse below the minimum impulse bit
        rounded to 0 or to the bit.

        Raises:
            InvalidArgument: when the minimum impulse bit exceeds ``max_thrust * period``.
        """
        self.check_period(period)
        thrusts = np.clip(np.asarray(thrusts, float), 0.0, self.max_thrust)
        bit = self.min_impulse_bit / period
        small = thrusts < bit
        return np.where(small, np.where(thrusts >= 0.5 * bit, bit, 0.0), thrusts)

    def check_period(self, period: float) -> None:
        """Check that a control period of ``period`` s can give the minimum impulse bit.

        Raises:
            InvalidArgument: when the minimum impulse bit exceeds ``max_thrust * period``.
        """
        if self.min_impulse_bit > self.max_thrust * period:
            raise InvalidArgument(f"thrusters: 'min_impulse_bit' {self.min_impulse_bit:g} N s exceeds the most one "
                                  f"control period of {period:g} s can give, max_thrust x period = "
                                  f"{self.max_thrust * period:g} N s")

    def command(self, t: float, thrusts: np.ndarray, period: float) -> np.ndarray:
        """Hold ``thrusts`` (k,), N, from ``t`` s on (after :meth:`pulses`); a command at or before
        an earlier one (a run restarted) forgets the later history. The thrusts held (k,)."""
        held = self.pulses(thrusts, period)
        while self.times and self.times[-1] >= t:
            self.times.pop()
            self.thrusts.pop()
        self.times.append(float(t))
        self.thrusts.append(held)
        return held

    def thrust(self, t: float) -> np.ndarray:
        """The thrusts held at ``t`` (k,), N (zero before the first command)."""
        i = bisect_right(self.times, t + 1e-12) - 1  # the list as it is: no array built per stage
        return self.thrusts[i] if i >= 0 else self._zero

    def forces(self, t: float, q: np.ndarray, v: np.ndarray) -> list[pin.Force] | None:
        """The thrusters' wrench on the base joint (its frame, moment about its origin), one
        ``pin.Force`` per joint; None when none fires."""
        thrusts = self.thrust(t)
        if not thrusts.any():
            return None
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        out[1] = pin.Force(self.B @ thrusts)
        return out

    def wrench(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``[R f_b; p x R f_b + R n_b]``: force (N) and torque about the inertial origin (N m),
        inertial frame (6,), at the base pose ``(R, p)`` of ``q``."""
        pin.forwardKinematics(self.model, self.data, q)
        return _inertial(self.data.oMi[1], self.B @ self.thrust(t))

    def impulse(self, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The impulse ``[int f dt (N s); int torque about the origin dt (N m s)]``, inertial frame,
        applied from ``t[0]`` to each row (N, 6), from rows ``t`` (N,), ``q`` (N, nq), ``v`` (N, nv)
        that hold every commanded period's start: Simpson's rule per period with the base's
        mid-period pose interpolated (module docstring)."""
        out = np.zeros((len(t), 6))
        total = np.zeros(6)
        joint_placement = self.model.jointPlacements[1]
        for row in range(len(t) - 1):
            thrusts = self.thrust(t[row])
            if thrusts.any():
                h = t[row + 1] - t[row]
                ends = [joint_placement * pin.XYZQUATToSE3(q[r][:7]) for r in (row, row + 1)]
                middle = _middle(ends[0], ends[1], v[row][:6], v[row + 1][:6], h)
                wrench = self.B @ thrusts
                total += h / 6.0 * (_inertial(ends[0], wrench) + 4.0 * _inertial(middle, wrench)
                                    + _inertial(ends[1], wrench))
            out[row + 1] = total
        return out

    def work(self, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The work (J) done from ``t[0]`` to each row (N,), from the rows as :meth:`impulse` takes
        them: per period, the held base wrench times the base joint's displacement in its own frame,
        ``w_b . log6(M_k^-1 M_k+1)`` (exact for a constant body twist over the period)."""
        out = np.zeros(len(t))
        for row in range(len(t) - 1):
            thrusts = self.thrust(t[row])
            step = 0.0
            if thrusts.any():
                ends = [pin.XYZQUATToSE3(q[r][:7]) for r in (row, row + 1)]
                step = float(self.B @ thrusts @ pin.log6(ends[0].actInv(ends[1])).vector)
            out[row + 1] = out[row] + step
        return out

    def total_impulse(self, end: float) -> np.ndarray:
        """``int F_i dt`` of each thruster from the first command to ``end`` s (k,), N s."""
        return self.impulse_until(np.array([end]))[0]

    def impulse_until(self, t: np.ndarray) -> np.ndarray:
        """``int F_i dt`` of each thruster from the first command to each of the times ``t``
        (N,), s: (N, k), N s, from the commands held (exact for any sampling of the run)."""
        t = np.asarray(t, float)
        if not self.times:
            return np.zeros((len(t), self.count))
        starts, held = np.array(self.times), np.array(self.thrusts)
        before = np.vstack((np.zeros(self.count), np.cumsum(np.diff(starts)[:, None] * held[:-1], axis=0)))
        last = np.searchsorted(starts, t, side="right") - 1  # the command held at each t (-1: none yet)
        since = np.clip(t - starts[np.maximum(last, 0)], 0.0, None)[:, None]
        return np.where((last >= 0)[:, None], before[np.maximum(last, 0)] + since * held[np.maximum(last, 0)], 0.0)

    def delta_v(self, propellant: float) -> float:
        """Tsiolkovsky's ``I_sp g_0 ln(m_0 / (m_0 - m_p))``, m/s, for ``propellant`` m_p kg burnt
        from the robot's mass m_0 (:attr:`mass`; module docstring)."""
        return -self.specific_impulse * G0 * math.log1p(-propellant / self.mass)

    def rows(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """What a run's ``thrusters`` figure draws at the times ``t`` (N,), s: the thrusts held
        (N, k), N, and the propellant burnt since the first command (N,), kg
        (:meth:`impulse_until` over ``I_sp g_0``)."""
        thrust = np.array([self.thrust(s) for s in t]).reshape(len(t), self.count)
        return thrust, self.impulse_until(t).sum(axis=1) / (self.specific_impulse * G0)


def _inertial(placement: pin.SE3, wrench: np.ndarray) -> np.ndarray:
    """A base-frame wrench at the base joint's origin (6,) as [force; torque about the inertial
    origin], inertial frame (6,), at the base joint's ``placement``."""
    return placement.act(pin.Force(wrench)).vector


def _middle(start: pin.SE3, end: pin.SE3, v0: np.ndarray, v1: np.ndarray, h: float) -> pin.SE3:
    """The base joint's pose halfway between two rows ``h`` s apart, from the poses and the local
    velocities ``[v; w]`` (6,) at both: cubic Hermite in position, and in the rotation's Lie
    algebra at ``start`` (``phi(1/2) = phi_1 / 2 + h (w_0 - w_1) / 8``)."""
    p0, p1 = start.translation, end.translation
    p = 0.5 * (p0 + p1) + h / 8.0 * (start.rotation @ v0[:3] - end.rotation @ v1[:3])
    phi = pin.log3(start.rotation.T @ end.rotation)
    rotation = start.rotation @ pin.exp3(0.5 * phi + h / 8.0 * (v0[3:] - v1[3:]))
    return pin.SE3(rotation, p)


#: The unit of each key :func:`thruster_summary` adds ("" for a count).
SUMMARY_UNITS = {
    "thruster_impulse_total": "N s", "thruster_impulse_each": "N s", "propellant_mass": "kg",
    "thruster_delta_v": "m/s", "thruster_impulse": "N s, N m s", "thruster_firings": "",
}


def thruster_summary(field: ThrusterSet, robot: Robot, telemetry: Any) -> dict[str, Any]:
    """What the thrusters did over a run (``telemetry`` of ``robot``): each thruster's impulse
    ``int F_i dt`` and their sum (N s), the propellant mass (kg) and the delta-v (m/s, the rocket
    equation) they cost (module docstring), their net impulse ``[N s; N m s about the origin]`` (inertial, (6,), at the
    end; the run's ``momentum_balance_max`` balances the momentum against it), and
    ``thruster_firings``: the (period, thruster) pairs with a non-zero thrust.

    Units: :data:`SUMMARY_UNITS`.
    """
    tel = telemetry
    each = field.total_impulse(float(tel.t[-1]))
    total = float(each.sum())
    propellant = total / (field.specific_impulse * G0)
    return {
        "thruster_impulse_total": total,
        "thruster_impulse_each": each.tolist(),
        "propellant_mass": propellant,
        "thruster_delta_v": field.delta_v(propellant),
        "thruster_impulse": field.impulse(tel.t, tel.q, tel.v)[-1].tolist(),
        "thruster_firings": int(sum(np.count_nonzero(f) for f in field.thrusts)),
    }
