"""The reference circular orbit, its LVLH (Hill) frame, and the Clohessy-Wiltshire closed form.

Frames (all right-handed, SI units):

- **Earth-centred inertial (ECI)**: origin at the Earth's centre; the reference orbit lies in its
  x-y plane, counter-clockwise about +z, on the +x axis at ``t = phase / n = 0`` when
  ``phase = 0``.
- **Simulation frame**: ECI axes, origin on the reference orbit point ``R0(t)``; it falls freely
  with the orbit and does not rotate. Robot states (q, v) are given in it.
- **LVLH (Hill) frame**: origin on ``R0(t)``; x radial out (``R0 / |R0|``), y along-track
  (``V0 / |V0|``), z the orbit normal (ECI +z); it turns at ``n`` about z.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from ...arguments import real_number
from ...errors import InvalidArgument

__all__ = ["EARTH_MU", "EARTH_RADIUS", "CircularOrbit", "OrbitSettings", "clohessy_wiltshire"]

#: Earth's gravitational parameter, m^3/s^2 (WGS 84).
EARTH_MU = 3.986004418e14
#: Earth's equatorial radius, m (WGS 84); the Earth is a sphere here.
EARTH_RADIUS = 6378137.0


class CircularOrbit:
    """A circular Keplerian orbit about a spherical Earth, given by exactly one of ``altitude``
    (m above ``EARTH_RADIUS``) or ``mean_motion`` (rad/s).

    Args:
        altitude: height of the orbit above the Earth's surface, m (> 0).
        mean_motion: n, rad/s (> 0); its radius ``(mu / n^2)^(1/3)`` must lie above the surface.
        phase: argument of latitude at t = 0, rad (the angle of ``R0(0)`` from ECI +x).
        mu: gravitational parameter, m^3/s^2.

    Attributes:
        radius: orbit radius |R0|, m.
        mean_motion: n = sqrt(mu / radius^3), rad/s.
        period: 2 pi / n, s.

    Raises:
        InvalidArgument: for neither or both of ``altitude`` and ``mean_motion``, a non-positive
            one, or a mean motion whose orbit would pass inside the Earth.
    """

    def __init__(self, *, altitude: float | None = None, mean_motion: float | None = None, phase: float = 0.0,
                 mu: float = EARTH_MU):
        if (altitude is None) == (mean_motion is None):
            raise InvalidArgument("orbit: give exactly one of 'altitude' (m) and 'mean_motion' (rad/s)")
        self.mu = real_number("mu", mu, above=0.0)
        self.phase = real_number("phase", phase)
        if altitude is not None:
            self.radius = EARTH_RADIUS + real_number("altitude", altitude, above=0.0)
            self.mean_motion = math.sqrt(self.mu / self.radius**3)
        else:
            self.mean_motion = real_number("mean_motion", mean_motion, above=0.0)
            self.radius = (self.mu / self.mean_motion**2) ** (1.0 / 3.0)
            if self.radius <= EARTH_RADIUS:
                raise InvalidArgument(f"orbit: 'mean_motion' {mean_motion!r} rad/s gives a radius of "
                                      f"{self.radius:.6g} m, inside the Earth (radius {EARTH_RADIUS:.0f} m)")
        self.period = 2.0 * math.pi / self.mean_motion

    @property
    def altitude(self) -> float:
        """Height above the Earth's surface, m."""
        return self.radius - EARTH_RADIUS

    def __repr__(self) -> str:
        return f"CircularOrbit(altitude={self.altitude:.6g}, mean_motion={self.mean_motion:.9g}, phase={self.phase:g})"

    def later(self, start: float) -> CircularOrbit:
        """This orbit on a clock started ``start`` s later: its ``R0(t)`` is this one's
        ``R0(start + t)`` (its phase advanced by ``n start``; radius and mean motion the same), for
        a run that begins at ``start`` s of another's time."""
        out = copy.copy(self)
        out.phase = self.phase + self.mean_motion * start
        return out

    def angle(self, t: float | np.ndarray) -> float | np.ndarray:
        """Argument of latitude ``phase + n t``, rad (scalar or (k,) for (k,) times)."""
        return self.phase + self.mean_motion * np.asarray(t, dtype=float)

    def position(self, t: float) -> np.ndarray:
        """R0(t): the reference point, ECI, m (3,)."""
        u = self.phase + self.mean_motion * t
        return self.radius * np.array([math.cos(u), math.sin(u), 0.0])

    def velocity(self, t: float) -> np.ndarray:
        """V0(t) = dR0/dt, ECI, m/s (3,)."""
        u = self.phase + self.mean_motion * t
        return self.radius * self.mean_motion * np.array([-math.sin(u), math.cos(u), 0.0])

    def angular_velocity(self) -> np.ndarray:
        """The LVLH frame's angular velocity, ECI (= LVLH) axes, rad/s (3,): n along the orbit normal."""
        return np.array([0.0, 0.0, self.mean_motion])

    def lvlh_rotation(self, t: float | np.ndarray) -> np.ndarray:
        """Rotation from LVLH to ECI axes: columns the LVLH x (radial), y (along-track) and z
        (normal) axes in ECI (3, 3); (k, 3, 3) for (k,) times."""
        u = self.angle(t)
        c, s = np.cos(u), np.sin(u)
        out = np.zeros(np.shape(u) + (3, 3))
        out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1], out[..., 2, 2] = c, -s, s, c, 1.0
        return out

    def to_lvlh(self, t: np.ndarray, position: np.ndarray, velocity: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray | None]:
        """Simulation-frame positions (and velocities) to LVLH components.

        Args:
            t: times, s (k,).
            position: points relative to R0(t), ECI axes, m (k, 3).
            velocity: their time derivatives in the simulation frame, m/s (k, 3), or None.

        Returns:
            LVLH positions (k, 3), m, and velocities seen from the rotating LVLH frame,
            ``R^T (v - w x p)`` (k, 3), m/s (None when no velocity was given).
        """
        R = self.lvlh_rotation(np.asarray(t, dtype=float))
        p = np.einsum("kji,kj->ki", R, position)
        if velocity is None:
            return p, None
        w = self.angular_velocity()
        return p, np.einsum("kji,kj->ki", R, velocity - np.cross(w, position))

    def from_lvlh(self, t: float, position: np.ndarray, velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """LVLH position (3,), m, and velocity seen from the LVLH frame (3,), m/s, at time t to the
        simulation frame's (ECI axes, relative to R0(t)): ``R p`` and ``R (v + w x p)``."""
        R = self.lvlh_rotation(t)
        p = R @ np.asarray(position, dtype=float)
        return p, R @ (np.asarray(velocity, dtype=float) + np.cross(self.angular_velocity(), position))


@dataclass(frozen=True)
class OrbitSettings:
    """What a scene says of the orbit (the keys of an ``[orbit]`` or ``[[environment]]`` table):
    ``altitude`` (m above the Earth's surface) or ``mean_motion`` (rad/s), exactly one, and
    ``phase`` (rad: the reference point's angle from ECI +x at t = 0).

    Raises:
        InvalidArgument: as :class:`CircularOrbit` does (neither or both keys, a non-finite or
            non-positive one, an orbit inside the Earth), naming the key, when made.
    """

    altitude: float | None = None
    mean_motion: float | None = None
    phase: float = 0.0

    def __post_init__(self) -> None:
        self.orbit()

    def orbit(self) -> CircularOrbit:
        """The :class:`CircularOrbit` (its checks name the key that is wrong)."""
        return CircularOrbit(altitude=self.altitude, mean_motion=self.mean_motion, phase=self.phase)


def clohessy_wiltshire(n: float, position: np.ndarray, velocity: np.ndarray, t: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The Clohessy-Wiltshire (Hill) closed form: relative motion about a circular orbit of mean
    motion n, linearised in the offset.

    .. math::
        \\ddot x - 2 n \\dot y - 3 n^2 x = 0, \\quad \\ddot y + 2 n \\dot x = 0, \\quad \\ddot z + n^2 z = 0

    Args:
        n: mean motion, rad/s.
        position: LVLH position at t = 0 (x radial, y along-track, z normal), m (3,).
        velocity: LVLH velocity at t = 0 (seen from the rotating frame), m/s (3,).
        t: times, s (k,).

    Returns:
        LVLH positions (k, 3), m, and velocities (k, 3), m/s.
    """
    x0, y0, z0 = np.asarray(position, dtype=float)
    u0, v0, w0 = np.asarray(velocity, dtype=float)
    nt = n * np.asarray(t, dtype=float)
    s, c = np.sin(nt), np.cos(nt)
    x = (4.0 - 3.0 * c) * x0 + s / n * u0 + 2.0 / n * (1.0 - c) * v0
    y = 6.0 * (s - nt) * x0 + y0 - 2.0 / n * (1.0 - c) * u0 + (4.0 * s - 3.0 * nt) / n * v0
    z = c * z0 + s / n * w0
    xd = 3.0 * n * s * x0 + c * u0 + 2.0 * s * v0
    yd = 6.0 * n * (c - 1.0) * x0 - 2.0 * s * u0 + (4.0 * c - 3.0) * v0
    zd = -n * s * z0 + c * w0
    return np.stack((x, y, z), axis=-1), np.stack((xd, yd, zd), axis=-1)
