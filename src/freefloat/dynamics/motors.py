"""DC motors driving joints (thesis proposal sec 9, items 5 and 8): the electrical and the
mechanical side of a permanent-magnet DC motor with a gear, and the data files that give them.

A motor of armature resistance ``R`` (ohm) and inductance ``L`` (H), torque constant ``k_t``
(N m/A) and back-EMF constant ``k_e`` (V s/rad), driving its joint through a gear of ratio ``N``
(motor angle per joint angle, rad/rad; per joint travel, rad/m, on a slide):

.. math::
    L \\frac{di}{dt} = V - R i - k_e N \\dot q, \\qquad \\tau = N k_t i,

``i`` its current (A), ``V`` its terminal voltage (V; the supply clips it to ``+-V_max``),
``qdot`` the joint rate, ``tau`` the effort on the joint (N m or N). Its rotor (inertia ``J_m``
about its axis) adds ``N^2 J_m`` to the joint's diagonal of the mass matrix (the armature; the
rotor's gyroscopic coupling with a moving carrier neglected, as Pinocchio's ``model.armature``)
and the friction of motor and gear (``viscous``, ``coulomb``, referred to the joint) adds to the
joint's friction (:mod:`.friction`). Power: ``V i = R i^2 + d(L i^2 / 2)/dt + k_e N qdot i``,
the last term equal to the mechanical power ``tau qdot`` when ``k_e = k_t`` (SI units): what the
energy balance of a run checks. Gear efficiency (load-dependent losses) is not modelled.

The current is a state. :class:`~freefloat.dynamics.plants.MotorDrivenPlant` integrates it as the
rate of a coordinate, the motor's charge ``q_e`` (C), whose "acceleration" is ``di/dt``, so a
motor-driven plant is the mechanical plant's configuration space times R^k and every integrator
of the registry steps it unchanged.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..errors import FreefloatError, InvalidArgument
from ..inputs import read_toml, reject_unknown
from .friction import SLIP_SPEED, JointFriction

#: The motor parameters a ``[motors.<name>]`` table gives (all required), with their unit.
MOTOR_KEYS = {"resistance": "ohm", "inductance": "H", "torque_constant": "N m/A", "back_emf_constant": "V s/rad",
              "rotor_inertia": "kg m^2", "voltage_limit": "V", "current_limit": "A"}
#: What an ``[actuators.<joint>]`` table gives: the motor's name, the gear ratio, the drive train's friction.
ACTUATOR_KEYS = ("motor", "gear_ratio", "viscous", "coulomb")
#: The parameters an ``[uncertainty]`` table may bound (relative half-widths, 0.15 for 15 %).
UNCERTAIN = ("resistance", "inductance", "torque_constant", "back_emf_constant", "rotor_inertia", "viscous", "coulomb")


@dataclass(frozen=True)
class DCMotor:
    """A DC motor with its gear, or ``k`` of them (every field then an array (k,): :meth:`stack`).

    Attributes:
        resistance: ``R``, ohm (> 0).
        inductance: ``L``, H (> 0).
        torque_constant: ``k_t``, N m/A (> 0).
        back_emf_constant: ``k_e``, V s/rad (> 0).
        gear_ratio: ``N``, rad/rad (rad/m on a slide), > 0.
        rotor_inertia: ``J_m``, kg m^2 (>= 0).
        voltage_limit: ``V_max``, V (> 0): the supply.
        current_limit: ``i_max``, A (> 0): what the drive lets the current ask for.
        viscous, coulomb: friction of motor and gear referred to the joint, N m s/rad and N m
            (N s/m and N on a slide), >= 0.

    Raises:
        InvalidArgument: for a parameter out of its range or not finite, naming it.
    """

    resistance: float | np.ndarray
    inductance: float | np.ndarray
    torque_constant: float | np.ndarray
    back_emf_constant: float | np.ndarray
    gear_ratio: float | np.ndarray
    rotor_inertia: float | np.ndarray = 0.0
    voltage_limit: float | np.ndarray = np.inf
    current_limit: float | np.ndarray = np.inf
    viscous: float | np.ndarray = 0.0
    coulomb: float | np.ndarray = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = np.asarray(getattr(self, f.name), dtype=float)
            limit = f.name in ("voltage_limit", "current_limit")
            non_negative = f.name in ("rotor_inertia", "viscous", "coulomb")
            ok = (np.isfinite(value) | limit) & ((value >= 0.0) if non_negative else (value > 0.0))
            if not np.all(ok):
                raise InvalidArgument(f"DC motor: '{f.name}' must be {'>= 0' if non_negative else '> 0'} and finite, got "
                                      f"{value.tolist()}")

    @classmethod
    def stack(cls, motors: Sequence[DCMotor]) -> DCMotor:
        """``k`` motors as one whose fields are arrays (k,), actuator order."""
        return cls(**{f.name: np.array([float(getattr(m, f.name)) for m in motors]) for f in fields(cls)})

    def __len__(self) -> int:
        return int(np.size(self.resistance))

    def __getitem__(self, index: int) -> DCMotor:
        """Motor ``index`` of a stack."""
        return DCMotor(**{f.name: float(np.atleast_1d(getattr(self, f.name))[index]) for f in fields(self)})

    def scaled(self, **factors: float) -> DCMotor:
        """The motor with the named parameters multiplied by the factors (e.g. ``resistance=1.15``)."""
        return replace(self, **{name: getattr(self, name) * factor for name, factor in factors.items()})

    @property
    def armature(self) -> float | np.ndarray:
        """``N^2 J_m``: the rotor's inertia seen at the joint, kg m^2 (kg on a slide)."""
        return self.gear_ratio**2 * self.rotor_inertia

    def friction(self, slip_speed: float = SLIP_SPEED) -> JointFriction:
        """The drive train's friction at the joints (:class:`~.friction.JointFriction`)."""
        return JointFriction(np.atleast_1d(self.viscous), np.atleast_1d(self.coulomb), slip_speed)

    def effort(self, current: np.ndarray) -> np.ndarray:
        """The joint effort ``N k_t i``, N m or N."""
        return self.gear_ratio * self.torque_constant * current

    def back_emf(self, rate: np.ndarray) -> np.ndarray:
        """``k_e N qdot``, V, for joint rates ``qdot``."""
        return self.back_emf_constant * self.gear_ratio * rate

    def applied(self, voltage: np.ndarray) -> np.ndarray:
        """The terminal voltage the supply gives for ``voltage``: clipped to ``+-V_max``."""
        return np.clip(voltage, -self.voltage_limit, self.voltage_limit)

    def current_rate(self, voltage: np.ndarray, current: np.ndarray, rate: np.ndarray) -> np.ndarray:
        """``di/dt = (V - R i - k_e N qdot) / L``, A/s, the supply's clip applied to ``voltage``."""
        return (self.applied(voltage) - self.resistance * current - self.back_emf(rate)) / self.inductance


class MotorFile(NamedTuple):
    """A motor data file read for some joints.

    Attributes:
        motors: one motor per joint asked for, in that order (stacked, :meth:`DCMotor.stack`).
        uncertainty: relative half-widths of the parameters (:data:`UNCERTAIN`), the file's
            ``[uncertainty]`` (0 for the parameters it leaves out).
        names: the motor model (the ``[motors]`` key) of each joint.
    """

    motors: DCMotor
    uncertainty: dict[str, float]
    names: tuple[str, ...]


def read_motors(path: str | Path, joints: Sequence[str]) -> MotorFile:
    """The motors of ``joints`` from a motor data file:

    .. code-block:: toml

        [motors.re40]                 # a motor model, every key of MOTOR_KEYS
        resistance = 0.317            # ohm
        ...
        [actuators.c1_joint1]         # one per driven joint
        motor = "re40"
        gear_ratio = 12.0             # rad/rad (rad/m on a slide)
        viscous = 0.0                 # drive-train friction at the joint, N m s/rad (N s/m)
        coulomb = 0.05                # N m (N)
        [uncertainty]                 # optional: relative half-widths (0.15 = 15 %)
        resistance = 0.15

    Raises:
        FreefloatError: naming the file and the key: a missing or unknown key (with the nearest
            valid one), a joint without an actuator, an unknown motor, a value of the wrong type
            or out of its range.
    """
    path = Path(path)
    spec = read_toml(path, "motor file")
    reject_unknown(f"{path}: ", spec, ("motors", "actuators", "uncertainty"))
    for key in ("motors", "actuators"):
        if not isinstance(spec.get(key), dict) or not all(isinstance(v, dict) for v in spec[key].values()):
            raise FreefloatError(f"{path}: '{key}' must be a table of tables ([{key}.<name>])")
    motors = {}
    for name, table in spec["motors"].items():
        reject_unknown(f"{path}: ", table, MOTOR_KEYS, f"motors.{name}")
        missing = [k for k in MOTOR_KEYS if k not in table]
        if missing:
            raise FreefloatError(f"{path}: '[motors.{name}]' lacks {', '.join(missing)}")
        motors[name] = {k: _number(path, f"motors.{name}.{k}", table[k]) for k in MOTOR_KEYS}
    out, names = [], []
    for joint in joints:
        if joint not in spec["actuators"]:
            close = difflib.get_close_matches(joint, list(spec["actuators"]), n=1)
            hint = f" (the file has '{close[0]}')" if close else ""
            raise FreefloatError(f"{path}: no '[actuators.{joint}]' for joint '{joint}'{hint}")
        table = spec["actuators"][joint]
        reject_unknown(f"{path}: ", table, ACTUATOR_KEYS, f"actuators.{joint}")
        for key in ("motor", "gear_ratio"):
            if key not in table:
                raise FreefloatError(f"{path}: '[actuators.{joint}]' lacks '{key}'")
        model = table["motor"]
        if model not in motors:
            close = difflib.get_close_matches(str(model), list(motors), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise FreefloatError(f"{path}: 'actuators.{joint}.motor' names '{model}', which is no [motors] entry{hint}; "
                                 f"motors: {', '.join(motors)}")
        drive = {k: _number(path, f"actuators.{joint}.{k}", table[k]) for k in ACTUATOR_KEYS[1:] if k in table}
        try:
            out.append(DCMotor(**motors[model], **drive))
        except InvalidArgument as exc:
            raise FreefloatError(f"{path}: '[actuators.{joint}]' with motor '{model}': {exc}") from None
        names.append(model)
    uncertainty = spec.get("uncertainty", {})
    if not isinstance(uncertainty, dict):
        raise FreefloatError(f"{path}: 'uncertainty' must be a table of relative half-widths")
    reject_unknown(f"{path}: ", uncertainty, UNCERTAIN, "uncertainty")
    relative = {k: _number(path, f"uncertainty.{k}", uncertainty.get(k, 0.0)) for k in UNCERTAIN}
    for key, value in relative.items():
        if not value < 1.0:
            raise FreefloatError(f"{path}: 'uncertainty.{key}' must be below 1 (a relative half-width), got {value}")
    return MotorFile(DCMotor.stack(out), relative, tuple(names))


def _number(path: Path, key: str, value: object) -> float:
    """``value`` as a float >= 0.

    Raises:
        FreefloatError: naming the file and the key for anything else.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0:
        raise FreefloatError(f"{path}: '{key}' must be a finite number >= 0, got {value!r}")
    return float(value)


def add_armature(model: pin.Model, rows: Sequence[int], motors: DCMotor) -> None:
    """Add each motor's armature ``N^2 J_m`` to ``model.armature`` at its joint's velocity index
    ``rows`` (k,), in place; ``model.rotorInertia`` and ``model.rotorGearRatio`` record ``J_m``
    and ``N`` (Pinocchio's algorithms read the armature alone)."""
    rows = np.asarray(rows, dtype=int)
    model.armature[rows] += np.atleast_1d(motors.armature)
    model.rotorInertia[rows] = np.atleast_1d(motors.rotor_inertia)
    model.rotorGearRatio[rows] = np.atleast_1d(motors.gear_ratio)
