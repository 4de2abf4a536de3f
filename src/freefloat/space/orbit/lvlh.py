"""A run reported in the LVLH (Hill) frame: where the base is and how it is turned, over time."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from .reference import CircularOrbit

__all__ = ["LvlhTrack", "base_in_lvlh", "free_flyer_state", "in_lvlh", "root_in_lvlh"]


class LvlhTrack(NamedTuple):
    """A body's motion in the LVLH frame (x radial, y along-track, z orbit normal).

    Attributes:
        t: times, s (k,).
        position: its point in LVLH, m (k, 3).
        velocity: that point's velocity seen from the LVLH frame, LVLH axes, m/s (k, 3), or None.
        rotation: its attitude, body axes to LVLH axes (k, 3, 3).
    """

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray | None
    rotation: np.ndarray

    def quaternion(self) -> np.ndarray:
        """The attitude as unit quaternions [x, y, z, w] (Pinocchio's order), body to LVLH (k, 4)."""
        return np.array([pin.Quaternion(R).coeffs() for R in self.rotation]).reshape(-1, 4)

    def pitch(self) -> np.ndarray:
        """In-plane angle of the body's x axis about the orbit normal (LVLH z), from the radial
        direction (LVLH x) towards the along-track one, rad (k,): the pitch of a body whose x
        axis points radially at equilibrium."""
        return np.arctan2(self.rotation[:, 1, 0], self.rotation[:, 0, 0])


def in_lvlh(orbit: CircularOrbit, t: np.ndarray, position: np.ndarray, quaternion: np.ndarray,
            velocity: np.ndarray | None = None) -> LvlhTrack:
    """A body's track in the simulation frame (ECI axes, origin on the reference orbit point), as
    an :class:`LvlhTrack`.

    Args:
        orbit: the reference orbit.
        t: times, s (k,).
        position: the body's point, simulation frame, m (k, 3).
        quaternion: its attitude [x, y, z, w], body to ECI axes (k, 4).
        velocity: the point's velocity, simulation frame (ECI axes), m/s (k, 3), or None.
    """
    t = np.asarray(t, dtype=float)
    p, v = orbit.to_lvlh(t, np.asarray(position, dtype=float).reshape(-1, 3),
                         None if velocity is None else np.asarray(velocity, dtype=float).reshape(-1, 3))
    attitude = np.array([pin.Quaternion(np.asarray(x, dtype=float)).normalized().matrix()
                         for x in np.asarray(quaternion).reshape(-1, 4)]).reshape(-1, 3, 3)
    return LvlhTrack(t, p, v, orbit.lvlh_rotation(t).transpose(0, 2, 1) @ attitude)


def base_in_lvlh(orbit: CircularOrbit, telemetry) -> LvlhTrack:
    """The base CoM frame of a run's :class:`~freefloat.dynamics.telemetry.Telemetry` (``t``,
    ``base_position``, ``base_quaternion``, ``base_twist``) in the LVLH frame."""
    return in_lvlh(orbit, telemetry.t, telemetry.base_position, telemetry.base_quaternion,
                   np.asarray(telemetry.base_twist)[:, :3])


def root_in_lvlh(orbit: CircularOrbit, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> LvlhTrack:
    """The free-flyer root joint's frame in the LVLH frame, from states q (k, nq) and v (k, nv)
    (Pinocchio's local velocity, root joint first)."""
    q, v = np.atleast_2d(q), np.atleast_2d(v)
    velocity = np.array([pin.Quaternion(x[3:7]).normalized().matrix() @ w[:3] for x, w in zip(q, v)]).reshape(-1, 3)
    return in_lvlh(orbit, t, q[:, :3], q[:, 3:7], velocity)


def free_flyer_state(orbit: CircularOrbit, t: float, position: np.ndarray, velocity: np.ndarray,
                     rotation: np.ndarray | None = None, angular_velocity: np.ndarray | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """A free-flyer joint's q (7,) and Pinocchio local v (6,) in the simulation frame at time t
    from its state in LVLH: position (3,), m, velocity seen from LVLH (3,), m/s, attitude body to
    LVLH (3, 3) (identity by default) and angular velocity relative to LVLH, LVLH axes (3,), rad/s
    (zero by default: turning with the frame at n about the normal)."""
    frame = orbit.lvlh_rotation(t)
    point, rate = orbit.from_lvlh(t, position, velocity)
    attitude = frame @ (np.eye(3) if rotation is None else np.asarray(rotation, dtype=float))
    spin = orbit.angular_velocity() + frame @ (np.zeros(3) if angular_velocity is None else angular_velocity)
    return (np.concatenate((point, pin.Quaternion(attitude).normalized().coeffs())),
            np.concatenate((attitude.T @ rate, attitude.T @ spin)))
