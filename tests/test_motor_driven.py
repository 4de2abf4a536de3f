"""Motor-driven plants (freefloat.dynamics.plants.motor_driven): the currents as states of the one
loop, against a closed form, and the electrical and mechanical energy balance of a run, on a
closed chain (the 5R) and on a robot's joint."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import simpson
from scipy.linalg import expm

from freefloat import InvalidArgument
from freefloat.dynamics.motors import DCMotor, add_armature
from freefloat.dynamics.plants import vector_space
from freefloat.dynamics.plants.motor_driven import MotorDrivenPlant, with_coordinates
from freefloat.dynamics.simulation import run_plant
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.drives import five_bar_motors, motor_driven, motorised
from freefloat.parallel.five_bar import FiveBarParameters, elbow_guess

from .conftest import REPO
from .loops import Law

MOTOR = DCMotor(resistance=0.317, inductance=0.0823e-3, torque_constant=0.0302, back_emf_constant=0.0302,
                gear_ratio=12.0, rotor_inertia=1.42e-5, voltage_limit=24.0, current_limit=30.0)


class Rotor:
    """A joint of inertia ``J`` and viscous friction ``b`` on R: the mechanical plant."""

    name, max_drift, n_efforts = "rotor", np.inf, 1

    def __init__(self, J: float, b: float):
        self.J, self.b, self.space = J, b, vector_space(1)

    def acceleration(self, q, v, u):
        return (u - self.b * v) / self.J

    def drift(self, q):
        return 0.0, 0.0


def test_a_driven_rotor_follows_the_linear_closed_form():
    """A motor at 6 V on a rotor (armature included): (omega, i) from RK4 at 10 us over 20 ms equal
    exp(A t) of the linear system L di/dt = V - R i - k_e N w, J w' = N k_t i - b w, to 1e-9."""
    J, b = 2e-3 + MOTOR.armature, 1e-3
    plant = MotorDrivenPlant(Rotor(J, b), DCMotor.stack([MOTOR]), [0])
    tel = run_plant(plant, np.zeros(2), np.zeros(2), 0.02, 1e-5, "rkmk4", Law(lambda *_: np.array([6.0]))).telemetry
    R, L, N, kt, ke = MOTOR.resistance, MOTOR.inductance, MOTOR.gear_ratio, MOTOR.torque_constant, MOTOR.back_emf_constant
    A = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, -b / J, 0.0, N * kt / J], [0.0, 0.0, 0.0, 1.0],
                  [0.0, -ke * N / L, 0.0, -R / L]])   # state (angle, rate, charge, current)
    extended = np.zeros((5, 5))
    extended[:4, :4], extended[3, 4] = A, 6.0 / L
    for t, q, v in zip(tel.t[::200], tel.q[::200], tel.v[::200]):
        x = (expm(extended * t) @ np.r_[np.zeros(4), 1.0])[:4]
        np.testing.assert_allclose([q[0], v[0], q[1], v[1]], x, atol=1e-9 * max(1.0, np.abs(x).max()))


def balance(t, voltage, charge, current, motors, mechanical_energy, friction_power):
    """Electrical energy drawn (exact with V held: V dq_e) minus Joule heat, magnetic energy gained,
    mechanical energy gained and friction's work: what the run leaves unexplained, and the drawn energy."""
    drawn = (voltage * (charge[-1] - charge[0])).sum()
    joule = simpson((motors.resistance * current**2).sum(axis=1), x=t)
    magnetic = 0.5 * (motors.inductance * (current[-1] ** 2 - current[0] ** 2)).sum()
    lost = simpson(friction_power, x=t)
    return drawn - joule - magnetic - (mechanical_energy[-1] - mechanical_energy[0]) - lost, abs(drawn)


def test_the_5r_driven_by_its_motors_balances_electrical_and_mechanical_energy():
    """The 5R with its motor file's rotors and drive trains, 3 and -2 V held for 0.04 s (RK4 at
    20 us): the electrical energy drawn equals Joule heat + magnetic energy + the mechanism's
    energy (Pinocchio's, armature included) + friction's work, to 5e-8 of the energy drawn (1.3e-8
    measured; the magnetic energy alone is 1e-3 of it)."""
    loaded = load_closed_chain(REPO / "urdf" / "five_bar.closure.toml")
    motors = five_bar_motors().motors
    mech = motorised(loaded.mechanism, motors)
    plant = motor_driven(mech, motors, baumgarte=0.0)
    point = np.array([0.07, 0.17])
    q0 = mech.assemble(point, elbow_guess(FiveBarParameters(), point))
    voltage = np.array([3.0, -2.0])
    tel = run_plant(plant, np.r_[q0, 0.0, 0.0], np.zeros(8), 0.04, 2e-5, "rkmk4", Law(lambda *_: voltage)).telemetry
    model = pin.Model(loaded.model)
    add_armature(model, [model.idx_vs[j] for j in loaded.actuated], motors)
    data = model.createData()
    q_m, v_m, charge, current = plant.split(tel.q, tel.v)
    energy = np.array([pin.computeKineticEnergy(model, data, loaded.pinocchio_q(q), loaded.pinocchio_q(v))
                       + pin.computePotentialEnergy(model, data, loaded.pinocchio_q(q)) for q, v in zip(q_m, v_m)])
    left, drawn = balance(tel.t, voltage, charge, current, motors, energy, (mech.joint_friction(v_m) * v_m).sum(axis=1))
    assert drawn > 0.1 and abs(left) < 5e-8 * drawn


def test_a_robot_joint_driven_by_a_motor_balances_its_energy():
    """A motor on the first joint of the two-arm planar robot (free-floating, rotor as Pinocchio's
    armature, drive-train friction), 5 V for 0.05 s: the same balance on a Lie group (RK4 at
    10 us), to 1e-8 of the energy drawn (2.8e-10 measured); the base rows' momentum (Pinocchio's, which leaves out
    the rotor's spin as the armature model does) is kept."""
    import warnings

    from freefloat.dynamics.friction import JointFriction
    from freefloat.dynamics.models import ExactModel
    from freefloat.dynamics.models.friction import WithFriction
    from freefloat.dynamics.plants.tree import TreePlant
    from freefloat.robot.conventions import momentum_about_origin
    from freefloat.robot.loading import load_robot

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_robot(REPO / "urdf" / "two_arm_planar.urdf", visuals=False)
    joint = robot.n_base
    motors = DCMotor.stack([MOTOR])
    add_armature(robot.model, [joint], motors)
    friction = JointFriction(np.where(np.arange(robot.model.nv) == joint, 0.01, 0.0),
                             np.where(np.arange(robot.model.nv) == joint, 0.05, 0.0))
    plant = MotorDrivenPlant(TreePlant(robot, WithFriction(ExactModel(robot), friction), [joint]), motors, [joint])
    assert plant.space.nq == robot.model.nq + 1 and plant.space.nv == robot.model.nv + 1
    q0, v0 = np.r_[robot.neutral(), 0.0], np.zeros(plant.space.nv)
    tel = run_plant(plant, q0, v0, 0.05, 1e-5, "rkmk4", Law(lambda *_: np.array([5.0]))).telemetry
    q_m, v_m, charge, current = plant.split(tel.q, tel.v)
    data = robot.model.createData()
    energy = np.array([pin.computeKineticEnergy(robot.model, data, q, v) for q, v in zip(q_m, v_m)])
    left, drawn = balance(tel.t, np.array([5.0]), charge, current, motors, energy, friction.power(v_m))
    assert drawn > 0.1 and abs(left) < 1e-8 * drawn
    momenta = np.array([momentum_about_origin(robot.model, data, q, v) for q, v in zip(q_m[::500], v_m[::500])])
    assert np.abs(momenta - momenta[0]).max() < 1e-9 * max(1.0, np.abs(momenta).max())


def test_the_space_is_the_plant_s_times_r_k():
    """A vector space grows into a longer one (shared); a Lie group gets k prismatic joints last."""
    assert with_coordinates(vector_space(6), 2) is vector_space(8)
    model = pin.buildSampleModelHumanoidRandom()
    grown = with_coordinates(model, 3)
    assert (grown.nq, grown.nv) == (model.nq + 3, model.nv + 3) and model.njoints + 3 == grown.njoints
    q = pin.randomConfiguration(grown, -np.ones(grown.nq), np.ones(grown.nq))
    dq = np.random.default_rng(0).normal(size=grown.nv)
    moved = pin.integrate(grown, q, dq)
    np.testing.assert_allclose(moved[: model.nq], pin.integrate(model, q[: model.nq], dq[: model.nv]), atol=1e-14)
    np.testing.assert_allclose(moved[model.nq:], q[model.nq:] + dq[model.nv:], atol=1e-14)


def test_motors_rates_and_efforts_must_agree():
    """Two motors on a one-effort plant, or a rate index out of range: InvalidArgument."""
    with pytest.raises(InvalidArgument, match="must agree"):
        MotorDrivenPlant(Rotor(1.0, 0.0), DCMotor.stack([MOTOR, MOTOR]), [0, 0])
    with pytest.raises(InvalidArgument, match="must agree"):
        MotorDrivenPlant(Rotor(1.0, 0.0), DCMotor.stack([MOTOR]), [3])
