"""A sensed controller: with ideal sensors the run is today's bit for bit (compiled and Python
loops); otherwise the law reads what the log recorded, runs in Python, and the detumbling law of
sec 5.3 still settles under 1 % noise, a 2-period delay and 100 Hz sampling."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

from freefloat import load_robot
from freefloat.dynamics import gjm
from freefloat.dynamics.identification.measurements import channel_scale
from freefloat.dynamics.integrators import make_integrator
from freefloat.dynamics.metrics import settling_time
from freefloat.dynamics.models import make_model
from freefloat.dynamics.sensors import Channel, MomentumKalman, Sensed, Sensors, SensorSettings
from freefloat.dynamics.simulation import run
from freefloat.dynamics.wrenches import ExternalWrench
from freefloat.space.control.detumbling_control import DetumblingController
from freefloat.space.detumbling import joint_indices, task_rows

T = 1e-3
#: Dissertation sec 5.3, scenario 1 (the built-in scene detumble_impulse_arm1_joint4): 500 N m about
#: z on arm 1's last link from 5 to 15 ms, then arm 1's end-effector rotation stopped by joint 4.
CAPTURE = (ExternalWrench("arm1_link4", (0.0, 0.0, 0.0), (0.0, 0.0, 500.0), 0.005, 0.015, 0.005),)


@pytest.fixture(scope="module")
def robot():
    """The two-arm planar robot on a planar base."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_robot("two_arm_planar", base="planar", visuals=False)


def detumbling(robot, duration: float, settings: SensorSettings | None = None, backend: str = "auto"):
    """Scenario 1 of sec 5.3 from rest, the law sensed through ``settings`` (None: not wrapped):
    the run's result and the controller the loop ran."""
    law = DetumblingController(robot, task_rows(robot, [("arm1_ee", "wz")]), joint_indices(robot, ["arm1_joint4"]),
                               0.015, T, "single", 10.0, 100.0, "exact")
    controller = law if settings is None else Sensed(law, Sensors(robot, settings, T))
    result = run(robot, robot.neutral(), np.zeros(robot.model.nv), duration, T,
                 make_integrator("rkmk4", robot.model, 10), make_model("exact", robot), controller, CAPTURE,
                 backend=backend)
    return result, controller


@pytest.mark.parametrize("backend", ["auto", "python"])
def test_ideal_sensors_leave_the_run_unchanged_bit_for_bit(robot, backend):
    """Every channel ideal: the telemetry equals the unwrapped law's bit for bit, on the compiled
    law (the wrapper hands it the controller's own) and in the Python loop (the law is handed the
    true state, every period recorded)."""
    plain, _ = detumbling(robot, 0.1, None, backend)
    sensed, controller = detumbling(robot, 0.1, SensorSettings(), backend)
    assert sensed.backend == plain.backend
    for name in ("q", "v", "tau", "momentum"):
        assert np.array_equal(getattr(sensed.telemetry, name), getattr(plain.telemetry, name)), name
    recorded = controller.log.record()
    assert len(recorded.t) == (100 if backend == "python" else 0)
    if len(recorded.t):
        assert np.array_equal(recorded.q, plain.telemetry.q[:-1]) and np.array_equal(recorded.v, plain.telemetry.v[:-1])


def test_imperfect_sensors_have_no_compiled_law_and_the_law_reads_the_log(robot):
    """Noisy, delayed joint rates: no compiled law; the states the law was handed are the rows
    the log recorded, and they differ from the truth."""
    seen = []

    class Recording:
        def torque(self, t, q, v):
            seen.append((q.copy(), v.copy()))
            return np.zeros(robot.n_joints)

        def reference(self, t):
            return None

    sensed = Sensed(Recording(), Sensors(robot, SensorSettings(joint_rate=Channel(noise=0.01, delay=2)), T))
    assert sensed.compiled_law() is None
    result = run(robot, robot.neutral(), np.ones(robot.model.nv), 0.02, T, make_integrator("rkmk4", robot.model),
                 make_model("exact", robot), sensed)
    recorded = sensed.log.record()
    assert np.array_equal(recorded.q, [q for q, _ in seen]) and np.array_equal(recorded.v, [v for _, v in seen])
    assert not np.array_equal(recorded.v, result.telemetry.v[:-1])


def one_percent(robot, ideal, delay: int, every: int, estimator: MomentumKalman | None) -> SensorSettings:
    """1 % noise on every channel, as freefloat's identification defines it: 1 % of each
    component's RMS over the ideal run for rates, of its displacement's spread for poses and angles
    (:func:`~freefloat.dynamics.identification.measurements.channel_scale`)."""
    tel, nb = ideal.telemetry, robot.n_base
    spread = channel_scale(np.array([pin.difference(robot.model, tel.q[0], q) for q in tel.q]), positions=True)
    size = channel_scale(tel.v)

    def channel(scale: np.ndarray) -> Channel:
        return Channel(noise=tuple(0.01 * scale), delay=delay, every=every)

    return SensorSettings(channel(spread[:nb]), channel(size[:nb]), channel(spread[nb:]), channel(size[nb:]), estimator,
                          seed=1)


def rows_speed(robot, telemetry) -> np.ndarray:
    """The detumbled row's speed (arm 1's end-effector wz), rad/s, at every telemetry row."""
    row = task_rows(robot, [("arm1_ee", "wz")])
    return np.array([np.abs(gjm.compute(robot, q, v).end_effector_velocity()[row]).max()
                     for q, v in zip(telemetry.q, telemetry.v)])


def test_detumbling_settles_under_noise_delay_and_sampling(robot):
    """1 % noise, 2-period delay, 100 Hz sampling and the momentum estimator (restarted at the end
    of the capture): arm 1's end-effector spin falls below 1 % of its peak within 0.3 s (0.1 s
    ideal) and stays there, its RMS over the last 0.1 s is above the ideal run's (1e-10 rad/s) and
    below 0.1 rad/s; the estimate of the conserved momenta ends within 4 of its standard deviations
    of Pinocchio's centroidal momentum, which are at most a fifth of the raw momentum map's RMS
    error (about 1/sqrt(98) of it: 98 readings since the restart at 0.022 s)."""
    ideal, _ = detumbling(robot, 1.0)
    settings = one_percent(robot, ideal, 2, 10, MomentumKalman(restart=(0.015,)))
    sensed, controller = detumbling(robot, 1.0, settings)
    assert sensed.status == "completed"
    speeds = {name: rows_speed(robot, result.telemetry) for name, result in (("ideal", ideal), ("sensed", sensed))}
    t = sensed.telemetry.t
    late = t > t[-1] - 0.1
    residual = {name: float(np.sqrt(np.mean(s[late] ** 2))) for name, s in speeds.items()}
    assert residual["ideal"] < 1e-9 < residual["sensed"] < 0.1
    settled = settling_time(t, speeds["sensed"], 0.01 * speeds["sensed"].max())
    assert settled is not None and settled < 0.3
    record = controller.log.record()
    truth = sensed.telemetry.momentum[:-1]
    rows = [0, 1, 5]  # Px, Py, Lz: what a planar base conserves
    error = np.abs(record.estimate[-1] - truth[-1])[rows]
    assert np.all(error < 4 * record.spread[-1][rows])
    after = record.t > 0.1
    raw = np.sqrt(np.mean((record.momentum[after] - truth[after])[:, rows] ** 2, axis=0))
    assert np.all(record.spread[-1][rows] < raw / 5)


def test_the_two_hand_loop_law_detumbles_through_sensors():
    """The two-hand law (loop_detumbling: its momentum from ``(M v)_b`` and the GJM) sensed with
    noise on every channel and the estimator: the held box's spin falls 100-fold in 0.3 s, and the
    estimated momentum ends within 4 of its standard deviations of Pinocchio's."""
    from freefloat.dynamics.closures import ClosedModel
    from freefloat.space.capture import TARGET_FRAME
    from freefloat.space.control.loop_detumbling import LoopDetumblingController

    from .conftest import box_held_in_both_hands

    merged, closure, q, v = box_held_in_both_hands(5)  # a 50 kg box, inertia (2, 2.5, 3) kg m^2
    law = LoopDetumblingController(merged, closure, TARGET_FRAME, 50.0, np.array([2.0, 2.5, 3.0]),
                                   task_rows(merged, [("left_tool0", "angular")]), joint_indices(merged, None), T,
                                   baumgarte=10.0)
    noisy = Channel(noise=1e-4)
    sensors = Sensors(merged, SensorSettings(noisy, noisy, noisy, Channel(noise=1e-3), MomentumKalman(), seed=2), T)
    controller = Sensed(law, sensors)
    result = run(merged, q, v, 0.3, T, make_integrator("rkmk4", merged.model), ClosedModel(merged, [closure], 10.0),
                 controller)
    hand, data = merged.end_effector_frame_ids[0], merged.model.createData()

    def spin(k: int) -> float:
        pin.forwardKinematics(merged.model, data, result.telemetry.q[k], result.telemetry.v[k])
        return float(np.linalg.norm(pin.getFrameVelocity(merged.model, data, hand, pin.LOCAL_WORLD_ALIGNED).angular))

    assert result.status == "completed" and spin(-1) < spin(0) / 100
    record = controller.log.record()
    assert np.all(np.abs(record.estimate[-1] - result.telemetry.momentum[-2]) < 4 * record.spread[-1])
