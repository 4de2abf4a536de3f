"""The numbers of docs/identification.md: a robot's and the 5R's parameters identified from
noisy efforts (with a seeded Monte-Carlo of the intervals), the 5R's sliding mode designed on
the identified intervals and run on the true plant, and a captured target identified from the
motion after the grasp, then detumbled on the identified, true and a wrong model. Prints one
table per part and writes runs/identification-<time>/identification.json.

    python3 scripts/identification.py [--quick]   # --quick: fewer Monte-Carlo draws (20 instead of 200)
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from freefloat import load_robot
from freefloat.dynamics.identification import excitation, measurements
from freefloat.dynamics.identification.parameters import about_com, model_parameters
from freefloat.dynamics.identification.regressors import torque_regressor
from freefloat.dynamics.identification.tree import identify, structural_base
from freefloat.parallel import gain_design
from freefloat.parallel import identification as chains
from freefloat.parallel.closed_chain import load_closed_chain
from freefloat.parallel.closed_loop import track_five_bar
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.registry import five_bar_inertias
from freefloat.parallel.sliding_mode import (
    PlatformControl,
    chattering,
    circle_reference,
    design_gains,
    workspace_grid,
)
from freefloat.paths import URDF_DIR
from freefloat.robot.catalog import find_robot
from freefloat.space.after_capture import detumble, manoeuvre
from freefloat.space.capture import Target, grasp
from freefloat.space.target_identification import held_parameters, identify_target, with_target

NOISE = 0.01  # 1 % of each channel's size


def coverage(draws: int, estimate, truth: np.ndarray) -> dict:
    """Share of true values inside the 95 % intervals of ``estimate(rng)`` over seeded draws."""
    hits, z = [], []
    for k in range(draws):
        est = estimate(np.random.default_rng(100 + k))
        lower, upper = est.interval(0.95)
        hits.append((lower <= truth) & (truth <= upper))
        z.append((est.values - truth) / est.std)
    return {"draws": draws, "coverage_95": float(np.mean(hits)), "z_std": float(np.std(z)), "z_mean": float(np.mean(z))}


def robot_part(draws: int) -> dict:
    """The UR5 (fixed base, gravity): base parameters, excitation, Monte-Carlo, filtered record."""
    model = pin.buildModelFromUrdf(str(find_robot("ur5")))
    base = structural_base(model, np.random.default_rng(0))
    beta = base.of(model_parameters(model))
    data = model.createData()

    def cost(trajectory):
        _, (q, v, a) = trajectory.sample(100)
        return float(np.linalg.cond(base.regressor(torque_regressor(model, q, v, a, data))))

    start = excitation.random_trajectory(np.zeros(6), 5, 10.0, 1.0, 2.0, np.random.default_rng(3))
    began = time.perf_counter()
    _, best_cost = excitation.optimise(start, cost, 1.0, 2.0, iterations=15)
    optimise_s = time.perf_counter() - began
    _, (q, v, a) = start.sample(400)
    tau = np.array([pin.rnea(model, data, *s) for s in zip(q, v, a)])
    mc = coverage(draws, lambda rng: identify(
        model, base, measurements.noisy_configurations(model, q, NOISE, rng), measurements.noisy(v, NOISE, rng), a,
        measurements.noisy(tau, NOISE, rng)), beta)
    t, (q, v, a) = start.sample(10000)
    tau = np.array([pin.rnea(model, data, *s) for s in zip(q, v, a)])
    rng = np.random.default_rng(5)
    record = measurements.filtered_record(model, t, measurements.noisy_configurations(model, q, NOISE, rng),
                                          measurements.noisy(v, NOISE, rng), measurements.noisy(tau, NOISE, rng), 101)
    est = identify(model, base, *record[1:])
    return {"parameters": len(base.names), "base_parameters": base.rank, "condition_random": cost(start),
            "condition_optimised": best_cost, "optimise_s": optimise_s, "monte_carlo": mc,
            "filtered": {"max_abs_z": float(np.abs((est.values - beta) / est.std).max()),
                         "max_error_of_largest": float(np.abs(est.values - beta).max() / np.abs(beta).max()),
                         "acceleration_error_rms": float(np.sqrt(np.mean((record[3] - start(record[0])[2]) ** 2))
                                                         / np.sqrt(np.mean(start(record[0])[2] ** 2)))}}


def tracking(control: PlatformControl) -> dict:
    """Sec 5.6's circle on the true 5R (15 % off), 0.5 s at 0.1 ms: error and chattering after 0.2 s."""
    tel = track_five_bar(TRUE_PARAMETERS, control, 0.5, 1e-4).telemetry
    e, s = control.sliding_variables(tel.t, tel.q, tel.v)
    late = tel.t > 0.2
    chat = chattering(tel.t, tel.efforts, s, 0.2)
    return {"tracking_error_max_m": np.abs(e[late]).max(axis=0).tolist(),
            "effort_variation_per_s": chat["effort_variation_per_s"], "peak_effort": float(np.abs(tel.efforts).max())}


def five_bar_part(draws: int) -> dict:
    """The 5R: base parameters, identification (Monte-Carlo), design and closed loop."""
    chain = load_closed_chain(URDF_DIR / "five_bar.closure.toml")

    def guess(point):
        return elbow_guess(FiveBarParameters(), point)

    rng = np.random.default_rng(0)
    grid = workspace_grid(FiveBarParameters(), 0.01)
    base = chains.structural_base(chain, grid[rng.choice(len(grid), 40, replace=False)], guess, rng)
    true_model = pin.Model(chain.model)
    five_bar_inertias(TRUE_PARAMETERS, true_model)
    beta = base.of(model_parameters(true_model))
    trajectory = excitation.random_trajectory(np.array([0.0, 0.17]), 5, 0.5, 0.05, 1.0, np.random.default_rng(2))
    _, (x, xd, xdd) = trajectory.sample(2000)
    q, _, _ = chains.platform_states(chain, x, xd, xdd, guess(x[0]))
    tau = five_bar(TRUE_PARAMETERS).reference().inverse(q, xd, xdd)[0]
    spread = measurements.channel_scale(x, positions=True)

    def estimate(rng):
        x_m = measurements.noisy(x, NOISE, rng, spread)
        states = chains.platform_states(chain, x_m, measurements.noisy(xd, NOISE, rng), xdd, guess(x_m[0]))
        return chains.identify(chain, base, *states, measurements.noisy(tau, NOISE, rng))

    mc = coverage(max(draws // 4, 5), estimate, beta)
    est = estimate(np.random.default_rng(5))
    model = chains.RegressorModel.identified(chain, base, est, guess, level=0.95)
    points = grid[::20]
    identified, thesis = gain_design.design_gains(model, points, 20.0), design_gains(FiveBarParameters(), points, 20.0)
    believed = chains.with_tree_parameters(chain, base.preimage(est.values, model_parameters(chain.model)))
    nominal = five_bar(FiveBarParameters())
    runs = {"nominal_model_thesis_gains": tracking(PlatformControl(nominal, circle_reference, 40.0, thesis)),
            "identified_model_thesis_gains": tracking(PlatformControl(believed, circle_reference, 40.0, thesis)),
            "identified_model_identified_gains": tracking(PlatformControl(believed, circle_reference, 40.0, identified)),
            "identified_model_computed_torque": tracking(PlatformControl(believed, circle_reference, 40.0))}
    return {"base_parameters": base.rank, "labels": list(base.labels()), "true": beta.tolist(),
            "estimate": est.values.tolist(), "half_width_95": est.half_width(0.95).tolist(),
            "joint_half_width_95": est.half_width(0.95, joint=True).tolist(), "condition": est.condition,
            "monte_carlo": mc, "design_points": len(points),
            "gains": {name: {"n": g.n.tolist(), "T": g.T.tolist(), "n_ij": {f"{i},{j}": v.tolist() for (i, j), v in g.n_ij.items()}}
                      for name, g in (("identified", identified), ("thesis_15", thesis))},
            "closed_loop": runs}


def target_part(draws: int) -> dict:
    """capture_satellite's box: grasp, 10 s manoeuvre, identification, detumbling three ways."""
    robot = load_robot("dual_arm_satellite", base="free", visuals=False)
    q0 = robot.neutral()
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q0)
    hand = data.oMf[robot.model.getFrameId("left_tool0")].translation
    target = Target.meeting(hand, 0.5, 50.0, (2.0, 2.5, 3.0), (-0.25, 0.0, 0.0), (0.05, -0.05, 0.02),
                            (0.0, 0.0, np.deg2rad(11.5)))
    held = grasp(robot, target, "left_tool0", approach_time=0.6, q0=q0)
    left = [name for name in robot.joint_names if name.startswith("left")]
    trajectory = excitation.random_trajectory(np.zeros(6), 5, 10.0, 0.3, 0.5, np.random.default_rng(0))
    tel = manoeuvre(held.merged, robot, held.q, held.v, trajectory, left, 10.0).telemetry
    truth = held_parameters(held.merged, robot, "left_tool0")
    m, c, I_C = about_com(truth)

    def noisy_estimate(rng, window=101):
        return identify_target(robot, "left_tool0", measurements.noisy_configurations(robot.model, tel.q, NOISE, rng),
                               measurements.noisy(tel.v, NOISE, rng), window=window)

    exact = identify_target(robot, "left_tool0", tel.q, tel.v)
    rows = {}
    for name, est in (("exact", exact), ("noise_1pct_raw", noisy_estimate(np.random.default_rng(7), 1)),
                      ("noise_1pct_smoothed", noisy_estimate(np.random.default_rng(7)))):
        m_hat, c_hat, I_hat = est.physical()
        m_std, _, _ = est.physical_std()
        z = (est.parameters - truth) / est.estimate.std[:10]
        rows[name] = {"mass_error": (m_hat - m) / m, "mass_std": m_std / m, "com_error_m": float(np.abs(c_hat - c).max()),
                      "inertia_error": float(np.linalg.norm(I_hat - I_C) / np.linalg.norm(I_C)),
                      "max_abs_z": float(np.abs(z).max()), "condition": est.estimate.condition}
    mc = coverage(max(draws // 5, 5), lambda rng: _TenParameters(noisy_estimate(rng)), truth)
    wrong = with_target(robot, "left_tool0", pin.Inertia(1.5 * m, c, I_C).toDynamicParameters())
    identified = with_target(robot, "left_tool0", noisy_estimate(np.random.default_rng(7)).parameters)
    detumbling = {}
    for name, believed in (("true", held.merged), ("identified", identified), ("mass_plus_50pct", wrong),
                           ("robot_alone", robot)):
        run = detumble(held.merged, believed, tel.q[-1], tel.v[-1], [("left_tool0", "angular")], 3.0, 1e-6)
        detumbling[name] = {"settling_time_1e-6": run.settling_time, "final_speed": run.final_speed,
                            "peak_torque": run.peak_torque, "start_speed": float(run.target_speed[0])}
    return {"truth": {"mass": m, "com": c.tolist(), "principal_inertia": np.linalg.eigvalsh(I_C).tolist()},
            "manoeuvre_momentum_drift": float(np.abs(tel.momentum - tel.momentum[0]).max()),
            "identification": rows, "monte_carlo": mc, "detumbling": detumbling}


class _TenParameters:
    """The target's ten parameters of a TargetEstimate as an Estimate-like record (values,
    std, interval) for :func:`coverage`."""

    def __init__(self, estimate):
        self.values, self.std = estimate.parameters, estimate.estimate.std[:10]
        self._half = estimate.estimate.half_width(0.95)[:10]

    def interval(self, level):
        return self.values - self._half, self.values + self._half


def main(argv: list[str]) -> int:
    draws = 20 if "--quick" in argv else 200
    out = Path("runs") / f"identification-{time.strftime('%Y%m%d-%H%M%S')}"
    report = {}
    for name, part in (("robot", robot_part), ("five_bar", five_bar_part), ("target", target_part)):
        began = time.perf_counter()
        report[name] = part(draws)
        report[name]["wall_s"] = time.perf_counter() - began
        print(name, json.dumps(report[name], indent=1, default=float))
    out.mkdir(parents=True, exist_ok=True)
    (out / "identification.json").write_text(json.dumps(report, indent=1, default=float))
    print(f"wrote {out / 'identification.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
