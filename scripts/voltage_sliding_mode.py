"""Sliding mode with the motors' voltage as the control input (thesis proposal sec 9, items 10-11),
against torque-input sliding mode and computed torque, on the 5R (sec 5.6's circle) and the
2RSU+PPaP (its scenes' circle).

Every plant is motorised (rotors and drive trains from ``urdf/<mechanism>.motors.toml``) with its
links 15 % off (the 5R's ``TRUE_PARAMETERS``, the 2RSU+PPaP's ``true_15`` masses) and, where the
input is the voltage, warm motors 15 % off (:func:`freefloat.parallel.drives.off_nominal`). The
laws work on the nominal motorised model; each sliding-mode law has the gains of its own worst-case
design (:mod:`freefloat.parallel.drive_gain_design`: voltage input with the motors' uncertainty,
torque input with the rotors' and the friction's only), lambda = 40, eta = 20, tanh(100 s); the
voltage through :class:`freefloat.dynamics.voltage_drive.VoltageDrive`. One integrator step (RK4) per
control period, the law held over it, the same step for every input.

    python3 scripts/voltage_sliding_mode.py [--quick] [--out DIR] [--figure FILE] [--sweep 2000 5000]

writes ``voltage_sliding_mode.json`` and ``.md`` (the tables), with ``--figure`` the figure, with
``--sweep`` the 5R's voltage-input sliding mode at those current-loop bandwidths (1/s). Seconds to minutes: the plants with armature and friction run their rigid-body terms in the
compiled core and the rest in Python.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from freefloat.dynamics.plants import CoupledChainPlant
from freefloat.dynamics.simulation import run_plant
from freefloat.dynamics.voltage_drive import VoltageDrive
from freefloat.parallel import drive_gain_design
from freefloat.parallel.drives import (
    five_bar_motors,
    motor_driven,
    motorised,
    off_nominal,
    rsu_ppap_motors,
)
from freefloat.parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from freefloat.parallel.gain_design import box_grid, spectral_radius
from freefloat.parallel.platform_control import CircleReference
from freefloat.parallel.registry import rsu_ppap_setup
from freefloat.parallel.rsu_ppap import CLOSURE, load_data
from freefloat.parallel.rsu_ppap_masses import RsuPpapModel
from freefloat.parallel.sliding_mode import (
    FiveBarModel,
    PlatformControl,
    chattering,
    circle_reference,
)

LAMBDA, ETA, ERROR = 40.0, 20.0, 0.15
#: The drive's current-loop rate, 1/s: just below the winding's own R/L (3850 1/s), the best of
#: the sweep this script runs (``--sweep``), the supply never reached.
BANDWIDTH = 3500.0


def five_bar_case():
    """The 5R: nominal and plant mechanisms (unmotorised), start, reference, design points, models."""
    nominal, true = five_bar(FiveBarParameters()), five_bar(TRUE_PARAMETERS)
    start = np.array([0.07, 0.17])
    q0 = true.assemble(start, elbow_guess(TRUE_PARAMETERS, start))
    angles = np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False)
    points = np.vstack((start, circle_reference.center + circle_reference.radius * np.c_[np.cos(angles), np.sin(angles)]))
    return {"name": "5R", "nominal": nominal, "plant": true, "q0": q0, "reference": circle_reference,
            "points": points, "model": FiveBarModel(FiveBarParameters()), "motors": five_bar_motors(),
            "step": 1e-4, "duration": 0.4, "after": 0.2}


def rsu_ppap_case():
    """The 2RSU+PPaP: the scenes' 3 cm horizontal circle at 1 Hz about home, from rest on it."""
    setup, data = rsu_ppap_setup(CLOSURE, "true_15"), load_data()
    home = np.array(data["home"])
    reference = CircleReference(home, 0.03, 2.0 * np.pi, (0, 1))
    start = reference(0.0)[0]
    q0 = setup.plant.assemble(start, setup.guess(start))
    return {"name": "2RSU+PPaP", "nominal": setup.nominal, "plant": setup.plant, "q0": q0, "reference": reference,
            "points": box_grid(home, 0.04, 0.04), "model": RsuPpapModel(setup.nominal, data),
            "motors": rsu_ppap_motors(), "step": 1e-4, "duration": 0.6, "after": 0.3}


def run_case(case: dict, law_kind: str, voltage: bool, gains, quick: bool) -> dict:
    """One closed loop; its errors, efforts, voltages, currents and chattering."""
    motors = case["motors"].motors
    true_motors = off_nominal(motors, ERROR)  # the same mechanical plant (rotors, drive trains) for either input
    nominal = motorised(case["nominal"], motors)
    plant_mech = motorised(case["plant"], true_motors)
    law = PlatformControl(nominal, case["reference"], LAMBDA, gains if law_kind == "sliding_mode" else None)
    step, duration = case["step"], case["duration"] * (0.5 if quick else 1.0)
    after = case["after"] * (0.5 if quick else 1.0)
    start = time.perf_counter()
    if voltage:
        plant = motor_driven(plant_mech, true_motors)
        controller = VoltageDrive(law, plant, motors, BANDWIDTH, step)
        q0, v0 = np.r_[case["q0"], np.zeros(len(motors))], np.zeros(plant.space.nv)
    else:
        plant, controller = CoupledChainPlant(plant_mech, 100.0), law
        q0, v0 = case["q0"], np.zeros(len(case["q0"]))
    result = run_plant(plant, q0, v0, duration, step, "rkmk4", controller)
    tel = result.telemetry
    n = len(case["q0"])
    q, v = tel.q[:, :n], tel.v[:, :n]
    e, s = law.sliding_variables(tel.t, q, v)
    late = tel.t > after
    if voltage:
        current = tel.v[:, n:]
        effort = true_motors.effort(current)
        volts = np.abs(tel.efforts).max(axis=0)
    else:
        current = effort = tel.efforts
        volts = None
    out = {"law": law_kind, "input": "voltage" if voltage else "torque", "status": result.status,
           "wall_s": round(time.perf_counter() - start, 1),
           "error_max": np.abs(e[late]).max(axis=0).tolist(), "error_rms": np.sqrt((e[late] ** 2).mean(axis=0)).tolist(),
           "error_norm_max": float(np.linalg.norm(e[late], axis=1).max()),
           "effort_peak": np.abs(effort).max(axis=0).tolist(),
           "chattering": chattering(tel.t, tel.efforts, s, after)}
    if voltage:
        out.update(voltage_peak=volts.tolist(), current_peak=np.abs(current).max(axis=0).tolist(),
                   current_rms=np.sqrt((current[late] ** 2).mean(axis=0)).tolist())
    out["_series"] = {"t": tel.t, "e": e, "effort": effort, "efforts": tel.efforts, "current": current if voltage else None}
    return out


def design(case: dict, voltage: bool):
    m = case["motors"]
    model = drive_gain_design.DrivenModel(case["model"], m.motors, m.uncertainty, voltage)
    start = time.perf_counter()
    gains = drive_gain_design.design_gains(model, case["points"], ETA)
    return gains, {"n": gains.n.tolist(), "T": gains.T.tolist(), "n_rate": {str(k): v.tolist() for k, v in gains.n_rate.items()},
                   "n_ij": {f"{i},{j}": v.tolist() for (i, j), v in gains.n_ij.items()},
                   "spectral_radius": spectral_radius(gains.Delta_max), "points": len(case["points"]),
                   "wall_s": round(time.perf_counter() - start, 1)}


def study(quick: bool) -> dict:
    report = {}
    for case in (five_bar_case(), rsu_ppap_case()):
        gains_v, design_v = design(case, True)
        gains_t, design_t = design(case, False)
        runs = [run_case(case, "sliding_mode", False, gains_t, quick), run_case(case, "sliding_mode", True, gains_v, quick),
                run_case(case, "computed_torque", False, None, quick), run_case(case, "computed_torque", True, None, quick),
                {**run_case(case, "sliding_mode", False, gains_v, quick), "law": "sliding_mode (voltage design's gains)"}]
        report[case["name"]] = {"design": {"voltage": design_v, "torque": design_t}, "runs": runs,
                                "motors": [case["motors"].motors[j] for j in range(len(case["motors"].motors))]}
    return report


def table(report: dict) -> str:
    lines = []
    for name, part in report.items():
        lines += [f"### {name}", "", ("| law | input | max error after the reaching phase (per axis, mm) | max norm of e "
                                      "(mm) | RMS (mm) | peak effort | peak voltage (V) | peak current (A) | median "
                                      "effort/voltage jump | sign changes of s per s |"), "|---|---|---|---|---|---|---|---|---|---|"]
        for r in part["runs"]:
            fmt = lambda xs, k=1e3: " / ".join(f"{k * x:.3g}" for x in xs)
            lines.append(f"| {r['law']} | {r['input']} | {fmt(r['error_max'])} | {1e3 * r['error_norm_max']:.3g} | "
                         f"{fmt(r['error_rms'])} | {fmt(r['effort_peak'], 1)} | "
                         f"{fmt(r['voltage_peak'], 1) if 'voltage_peak' in r else '-'} | "
                         f"{fmt(r['current_peak'], 1) if 'current_peak' in r else '-'} | "
                         f"{fmt(r['chattering']['effort_jump_median'], 1)} | {fmt(r['chattering']['s_sign_changes_per_s'], 1)} |")
        lines.append("")
    return "\n".join(lines)


def figure(report: dict, path: Path) -> None:
    """Top: each mechanism's error norm under the four laws. Bottom left: the 5R's first motor over
    20 ms, its current under voltage-input sliding mode against the current the torque-input law's
    effort would take (tau / (N k_t)), and its terminal voltage. Bottom right: the 2RSU+PPaP's
    voltages and currents under voltage-input sliding mode."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    for column, (name, part) in enumerate(report.items()):
        for r in part["runs"][:4]:
            series = r["_series"]
            axes[0, column].semilogy(series["t"], 1e3 * np.linalg.norm(series["e"], axis=1) + 1e-9, lw=0.8,
                                     label=f"{r['law'].replace('_', ' ')}, {r['input']} input")
        axes[0, column].set(title=f"{name}: tracking error", ylabel="|e| (mm)", xlabel="t (s)", ylim=(1e-4, 1e2))
        axes[0, column].legend(fontsize=7)
    runs = report["5R"]["runs"]
    voltage, torque = runs[1]["_series"], runs[0]["_series"]
    window = (voltage["t"] >= 0.30) & (voltage["t"] <= 0.32)
    motor = report["5R"]["motors"][0]
    ax = axes[1, 0]
    ax.plot(voltage["t"][window], voltage["current"][window, 0], lw=0.8, label="current, voltage input")
    ax.plot(torque["t"][window], torque["efforts"][window, 0] / (motor.gear_ratio * motor.torque_constant), lw=0.8,
            label="tau / (N k_t), torque input")
    ax.set(xlabel="t (s)", ylabel="motor 1 current (A)", title="5R, sliding mode: motor 1 over 20 ms",
           xticks=np.linspace(0.30, 0.32, 5))
    twin = ax.twinx()
    twin.plot(voltage["t"][window], voltage["efforts"][window, 0], lw=0.5, color="grey", alpha=0.6)
    twin.set_ylabel("terminal voltage (V), grey")
    ax.legend(fontsize=7, loc="upper left")
    series = report["2RSU+PPaP"]["runs"][1]["_series"]
    ax = axes[1, 1]
    for j, name in enumerate(("crank 1", "crank 2", "rail")):
        line, = ax.plot(series["t"], series["efforts"][:, j], lw=0.8, label=f"{name}: V")
        ax.plot(series["t"], series["current"][:, j], lw=0.8, ls=":", color=line.get_color(), label=f"{name}: A")
    ax.set(xlabel="t (s)", ylabel="V (solid), A (dotted)", title="2RSU+PPaP, sliding mode, voltage input")
    ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def sweep(bandwidths: list[float]) -> list[dict]:
    """The 5R's voltage-input sliding mode at each current-loop bandwidth (1/s)."""
    global BANDWIDTH
    case, out = five_bar_case(), []
    gains = design(case, True)[0]
    kept = BANDWIDTH
    for bandwidth in bandwidths:
        BANDWIDTH = bandwidth
        r = run_case(case, "sliding_mode", True, gains, False)
        out.append({"bandwidth": bandwidth, **{k: r[k] for k in ("error_max", "error_norm_max", "voltage_peak",
                                                                "current_peak")},
                    "s_sign_changes_per_s": r["chattering"]["s_sign_changes_per_s"]})
    BANDWIDTH = kept
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="half the durations")
    parser.add_argument("--out", type=Path, default=Path("."))
    parser.add_argument("--figure", type=Path, default=None)
    parser.add_argument("--sweep", type=float, nargs="*", default=(), help="the 5R's bandwidths to sweep, 1/s")
    args = parser.parse_args()
    report = study(args.quick)
    args.out.mkdir(parents=True, exist_ok=True)
    clean = {name: {"design": part["design"], "runs": [{k: v for k, v in r.items() if k != "_series"} for r in part["runs"]]}
             for name, part in report.items()}
    if args.sweep:
        clean["5R bandwidth sweep"] = sweep(list(args.sweep))
        print(json.dumps(clean["5R bandwidth sweep"], indent=1))
    (args.out / "voltage_sliding_mode.json").write_text(json.dumps(clean, indent=1))
    (args.out / "voltage_sliding_mode.md").write_text(table(report))
    print(json.dumps({n: report[n]["design"] for n in report}, indent=1))
    print(table(report))
    if args.figure is not None:
        figure(report, args.figure)


if __name__ == "__main__":
    main()
