"""The detumbling law of dissertation sec 5.3 (scenario 1, the built-in scene
detumble_impulse_arm1_joint4) read through sensors: ideal, then 1 % noise, a 2-period delay and
100 Hz sampling alone and together, with the momentum from the measured state's map or from the
Kalman estimator; how fast and how far arm 1's end-effector spin settles, how close the momentum
estimate is, and what the sensors cost. Prints one table, writes
runs/sensed-detumbling-<time>/sensed_detumbling.json and the figure docs/img/sensed_detumbling.png
(docs/sensors.md quotes both).

    python3 scripts/sensed_detumbling.py [--seeds N]   # default 5 seeds per noisy case
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from freefloat.app.experiments.detumbling import detumble_task, prepare
from freefloat.app.scenes import find_scene
from freefloat.dynamics import gjm
from freefloat.dynamics.identification.measurements import channel_scale
from freefloat.dynamics.metrics import band_settling_time, settling_time
from freefloat.dynamics.sensors import Channel, MomentumKalman, Sensed, Sensors, SensorSettings
from freefloat.dynamics.simulation import run

SCENE = "detumble_impulse_arm1_joint4"
#: The capture's end (the scene's task.start), s: the known impulse the estimator restarts at.
CAPTURE_END = 0.015


class InPython:
    """A law without its compiled twin (what a sensed law costs without the sensors)."""

    def __init__(self, law):
        self.law = law

    def torque(self, t, q, v):
        return self.law.torque(t, q, v)

    def reference(self, t):
        return self.law.reference(t)


def simulate(wrap=None) -> tuple:
    """The scene's run with its controller wrapped by ``wrap(controller, robot, period)`` (None:
    as it is): the result and the controller the loop ran."""
    setup = prepare(find_scene(SCENE))
    sim = setup.scene.simulation
    controller = setup.controller if wrap is None else wrap(setup.controller, setup.robot, sim.control_period)
    result = run(setup.robot, setup.q0, setup.v0, sim.duration, sim.control_period, setup.integrator, setup.model,
                 controller, setup.wrenches)
    return setup, result, controller


def one_percent(robot, ideal, seed: int, noise: float = 0.01, delay: int = 2, every: int = 10,
                estimator: MomentumKalman | None = None, groups: tuple[str, ...] | None = None) -> SensorSettings:
    """``noise`` (a fraction) of each component's size over the ideal run (the RMS for rates, the
    spread of the displacement for poses and angles: freefloat's identification's definition of
    "1 %"), on every group or only ``groups``; the delay and sampling on every group."""
    tel, nb = ideal.telemetry, robot.n_base
    spread = channel_scale(np.array([pin.difference(robot.model, tel.q[0], q) for q in tel.q]), positions=True)
    size = channel_scale(tel.v)
    scales = {"base_pose": spread[:nb], "base_twist": size[:nb], "joint_position": spread[nb:],
              "joint_rate": size[nb:]}
    channels = {name: Channel(noise=tuple(noise * s) if groups is None or name in groups else 0.0, delay=delay,
                              every=every) for name, s in scales.items()}
    return SensorSettings(**channels, momentum=estimator, seed=seed)


def measures(setup, result, controller) -> dict:
    """Arm 1's end-effector spin (the detumbled row) and the base's: settling and residual; the
    momentum estimate's error against the telemetry's (Pinocchio's) momentum; wall time."""
    tel, robot = result.telemetry, setup.robot
    rows = detumble_task(robot, setup.scene)[0]
    speed = np.array([np.abs(gjm.compute(robot, q, v).end_effector_velocity()[rows]).max()
                      for q, v in zip(tel.q, tel.v)])
    late = tel.t > tel.t[-1] - 0.1
    base = np.abs(tel.base_twist[:, 5])
    out = {"status": result.status, "wall_time_s": result.wall_time_s, "rows_speed_max": float(speed.max()),
           "settling_time_1pc": settling_time(tel.t, speed, 0.01 * speed.max()),
           "rows_speed_rms_last_0.1s": float(np.sqrt(np.mean(speed[late] ** 2))),
           "rows_speed_final": float(speed[-1]), "base_rate_final": float(base[-1]),
           "base_rate_rms_last_0.1s": float(np.sqrt(np.mean(base[late] ** 2))),
           "base_rate_settling_time": band_settling_time(tel.t, base), "peak_torque": float(np.abs(tel.tau).max())}
    if isinstance(controller, Sensed) and controller.sensors.estimator is not None:
        record, truth = controller.log.record(), tel.momentum[:-1, 5]
        after = record.t > 0.1
        out.update({"Lz_estimate_error_rms": float(np.sqrt(np.mean((record.estimate[after, 5] - truth[after]) ** 2))),
                    "Lz_map_error_rms": float(np.sqrt(np.mean((record.momentum[after, 5] - truth[after]) ** 2))),
                    "Lz_estimate_error_final": float(abs(record.estimate[-1, 5] - truth[-1])),
                    "Lz_estimate_sd_final": float(record.spread[-1, 5]), "resets": int(record.reset.sum()),
                    "Lz_true": float(truth[-1])})
    return out


#: Measures the table shows: median [min, max] over the seeds.
SHOWN = ("settling_time_1pc", "rows_speed_rms_last_0.1s", "base_rate_final", "peak_torque", "wall_time_s",
         "Lz_estimate_error_rms", "Lz_map_error_rms")


def spread(rows: list[dict], key: str) -> str:
    """``key median [min, max]`` over the rows (a missing value as NaN)."""
    values = np.array([np.nan if row.get(key) is None else row[key] for row in rows])
    return f"{key} {np.median(values):.3g} [{np.nanmin(values):.3g}, {np.nanmax(values):.3g}]"


def sensed(settings_of):
    """A wrapper for :func:`simulate`: the law read through the sensors ``settings_of(robot)``."""
    return lambda law, robot, period: Sensed(law, Sensors(robot, settings_of(robot), period))


def main(seeds: int) -> None:
    out = Path("runs") / f"sensed-detumbling-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    setup, ideal, law = simulate()
    report: dict = {"ideal (compiled law)": [measures(setup, ideal, law)],
                    "ideal, the law in Python": [measures(*simulate(lambda c, r, p: InPython(c)))],
                    "ideal, through Sensed": [measures(*simulate(sensed(lambda r: SensorSettings())))]}
    kalman = MomentumKalman(restart=(CAPTURE_END,))
    cases = {"2-period delay": {"noise": 0.0, "every": 1}, "100 Hz sampling": {"noise": 0.0, "delay": 0},
             "delay + sampling": {"noise": 0.0}, "1 % noise": {"delay": 0, "every": 1},
             "1 % noise, Kalman": {"delay": 0, "every": 1, "estimator": kalman},
             "1 % noise on the joint rates only": {"delay": 0, "every": 1, "groups": ("joint_rate",)},
             "1 % noise on the base only": {"delay": 0, "every": 1, "groups": ("base_pose", "base_twist")},
             "all three, momentum map": {}, "all three, Kalman (restart at capture)": {"estimator": kalman},
             "all three, Kalman (gate only)": {"estimator": MomentumKalman()}}
    for name, keys in cases.items():
        seeds_run = range(1, 1 + (seeds if keys.get("noise", 0.01) > 0.0 else 1))
        report[name] = [measures(*simulate(sensed(lambda r, s=seed, k=keys: one_percent(r, ideal, s, **k))))
                        for seed in seeds_run]
    for name, rows in report.items():
        print(f"{name:42s} " + ", ".join(spread(rows, key) for key in SHOWN if key in rows[0]))
    report["cost, best of 3 (s)"] = [costs(ideal, kalman)]
    print("cost, best of 3 (s):", report["cost, best of 3 (s)"][0])
    (out / "sensed_detumbling.json").write_text(json.dumps(report, indent=1))
    figure(ideal, setup)
    print(f"-> {out / 'sensed_detumbling.json'}, docs/img/sensed_detumbling.png")


def costs(ideal, kalman: MomentumKalman, repeats: int = 3) -> dict[str, float]:
    """The loop's wall time of one run (s), best of ``repeats`` taken in turn: the compiled law, the
    law in Python, sensed (1 %, 2-period delay, 100 Hz), with the estimator at 100 Hz and at 1 kHz."""
    wraps = {"compiled law": None, "law in Python": lambda c, r, p: InPython(c),
             "sensed": sensed(lambda r: one_percent(r, ideal, 1)),
             "sensed + Kalman": sensed(lambda r: one_percent(r, ideal, 1, estimator=kalman)),
             "sensed at 1 kHz + Kalman": sensed(lambda r: one_percent(r, ideal, 1, delay=0, every=1, estimator=kalman))}
    times: dict[str, list[float]] = {name: [] for name in wraps}
    for _ in range(repeats):
        for name, wrap in wraps.items():
            times[name].append(simulate(wrap)[1].wall_time_s)
    return {name: min(values) for name, values in times.items()}


def figure(ideal, setup) -> None:
    """Arm 1's end-effector spin, ideal and sensed (all three, seed 1), and the angular momentum
    the law read: the raw map of the readings, the Kalman estimate, the truth."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = detumble_task(setup.robot, setup.scene)[0]

    def spin(result) -> np.ndarray:
        return np.array([np.abs(gjm.compute(setup.robot, q, v).end_effector_velocity()[rows]).max()
                         for q, v in zip(result.telemetry.q, result.telemetry.v)])

    runs = {"ideal": ideal}
    for label, estimator in (("1 % noise, 2-period delay, 100 Hz: momentum map", None),
                             ("the same, Kalman estimate", MomentumKalman(restart=(CAPTURE_END,)))):
        _, result, controller = simulate(sensed(lambda r, e=estimator: one_percent(r, ideal, 1, estimator=e)))
        runs[label] = result
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for label, result in runs.items():
        top.semilogy(result.telemetry.t, np.maximum(spin(result), 1e-12), label=label, lw=1)
    top.set_ylabel("arm 1 end-effector |wz| (rad/s)")
    top.legend(fontsize=8)
    record = controller.log.record()
    bottom.plot(record.t, record.momentum[:, 5], lw=0.6, color="0.7", label="map of the readings")
    bottom.plot(record.t, record.estimate[:, 5], lw=1.2, label="Kalman estimate")
    bottom.plot(result.telemetry.t, result.telemetry.momentum[:, 5], "k--", lw=1, label="true (Pinocchio)")
    bottom.set_ylabel("Lz about the origin (N m s)")
    bottom.set_xlabel("t (s)")
    bottom.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(Path(__file__).resolve().parents[1] / "docs" / "img" / "sensed_detumbling.png", dpi=110)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    main(parser.parse_args().seeds)
