"""Pitch libration of a rigid satellite about its gravity-gradient equilibrium: the satellite, its
release off equilibrium, the closed-form period and the period measured from the motion.

At equilibrium the satellite's principal axes lie along LVLH (x radial: least moment Ix; y
along-track: Iy; z orbit normal: Iz) and it turns with the frame at n. Turned by a pitch angle
theta about the orbit normal, the gravity-gradient torque ``3 n^2 (Ix - Iy) sin(theta) cos(theta)``
(LVLH z) gives

.. math::
    I_z \\ddot\\theta = -\\tfrac{3}{2} n^2 (I_y - I_x) \\sin 2\\theta, \\qquad
    \\omega_0 = n \\sqrt{3 (I_y - I_x) / I_z}

stable for Iy > Ix. In the aerospace LVLH convention (x along-track, y against the orbit normal, z
nadir, pitch about y) the same frequency reads ``n sqrt(3 (Ix - Iz) / Iy)``. The equation is a
pendulum in 2 theta, so released at rest at theta0 the period is ``(4 / omega0) K(sin^2 theta0)``
(K the complete elliptic integral of the first kind, parameter m), ``2 pi / omega0`` as theta0 -> 0.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from .field import OrbitField
from .lvlh import free_flyer_state, root_in_lvlh
from .propagation import propagate
from .reference import CircularOrbit

__all__ = ["Libration", "crossing_period", "libration_period", "measure_libration", "pendulum_period",
           "release", "rigid_satellite", "rigid_satellite_urdf"]

#: The satellite of the built-in libration run: mass, kg, and principal moments (radial,
#: along-track, normal at equilibrium), kg m^2.
SATELLITE_MASS = 100.0
SATELLITE_INERTIA = (20.0, 60.0, 70.0)


def rigid_satellite_urdf(mass: float = SATELLITE_MASS, inertia: tuple[float, float, float] = SATELLITE_INERTIA) -> str:
    """A one-link URDF (link ``satellite``, CoM at its origin, principal axes along its frame)."""
    ixx, iyy, izz = inertia
    return (f'<robot name="satellite"><link name="satellite"><inertial><origin xyz="0 0 0" rpy="0 0 0"/>'
            f'<mass value="{mass!r}"/><inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" izz="{izz!r}"/>'
            '</inertial></link></robot>')


def rigid_satellite(mass: float = SATELLITE_MASS, inertia: tuple[float, float, float] = SATELLITE_INERTIA) -> pin.Model:
    """The one-body satellite of :func:`rigid_satellite_urdf` on a free-flyer root, gravity zero."""
    model = pin.buildModelFromXML(rigid_satellite_urdf(mass, inertia), pin.JointModelFreeFlyer())
    model.gravity.linear[:] = 0.0
    return model


def libration_period(orbit: CircularOrbit, inertia: tuple[float, float, float]) -> float:
    """Small-amplitude pitch libration period ``2 pi / (n sqrt(3 (Iy - Ix) / Iz))``, s, for
    principal moments (Ix radial, Iy along-track, Iz normal), kg m^2.

    Raises:
        InvalidArgument: when Iy <= Ix (the equilibrium is not stable in pitch).
    """
    ix, iy, iz = inertia
    if not iy > ix:
        raise InvalidArgument(f"libration: the along-track moment {iy!r} must exceed the radial one {ix!r} kg m^2 "
                              "for a stable pitch equilibrium")
    return 2.0 * math.pi / (orbit.mean_motion * math.sqrt(3.0 * (iy - ix) / iz))


def pendulum_period(orbit: CircularOrbit, inertia: tuple[float, float, float], amplitude: float) -> float:
    """The pitch period at a finite ``amplitude`` (rad, released at rest relative to LVLH):
    ``libration_period * (2 / pi) K(sin^2 amplitude)``, s (module docstring)."""
    from scipy.special import ellipk  # here: scipy costs every run's start 0.6 s

    return libration_period(orbit, inertia) * 2.0 / math.pi * float(ellipk(math.sin(amplitude) ** 2))


def release(orbit: CircularOrbit, pitch: float) -> tuple[np.ndarray, np.ndarray]:
    """q (7,) and v (6,) of a one-body satellite at the reference point, turned by ``pitch`` (rad)
    about the orbit normal from its equilibrium at t = 0, at rest relative to LVLH."""
    return free_flyer_state(orbit, 0.0, np.zeros(3), np.zeros(3), pin.utils.rotate("z", pitch))


def crossing_period(t: np.ndarray, signal: np.ndarray) -> float:
    """Mean period of an oscillation, s: the time between its first and last upward zero
    crossings (linear interpolation between samples) over the cycles between them.

    Raises:
        InvalidArgument: for fewer than two upward crossings.
    """
    up = np.flatnonzero((signal[:-1] < 0.0) & (signal[1:] >= 0.0))
    if up.size < 2:
        raise InvalidArgument(f"crossing_period: {up.size} upward zero crossing(s) in {t[-1] - t[0]:g} s; "
                              "at least two are needed")
    times = t[up] - signal[up] * (t[up + 1] - t[up]) / (signal[up + 1] - signal[up])
    return float((times[-1] - times[0]) / (times.size - 1))


class Libration(NamedTuple):
    """A measured libration run.

    Attributes:
        period: pitch period measured from the motion (upward zero crossings), s.
        closed_form: small-amplitude period :func:`libration_period`, s.
        pendulum: finite-amplitude period :func:`pendulum_period`, s.
        t: sample times, s (k,).
        pitch: pitch angle from the LVLH equilibrium, rad (k,).
    """

    period: float
    closed_form: float
    pendulum: float
    t: np.ndarray
    pitch: np.ndarray


def measure_libration(altitude: float = 400e3, amplitude: float = math.radians(5.0),
                      inertia: tuple[float, float, float] = SATELLITE_INERTIA, cycles: int = 3,
                      samples_per_cycle: int = 400, rtol: float = 1e-12) -> Libration:
    """Release :func:`rigid_satellite` ``amplitude`` rad off its pitch equilibrium in a circular
    orbit of ``altitude`` m, integrate the full two-body field for ``cycles`` closed-form periods
    plus a quarter (dopri5 at ``rtol``, :func:`.propagation.propagate`), and measure the period."""
    orbit = CircularOrbit(altitude=altitude)
    model = rigid_satellite(SATELLITE_MASS, inertia)
    closed = libration_period(orbit, inertia)
    t = np.linspace(0.0, (cycles + 0.25) * closed, int((cycles + 0.25) * samples_per_cycle) + 1)
    q, v = release(orbit, amplitude)
    Q, V = propagate(model, [OrbitField(model, orbit)], q, v, t, rtol=rtol)
    pitch = root_in_lvlh(orbit, t, Q, V).pitch()
    return Libration(crossing_period(t, pitch), closed, pendulum_period(orbit, inertia, amplitude), t, pitch)
