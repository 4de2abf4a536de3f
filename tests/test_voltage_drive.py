"""The voltage drive (freefloat.dynamics.voltage_drive): a torque law's efforts turned into terminal
voltages by a PI current loop with the back-EMF fed forward."""

from __future__ import annotations

import numpy as np
import pytest

from freefloat import InvalidArgument
from freefloat.dynamics.motors import DCMotor
from freefloat.dynamics.plants.motor_driven import MotorDrivenPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.dynamics.voltage_drive import VoltageDrive

from .loops import Law
from .test_motor_driven import MOTOR, Rotor

PERIOD, BANDWIDTH = 1e-5, 2000.0


def drive_run(true: DCMotor, effort: float, duration: float = 0.01, viscous: float = 0.0):
    """A rotor (2e-3 kg m^2 plus the armature, ``viscous`` N m s/rad) driven to ``effort`` N m
    through ``true`` motor parameters, the drive on the nominal ones (law held and drive run
    every 10 us, RK4)."""
    plant = MotorDrivenPlant(Rotor(2e-3 + true.armature, viscous), DCMotor.stack([true]), [0])
    drive = VoltageDrive(Law(lambda *_: np.array([effort])), plant, DCMotor.stack([MOTOR]), BANDWIDTH, PERIOD)
    return run_plant(plant, np.zeros(2), np.zeros(2), duration, PERIOD, "rkmk4", drive).telemetry


def test_with_exact_motors_the_current_follows_a_first_order_lag():
    """Exact parameters: the current rises to i_d = tau / (N k_t) as 1 - exp(-omega_c t) (the
    integral's zero cancels the winding's pole), to 1 % of i_d (the drive is digital at 10 us)."""
    tel = drive_run(MOTOR, 1.0)
    wanted = 1.0 / (MOTOR.gear_ratio * MOTOR.torque_constant)
    np.testing.assert_allclose(tel.v[:, 1], wanted * (1.0 - np.exp(-BANDWIDTH * tel.t)), atol=1e-2 * wanted)


def test_the_integral_brings_the_current_to_the_request_despite_motor_errors():
    """Resistance 15 % high, back-EMF constant 15 % low, a rotor held at 2.5 rad/s by viscous
    friction: after 20 ms the current is i_d to 1e-3 (the effort is then off by k_t's error
    alone; while the rotor accelerates, the back-EMF error is a ramp that a PI loop follows with a
    constant lag)."""
    true = MOTOR.scaled(resistance=1.15, back_emf_constant=0.85)
    tel = drive_run(true, 5.0, duration=0.02, viscous=2.0)
    wanted = 5.0 / (MOTOR.gear_ratio * MOTOR.torque_constant)
    assert tel.v[-1, 0] > 2.0  # the rotor turns (rad/s): a back-EMF error is at work
    np.testing.assert_allclose(tel.v[-1, 1], wanted, rtol=1e-3)


def test_the_current_limit_caps_the_request():
    """An effort beyond N k_t i_max asks i_max; the current settles there, not above."""
    tel = drive_run(MOTOR, 100.0, duration=0.004)
    assert abs(tel.v[-1, 1] - MOTOR.current_limit) < 1e-2 * MOTOR.current_limit
    assert tel.v[:, 1].max() < 1.01 * MOTOR.current_limit


def test_bad_settings_are_refused():
    """A bandwidth or period that is not positive, or motors of another number: InvalidArgument."""
    plant = MotorDrivenPlant(Rotor(1.0, 0.0), DCMotor.stack([MOTOR]), [0])
    law = Law(lambda *_: np.zeros(1))
    with pytest.raises(InvalidArgument, match="'bandwidth' must be positive"):
        VoltageDrive(law, plant, DCMotor.stack([MOTOR]), 0.0, PERIOD)
    with pytest.raises(InvalidArgument, match="'period' must be positive"):
        VoltageDrive(law, plant, DCMotor.stack([MOTOR]), 1.0, -1.0)
    with pytest.raises(InvalidArgument, match="2 motors for a plant of 1"):
        VoltageDrive(law, plant, DCMotor.stack([MOTOR, MOTOR]), 1.0, PERIOD)
