r"""The orbit as a wrench field: the tidal (differential) gravity of a two-body field on every body
of a robot that floats in the freely falling frame of a circular reference orbit.

Simulation frame: ECI axes, origin on the reference orbit point R0(t) (:mod:`.reference`); it
accelerates with ``-mu R0 / |R0|^3`` and does not rotate, so the only fictitious force on a body
of mass m is ``m mu R0 / |R0|^3``, and the field below is all the gravity a body feels there.

Per body of the Pinocchio model (one per joint: the links a fixed joint welds are one body,
``model.inertias[j]``), with c its centre of mass in the simulation frame, rho = R0 + c its
position from the Earth's centre, m its mass and I its inertia about its CoM (ECI axes), the
field is the body's gravity to second order in its size (MacCullagh's expansion: point mass plus
quadrupole) less the reference point's:

.. math::
    U = -\frac{\mu m}{|\rho|} + \frac{\mu}{2 |\rho|^3}
        \left( \frac{3\, \rho^T I \rho}{|\rho|^2} - \operatorname{tr} I \right)

    F = -\mu m \left( \frac{\rho}{|\rho|^3} - \frac{R_0}{|R_0|^3} \right)
        + \frac{\mu}{2 |\rho|^5} \left( \left( \frac{15\, \rho^T I \rho}{|\rho|^2}
        - 3 \operatorname{tr} I \right) \rho - 6 I \rho \right), \qquad
    \tau_{CoM} = \frac{3 \mu}{|\rho|^5}\, \rho \times (I \rho)

The first force term is the exact inverse-square difference for a point mass at the CoM (no
linearisation in |c| / |R0|; evaluated without cancellation, as Encke's method does, from
``(|rho| / |R0|)^3 - 1 = expm1(1.5 log1p((2 R0.c + c.c) / |R0|^2))``); the torque is the
gravity-gradient torque; the second force term is the quadrupole's force, ``O(mu |I| / |rho|^4)``
(1e-12 N for 10 kg m^2 in low orbit, a part in 1e8 of the tidal force 10 m off): the torque's
reaction on the orbit, without which the Earth-centred energy and angular momentum drift (by a
part in 1e9 of the robot's own share of them over an orbit, measured in docs/orbit.md). Omitted:
the terms of third and higher order in the body's size over |rho| (octupole and beyond; zero for a
body symmetric about its CoM), a part in ``size / |rho|`` (1e-7 for a 1 m body) of the quadrupole.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ...robot.conventions import cross_rows, momentum_about_origin
from ...robot.robot import Robot
from .reference import CircularOrbit, OrbitSettings

__all__ = ["OrbitField", "orbit_field"]


class OrbitField:
    """Tidal gravity and gravity-gradient torque of a circular orbit on a robot's bodies: a
    wrench field (``forces(t, q, v)``, ``wrench(t, q, v)``) for the engine and the balances.

    Args:
        robot: the robot (or its Pinocchio model), its gravity zero (the field is all of it).
        orbit: the reference orbit; t is the simulation time, s, R0(t) = ``orbit.position(t)``.

    Attributes:
        joints: joints whose bodies have mass (k,), the ones the field acts on.

    Raises:
        InvalidArgument: for a model with gravity (a uniform field on top of the orbit's).
    """

    def __init__(self, robot: Robot | pin.Model, orbit: CircularOrbit):
        self.model = robot.model if isinstance(robot, Robot) else robot
        gravity = self.model.gravity.linear
        if np.any(gravity != 0.0):
            raise InvalidArgument(f"orbit: the robot's model has gravity ({gravity[0]:g}, {gravity[1]:g}, {gravity[2]:g}) "
                                  "m/s^2; in orbit the field is all the gravity: load it with gravity (0, 0, 0)")
        self.data = self.model.createData()
        self.orbit = orbit
        inertias = [self.model.inertias[j] for j in range(self.model.njoints)]
        self.joints = [j for j in range(1, self.model.njoints) if inertias[j].mass > 0.0]
        self._mass = np.array([inertias[j].mass for j in self.joints])
        self._lever = np.array([inertias[j].lever for j in self.joints]).reshape(-1, 3)  # CoM, joint frame
        self._inertia = np.array([inertias[j].inertia for j in self.joints]).reshape(-1, 3, 3)  # about CoM

    def bodies(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rotations of the bodies' joint frames (k, 3, 3), their CoMs (k, 3), m, and inertias about
        the CoMs (k, 3, 3), kg m^2, all in the simulation frame (ECI axes); runs the forward
        kinematics of ``q`` (nq,)."""
        pin.forwardKinematics(self.model, self.data, q)
        oMi = self.data.oMi
        placements = np.array([oMi[j].homogeneous for j in self.joints]).reshape(-1, 4, 4)  # one read a body
        R = placements[:, :3, :3]
        com = placements[:, :3, 3] + (R @ self._lever[:, :, None])[:, :, 0]
        return R, com, R @ self._inertia @ R.transpose(0, 2, 1)

    def body_wrenches(self, t: float, com: np.ndarray, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Force on each body (k, 3), N (the point mass's tidal difference plus the quadrupole's
        force), and gravity-gradient torque about its CoM (k, 3),
        N m, ECI axes, at time t (s) for CoMs ``com`` (k, 3), m, and inertias (k, 3, 3), kg m^2
        (simulation frame): the module's equations."""
        mu, R0 = self.orbit.mu, self.orbit.position(t)
        rho = R0 + com
        x = (2.0 * com @ R0 + np.einsum("ki,ki->k", com, com)) / (R0 @ R0)  # |rho|^2 / |R0|^2 - 1
        growth = np.expm1(1.5 * np.log1p(x))  # |rho|^3 / |R0|^3 - 1
        r = np.sqrt(np.einsum("ki,ki->k", rho, rho))
        force = -(mu * self._mass / r**3)[:, None] * (com - growth[:, None] * R0)
        i_rho = np.einsum("kij,kj->ki", inertia, rho)
        trace, rir = np.trace(inertia, axis1=1, axis2=2), np.einsum("ki,ki->k", rho, i_rho)
        force += (0.5 * mu / r**5)[:, None] * ((15.0 * rir / r**2 - 3.0 * trace)[:, None] * rho - 6.0 * i_rho)
        torque = (3.0 * mu / r**5)[:, None] * cross_rows(rho, i_rho)
        return force, torque

    def forces(self, t: float, q: np.ndarray, v: np.ndarray | None = None) -> list[pin.Force]:
        """One ``pin.Force`` per joint (model.njoints): each body's force and torque in its joint
        frame's axes, moment about the joint origin (Pinocchio's ``fext`` for ``aba``); ``v`` is
        not used (the field depends on t and q only)."""
        R, com, inertia = self.bodies(q)
        force, torque = self.body_wrenches(t, com, inertia)
        f_local = np.einsum("kji,kj->ki", R, force)
        n_local = np.einsum("kji,kj->ki", R, torque) + cross_rows(self._lever, f_local)
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        for i, j in enumerate(self.joints):
            out[j] = pin.Force(f_local[i], n_local[i])
        return out

    def wrench(self, t: float, q: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """The total the field applies, [force; torque about the simulation origin] (6,), ECI axes,
        N and N m (the momentum balance's external wrench)."""
        _, com, inertia = self.bodies(q)
        force, torque = self.body_wrenches(t, com, inertia)
        return np.concatenate((force.sum(axis=0), (cross_rows(com, force) + torque).sum(axis=0)))

    def energy(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """Total energy in the Earth-centred frame, J: kinetic energy of the ECI velocities
        ``V0(t) + (simulation-frame velocity)`` plus the bodies' potentials U (module docstring),
        conserved by the motion.
        :meth:`energy_over_reference` plus the constant ``M (|V0|^2 / 2 - mu / |R0|)``."""
        mass = pin.computeTotalMass(self.model)
        V0 = self.orbit.velocity(t)
        return self.energy_over_reference(t, q, v) + mass * (0.5 * V0 @ V0 - self.orbit.mu / self.orbit.radius)

    def energy_over_reference(self, t: float, q: np.ndarray, v: np.ndarray) -> float:
        """:meth:`energy` less that of the robot's mass M moving with the reference point,
        ``M (|V0|^2 / 2 - mu / |R0|)``, J, computed without the cancellation of the two large
        terms: ``T + M V0 . c' - sum mu m (1 / |rho| - 1 / |R0|) + (gradient terms)``, T the
        simulation-frame kinetic energy and c' the system CoM's velocity there."""
        model, data = self.model, self.data
        kinetic = pin.computeKineticEnergy(model, data, q, v)
        pin.centerOfMass(model, data, q, v)
        kinetic += pin.computeTotalMass(model) * self.orbit.velocity(t) @ data.vcom[0]
        _, com, inertia = self.bodies(q)
        mu, R0 = self.orbit.mu, self.orbit.position(t)
        rho = R0 + com
        x = (2.0 * com @ R0 + np.einsum("ki,ki->k", com, com)) / (R0 @ R0)
        point = -mu * self._mass / self.orbit.radius * np.expm1(-0.5 * np.log1p(x))  # -mu m (1/|rho| - 1/|R0|)
        r2 = np.einsum("ki,ki->k", rho, rho)
        gradient = 3.0 * np.einsum("ki,kij,kj->k", rho, inertia, rho) / r2 - np.trace(inertia, axis1=1, axis2=2)
        return float(kinetic + np.sum(point + 0.5 * mu / r2**1.5 * gradient))

    def angular_momentum(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Angular momentum about the Earth's centre, ECI axes, kg m^2/s (3,):
        :meth:`momentum_over_reference` plus the constant ``M R0 x V0``; conserved by the motion."""
        R0, V0 = self.orbit.position(t), self.orbit.velocity(t)
        return self.momentum_over_reference(t, q, v) + pin.computeTotalMass(self.model) * np.cross(R0, V0)

    def momentum_over_reference(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """:meth:`angular_momentum` less the reference's ``M R0 x V0``, kg m^2/s (3,):
        ``L_o + R0 x P + M c x V0`` with ``[P; L_o]`` the simulation-frame momentum about its
        origin and c the system's CoM (no large terms to cancel)."""
        momentum = momentum_about_origin(self.model, self.data, q, v)
        mass, com = pin.computeTotalMass(self.model), self.data.com[0]
        R0, V0 = self.orbit.position(t), self.orbit.velocity(t)
        return momentum[3:] + np.cross(R0, momentum[:3]) + mass * np.cross(com, V0)


def orbit_field(robot: Robot, settings: OrbitSettings) -> OrbitField:
    """The field of a scene's orbit on ``robot``: ``build(robot, settings)`` of an environment
    registry entry whose settings are :class:`~.reference.OrbitSettings`."""
    return OrbitField(robot, settings.orbit())
