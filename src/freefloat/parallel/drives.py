"""A mechanism driven by DC motors (:mod:`freefloat.dynamics.motors`): the rotors' inertia and the
drive trains' friction put on the actuated joints of Orsino's chains, and the motor-driven plant
of the one loop (thesis proposal sec 9, items 5, 8, 10 and 11).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..dynamics.friction import SLIP_SPEED, JointFriction
from ..dynamics.motors import DCMotor, MotorFile, read_motors
from ..dynamics.plants import CoupledChainPlant
from ..dynamics.plants.motor_driven import MotorDrivenPlant
from ..errors import FreefloatError
from ..paths import URDF_DIR
from .mechanism import ParallelMechanism

#: The 5R's motors (maxon RE 40 class, 12:1; assumed, see the file).
FIVE_BAR_MOTORS = URDF_DIR / "five_bar.motors.toml"
#: The 2RSU+PPaP's motors (assumed, see the file).
RSU_PPAP_MOTORS = URDF_DIR / "rsu_ppap.motors.toml"
#: The 5R's actuated joints, in its actuator order (``five_bar.closure.toml``).
FIVE_BAR_JOINTS = ("c1_joint1", "c2_joint1")
#: The 2RSU+PPaP's actuated joints, in its actuator order (``rsu_ppap.closure.toml``).
RSU_PPAP_JOINTS = ("rsu1_crank", "rsu2_crank", "ppap_rail")


def motorised(mech: ParallelMechanism, motors: DCMotor, slip_speed: float = SLIP_SPEED) -> ParallelMechanism:
    """``mech`` with a motor on each actuated joint (actuator order): its armature ``N^2 J_m`` added
    to the joint's and its drive train's friction (Coulomb regularised at ``slip_speed``) to the
    joint's friction.

    Raises:
        FreefloatError: for another number of motors than actuators, or a chain friction of
            another slip speed.
    """
    if len(motors) != len(mech.actuated):
        raise FreefloatError(f"motorised: {len(motors)} motors for {len(mech.actuated)} actuators")
    armature = np.atleast_1d(motors.armature)
    drive = motors.friction(slip_speed)
    chains, start = list(mech.chains), mech.p
    for c, chain in enumerate(mech.chains):
        rows = [(a, int(index) - start) for a, index in enumerate(mech.actuated) if start <= index < start + chain.dof]
        if rows:
            added = np.zeros(chain.dof)
            friction = chain.friction or JointFriction.none(chain.dof)
            viscous, coulomb = friction.viscous.copy(), friction.coulomb.copy()
            for a, joint in rows:
                added[joint] = armature[a]
                viscous[joint] += drive.viscous[a]
                coulomb[joint] += drive.coulomb[a]
            if chain.friction is not None and chain.friction.slip_speed != slip_speed and any(chain.friction.coulomb):
                raise FreefloatError(f"motorised: chain {c + 1}'s joint friction has slip speed "
                                     f"{chain.friction.slip_speed}, the drives' {slip_speed}")
            base = np.zeros(chain.dof) if chain.armature is None else chain.armature
            chains[c] = replace(chain, armature=base + added, friction=JointFriction(viscous, coulomb, slip_speed))
        start += chain.dof
    return replace(mech, chains=tuple(chains))


def motor_driven(mech: ParallelMechanism, motors: DCMotor, baumgarte: float = 100.0) -> MotorDrivenPlant:
    """The motor-driven plant of ``mech`` (already :func:`motorised` with these motors' rotors and
    drive trains): eq 129 with Baumgarte ``baumgarte`` (1/s) for the mechanism, the motors'
    currents as states, their terminal voltages as the efforts."""
    return MotorDrivenPlant(CoupledChainPlant(mech, baumgarte), motors, mech.actuated)


def five_bar_motors(path: Path = FIVE_BAR_MOTORS) -> MotorFile:
    """The 5R's motors (both base joints) from its motor file."""
    return read_motors(path, FIVE_BAR_JOINTS)


def rsu_ppap_motors(path: Path = RSU_PPAP_MOTORS) -> MotorFile:
    """The 2RSU+PPaP's motors (the cranks and the rail) from its motor file."""
    return read_motors(path, RSU_PPAP_JOINTS)


def off_nominal(motors: DCMotor, error: float) -> DCMotor:
    """A warm motor, ``error`` (e.g. 0.15) off the data file's in the direction heat moves it: the
    winding's resistance and the friction up, the magnets' constants down; the rotor heavier and
    the inductance lower (to take both signs), the gear ratio exact."""
    up, down = 1.0 + error, 1.0 - error
    return motors.scaled(resistance=up, inductance=down, torque_constant=down, back_emf_constant=down,
                         rotor_inertia=up, viscous=up, coulomb=up)
