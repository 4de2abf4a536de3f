"""``freefloat reproduce identification``: least-squares estimates of dynamic parameters with
confidence intervals from simulated noisy measurements along exciting trajectories (thesis
proposal sec 9, item 9), against the true values; docs/identification.md gives the method.

Parts: ``robot`` (the UR5 on its fixed base: base parameters, the excitation's condition number,
a seeded Monte-Carlo of the 95 % intervals' coverage, a record filtered by Savitzky-Golay),
``five_bar`` (the 5R through Orsino's coupling: the 11 base parameters' estimates and 95 %
half-widths against the true plant's, a Monte-Carlo, the worst-case gain design on the identified
box and four closed loops on the true plant) and, in full, ``target`` (capture_satellite's box
identified from the motion after the grasp by momentum conservation, then detumbled on the
identified, true and wrong models). Monte-Carlo draws: 200 (``--quick``: 20). Writes
``report.json``, ``report.md`` and ``intervals.png``; ``scripts/identification.py`` runs it.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...dynamics.identification import excitation, measurements
from ...dynamics.identification.parameters import about_com, model_parameters
from ...dynamics.identification.regressors import torque_regressor
from ...dynamics.identification.tree import identify, structural_base
from ...parallel import gain_design
from ...parallel import identification as chains
from ...parallel.closed_chain import load_closed_chain
from ...parallel.closed_loop import track_five_bar
from ...parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from ...parallel.registry import five_bar_inertias
from ...parallel.sliding_mode import (
    PlatformControl,
    chattering,
    circle_reference,
    design_gains,
    workspace_grid,
)
from ...paths import URDF_DIR
from ...robot.catalog import find_robot
from ...robot.loading import load_robot
from ...space.after_capture import detumble, manoeuvre
from ...space.capture import Target, grasp
from ...space.target_identification import held_parameters, identify_measured, identify_target, with_target
from .interrupts import finished

#: The measurement noise: 1 % of each channel's size.
NOISE = 0.01
#: Monte-Carlo draws, full and quick.
DRAWS, QUICK_DRAWS = 200, 20


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
            "filtered": {"z": ((est.values - beta) / est.std).tolist(),
                         "max_abs_z": float(np.abs((est.values - beta) / est.std).max()),
                         "max_error_of_largest": float(np.abs(est.values - beta).max() / np.abs(beta).max()),
                         "acceleration_error_rms": float(np.sqrt(np.mean((record[3] - start(record[0])[2]) ** 2))
                                                         / np.sqrt(np.mean(start(record[0])[2] ** 2)))}}


def tracking(control: PlatformControl) -> dict:
    """Sec 5.6's circle on the true 5R (15 % off), 0.5 s at 0.1 ms: error and chattering after 0.2 s."""
    tel = finished(track_five_bar(TRUE_PARAMETERS, control, 0.5, 1e-4)).telemetry
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
    tel = finished(manoeuvre(held.merged, robot, held.q, held.v, trajectory, left, 10.0)).telemetry
    truth = held_parameters(held.merged, robot, "left_tool0")
    m, c, I_C = about_com(truth)

    def noisy_estimate(rng, window=101):
        return identify_measured(robot, "left_tool0", tel.q, tel.v, NOISE, rng, window)

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


def reproduce(out: Path, quick: bool = False) -> dict:
    """The parts (quick: robot and 5R, fewer draws); report and figure in ``out``."""
    start = time.perf_counter()
    draws = QUICK_DRAWS if quick else DRAWS
    parts = (("robot", robot_part), ("five_bar", five_bar_part)) + (() if quick else (("target", target_part),))
    report: dict = {"settings": {"quick": quick, "draws": draws, "noise": NOISE}}
    for name, part in parts:
        began = time.perf_counter()
        report[name] = part(draws)
        report[name]["wall_s"] = time.perf_counter() - began
    fb = report["five_bar"]
    truth, estimate, half = (np.array(fb[k]) for k in ("true", "estimate", "half_width_95"))
    fb["inside_95"] = int((np.abs(estimate - truth) <= half).sum())
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "intervals.png", dpi=110)
    return report


def markdown(report: dict) -> str:
    """The parts' tables."""
    r, fb = report["robot"], report["five_bar"]
    lines = ["# Identification with confidence intervals against the true values", "",
             f"Noise {100 * report['settings']['noise']:g} % per channel, {report['settings']['draws']} Monte-Carlo draws; "
             f"wall time {report['wall_time_s']:.0f} s.", "",
             f"## UR5: {r['base_parameters']} base parameters of {r['parameters']}", "",
             f"Excitation condition number {r['condition_random']:.4g} (random) -> {r['condition_optimised']:.4g} "
             f"(optimised). Monte-Carlo coverage of the 95 % intervals {100 * r['monte_carlo']['coverage_95']:.1f} % "
             f"(z mean {r['monte_carlo']['z_mean']:.3f}, spread {r['monte_carlo']['z_std']:.3f}); filtered record: "
             f"max |z| {r['filtered']['max_abs_z']:.3g}, max error {100 * r['filtered']['max_error_of_largest']:.2f} % of "
             "the largest parameter.", "",
             f"## The 5R: {fb['base_parameters']} base parameters ({fb['inside_95']} true values inside their 95 % "
             f"intervals; Monte-Carlo coverage {100 * fb['monte_carlo']['coverage_95']:.1f} %)", "",
             "| base parameter | true | estimate | 95 % half-width |", "|---|---|---|---|"]
    lines += [f"| `{label}` | {t:.6g} | {e:.6g} | {h:.3g} |"
              for label, t, e, h in zip(fb["labels"], fb["true"], fb["estimate"], fb["half_width_95"])]
    lines += ["", "| closed loop on the true 5R | max error after 0.2 s, x / y (m) | peak effort (N m) |", "|---|---|---|"]
    lines += [f"| {name.replace('_', ' ')} | {' / '.join(f'{x:.2g}' for x in c['tracking_error_max_m'])} | "
              f"{c['peak_effort']:.3g} |" for name, c in fb["closed_loop"].items()]
    if "target" in report:
        t = report["target"]
        lines += ["", "## The captured target", "", "| record | mass error | inertia error | CoM error (m) | max abs z |",
                  "|---|---|---|---|---|"]
        lines += [f"| {name} | {row['mass_error']:.2g} | {row['inertia_error']:.2g} | {row['com_error_m']:.2g} | "
                  f"{'-' if name == 'exact' else format(row['max_abs_z'], '.3g')} |"  # noise-free: std ~ 0, z says nothing
                  for name, row in t["identification"].items()]
        lines += ["", f"Monte-Carlo coverage {100 * t['monte_carlo']['coverage_95']:.1f} %.", "",
                  "| law's model | settled below 1e-6 rad/s (s) | final speed (rad/s) | peak torque (N m) |", "|---|---|---|---|"]
        lines += [f"| {name} | {d['settling_time_1e-6']} | {d['final_speed']:.2g} | {d['peak_torque']:.4g} |"
                  for name, d in t["detumbling"].items()]
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """Left: the 5R's base parameters, estimate minus true with the 95 % interval, in units of
    the half-width (inside: the bar crosses 0); right: the UR5's z-scores on the filtered record."""
    fb = report["five_bar"]
    truth, estimate, half = (np.array(fb[k]) for k in ("true", "estimate", "half_width_95"))
    fig = Figure(figsize=(12, 4.5))
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    k = np.arange(len(truth))
    a1.errorbar(k, (estimate - truth) / half, yerr=1.0, fmt="o", capsize=3)
    a1.axhline(0.0, color="k", lw=0.6)
    a1.set(xlabel="5R base parameter", ylabel="(estimate - true) / 95 % half-width",
           title=f"The 5R: {fb['inside_95']} of {len(truth)} true values inside their 95 % intervals")
    z = np.array(report["robot"]["filtered"]["z"])
    a2.bar(np.arange(len(z)), z)
    for bound in (-1.96, 1.96):
        a2.axhline(bound, color="k", lw=0.6, ls=":")
    a2.set(xlabel="UR5 base parameter", ylabel="(estimate - true) / std",
           title="UR5, filtered record: z-scores (dotted: 95 %)")
    fig.tight_layout()
    return fig
