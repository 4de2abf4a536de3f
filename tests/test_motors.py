"""DC motors (freefloat.dynamics.motors): the model's relations and its data files."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from freefloat import FreefloatError, InvalidArgument
from freefloat.dynamics.motors import DCMotor, add_armature, read_motors
from freefloat.parallel.drives import (
    FIVE_BAR_JOINTS,
    FIVE_BAR_MOTORS,
    RSU_PPAP_JOINTS,
    RSU_PPAP_MOTORS,
)

MOTOR = DCMotor(resistance=0.317, inductance=0.0823e-3, torque_constant=0.0302, back_emf_constant=0.0302,
                gear_ratio=12.0, rotor_inertia=1.42e-5, voltage_limit=24.0, current_limit=30.0)


def test_electrical_power_splits_into_joule_magnetic_and_mechanical():
    """V i = R i^2 + L i di/dt + k_e N qdot i, and k_e N qdot i = tau qdot when k_e = k_t."""
    rng = np.random.default_rng(0)
    for _ in range(10):
        V, i, rate = rng.uniform(-20, 20), rng.uniform(-10, 10), rng.uniform(-30, 30)
        di = MOTOR.current_rate(V, i, rate)
        np.testing.assert_allclose(V * i, MOTOR.resistance * i**2 + MOTOR.inductance * i * di + MOTOR.back_emf(rate) * i,
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(MOTOR.back_emf(rate) * i, MOTOR.effort(i) * rate, rtol=1e-12)


def test_the_supply_clips_the_voltage():
    """Beyond +-V_max the current rate is that of V_max."""
    assert MOTOR.current_rate(100.0, 1.0, 2.0) == MOTOR.current_rate(24.0, 1.0, 2.0)
    assert MOTOR.current_rate(-100.0, 1.0, 2.0) == MOTOR.current_rate(-24.0, 1.0, 2.0)


def test_stack_and_index_round_trip():
    """k motors stack into arrays (k,) and index back to the same motors; armature is N^2 J_m."""
    other = MOTOR.scaled(resistance=1.15, gear_ratio=2.0)
    stacked = DCMotor.stack([MOTOR, other])
    assert len(stacked) == 2 and stacked[1] == other and stacked[0] == MOTOR
    np.testing.assert_allclose(stacked.armature, [144 * 1.42e-5, 576 * 1.42e-5], rtol=1e-15)


@pytest.mark.parametrize(("field", "value"), [("resistance", 0.0), ("inductance", -1.0), ("rotor_inertia", -1e-6),
                                              ("gear_ratio", np.nan), ("coulomb", -0.1)])
def test_bad_parameters_are_refused_naming_them(field, value):
    """A parameter out of its range (R, L, k, N > 0; J_m, friction >= 0) or not finite: InvalidArgument."""
    from dataclasses import replace

    with pytest.raises(InvalidArgument, match=f"'{field}'"):
        replace(MOTOR, **{field: value})


@pytest.mark.parametrize(("path", "joints"), [(FIVE_BAR_MOTORS, FIVE_BAR_JOINTS), (RSU_PPAP_MOTORS, RSU_PPAP_JOINTS)])
def test_the_mechanisms_motor_files_read(path, joints):
    """Both mechanisms' motor files give one motor per actuated joint, k_e = k_t (SI), 15 % bounds."""
    read = read_motors(path, joints)
    assert len(read.motors) == len(joints)
    np.testing.assert_array_equal(read.motors.torque_constant, read.motors.back_emf_constant)
    assert read.uncertainty["torque_constant"] == 0.15


@pytest.mark.parametrize(("edit", "message"), [
    (lambda s: s.replace("resistance = 0.317", "resistence = 0.317"), "unknown \\[motors.re40\\] key 'resistence' \\(did you mean 'resistance'\\?\\)"),
    (lambda s: s.replace('motor = "re40"', 'motor = "re04"', 1), "names 're04', which is no \\[motors\\] entry \\(did you mean 're40'\\?\\)"),
    (lambda s: s.replace("[actuators.c1_joint1]", "[actuators.c1_joint]"), "no '\\[actuators.c1_joint1\\]' for joint 'c1_joint1' \\(the file has 'c1_joint'\\)"),
    (lambda s: s.replace("gear_ratio = 12.0", 'gear_ratio = "12"', 1), "'actuators.c1_joint1.gear_ratio' must be a finite number >= 0"),
    (lambda s: s.replace("gear_ratio = 12.0", "gear_ratio = 0.0", 1), "'\\[actuators.c1_joint1\\]' with motor 're40': DC motor: 'gear_ratio' must be > 0"),
    (lambda s: s.replace("torque_constant = 0.15", "torque_constant = 1.5"), "'uncertainty.torque_constant' must be below 1"),
    (lambda s: s.replace("voltage_limit = 24.0", ""), "'\\[motors.re40\\]' lacks voltage_limit"),
])
def test_bad_motor_files_name_the_key(tmp_path, edit, message):
    """A misspelt key, an unknown motor, a missing actuator, a wrong type or range, a missing
    parameter: FreefloatError naming the file and the key."""
    (tmp_path / "m.toml").write_text(edit(FIVE_BAR_MOTORS.read_text()))
    with pytest.raises(FreefloatError, match=message):
        read_motors(tmp_path / "m.toml", FIVE_BAR_JOINTS)


def test_add_armature_is_what_pinocchio_integrates():
    """add_armature puts N^2 J_m on the joints' diagonal of CRBA and records J_m and N."""
    model = pin.Model()
    parent = 0
    for i in range(2):
        parent = model.addJoint(parent, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.3, 0, 0])), f"j{i}")
        model.appendBodyToJoint(parent, pin.Inertia(1.0, np.array([0.15, 0, 0]), np.eye(3) * 0.01), pin.SE3.Identity())
    data, q = model.createData(), np.array([0.3, -0.5])
    before = pin.crba(model, data, q).copy()
    add_armature(model, [1], DCMotor.stack([MOTOR]))
    after = pin.crba(model, data, q)
    np.testing.assert_allclose(after - before, np.diag([0.0, 144 * 1.42e-5]), atol=1e-15)
    assert model.rotorGearRatio[1] == 12.0 and model.rotorInertia[1] == 1.42e-5
