"""``freefloat reproduce voltage_sliding``: sliding mode with the motors' voltage as the control
input (thesis proposal sec 9, items 8, 10, 11), against torque-input sliding mode and computed
torque, on the 5R (sec 5.6's circle) and the 2RSU+PPaP (its scenes' circle).

Every plant is motorised (rotors and drive trains from ``urdf/<mechanism>.motors.toml``) with its
links 15 % off (the 5R's ``TRUE_PARAMETERS``, the 2RSU+PPaP's ``true_15`` masses) and, where the
input is the voltage, warm motors 15 % off (:func:`freefloat.parallel.drives.off_nominal`). The
laws work on the nominal motorised model; each sliding-mode law has the gains of its own worst-case
design (:mod:`freefloat.parallel.drive_gain_design`: voltage input with the motors' uncertainty,
torque input with the rotors' and the friction's only), lambda = 40, eta = 20, tanh(100 s); the
voltage through :class:`freefloat.dynamics.voltage_drive.VoltageDrive`. One integrator step (RK4) per
control period, the law held over it, the same step for every input.

``--quick``: the 5R alone, 0.25 s (the aim's window after 0.2 s kept), four runs. The issue's aim:
voltage-input sliding mode within :data:`AIM` times the torque-input law's error after 0.2 s.
Writes ``report.json``, ``report.md`` and ``errors.png``; ``scripts/voltage_sliding_mode.py`` adds
the current loop's bandwidth sweep (:func:`sweep`).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...dynamics.plants import CoupledChainPlant
from ...dynamics.simulation import run_plant
from ...dynamics.voltage_drive import VoltageDrive
from ...parallel import drive_gain_design
from ...parallel.drives import (
    five_bar_motors,
    motor_driven,
    motorised,
    off_nominal,
    rsu_ppap_motors,
)
from ...parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from ...parallel.gain_design import box_grid, spectral_radius
from ...parallel.platform_control import CircleReference
from ...parallel.registry import rsu_ppap_setup
from ...parallel.rsu_ppap import CLOSURE, load_data
from ...parallel.rsu_ppap_masses import RsuPpapModel
from ...parallel.sliding_mode import FiveBarModel, PlatformControl, chattering, circle_reference
from .interrupts import finished

LAMBDA, ETA, ERROR = 40.0, 20.0, 0.15
#: The drive's current-loop rate, 1/s: just below the winding's own R/L (3850 1/s), the best of
#: the sweep (docs/parallel.md), the supply never reached.
BANDWIDTH = 3500.0
#: The 20 ms (s) over which the figure shows the 5R's motor 1 at every step.
WINDOW = (0.30, 0.32)
#: The issue's aim: voltage-input sliding mode's error after 0.2 s within this many times torque input's.
AIM = 2.0
#: The runs: (label, law, voltage input, gains of the voltage design); the quick run has the first four.
RUNS = (("sliding mode, torque", "sliding_mode", False, False), ("sliding mode, voltage", "sliding_mode", True, True),
        ("computed torque, torque", "computed_torque", False, False),
        ("computed torque, voltage", "computed_torque", True, False),
        ("sliding mode, torque, the voltage design's gains", "sliding_mode", False, True))


def five_bar_case() -> dict:
    """The 5R: nominal and plant mechanisms (unmotorised), start, reference, design points
    (the start and 12 points of the circle), models, step, duration and window start (s)."""
    nominal, true = five_bar(FiveBarParameters()), five_bar(TRUE_PARAMETERS)
    start = np.array([0.07, 0.17])
    q0 = true.assemble(start, elbow_guess(TRUE_PARAMETERS, start))
    angles = np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False)
    points = np.vstack((start, circle_reference.center + circle_reference.radius * np.c_[np.cos(angles), np.sin(angles)]))
    return {"name": "5R", "nominal": nominal, "plant": true, "q0": q0, "reference": circle_reference,
            "points": points, "model": FiveBarModel(FiveBarParameters()), "motors": five_bar_motors(),
            "step": 1e-4, "duration": 0.4, "after": 0.2}


def rsu_ppap_case() -> dict:
    """The 2RSU+PPaP: the scenes' 3 cm horizontal circle at 1 Hz about home, from rest on it."""
    setup, data = rsu_ppap_setup(CLOSURE, "true_15"), load_data()
    home = np.array(data["home"])
    reference = CircleReference(home, 0.03, 2.0 * np.pi, (0, 1))
    start = reference(0.0)[0]
    q0 = setup.plant.assemble(start, setup.guess(start))
    return {"name": "2RSU+PPaP", "nominal": setup.nominal, "plant": setup.plant, "q0": q0, "reference": reference,
            "points": box_grid(home, 0.04, 0.04), "model": RsuPpapModel(setup.nominal, data),
            "motors": rsu_ppap_motors(), "step": 1e-4, "duration": 0.6, "after": 0.3}


def design(case: dict, voltage: bool):
    """The worst-case gains of the voltage-input (``voltage``) or torque-input design over the
    case's points, and their record (n, T, n_rate, n_ij, spectral radius of the worst Delta)."""
    m = case["motors"]
    model = drive_gain_design.DrivenModel(case["model"], m.motors, m.uncertainty, voltage)
    start = time.perf_counter()
    gains = drive_gain_design.design_gains(model, case["points"], ETA)
    return gains, {"n": gains.n.tolist(), "T": gains.T.tolist(),
                   "n_rate": {str(k): v.tolist() for k, v in gains.n_rate.items()},
                   "n_ij": {f"{i},{j}": v.tolist() for (i, j), v in gains.n_ij.items()},
                   "spectral_radius": spectral_radius(gains.Delta_max), "points": len(case["points"]),
                   "wall_s": time.perf_counter() - start}


def run_case(case: dict, law_kind: str, voltage: bool, gains, duration: float, after: float,
             bandwidth: float = BANDWIDTH) -> dict:
    """One closed loop of ``duration`` s: its errors after ``after`` s (m), efforts, voltages,
    currents and chattering; ``series`` holds the time series for the figure (every ms, and
    motor 1's held effort and current at every step over :data:`WINDOW`)."""
    motors = case["motors"].motors
    true_motors = off_nominal(motors, ERROR)  # the same mechanical plant (rotors, drive trains) for either input
    plant_mech = motorised(case["plant"], true_motors)
    law = PlatformControl(motorised(case["nominal"], motors), case["reference"], LAMBDA,
                          gains if law_kind == "sliding_mode" else None)
    step = case["step"]
    start = time.perf_counter()
    if voltage:
        plant = motor_driven(plant_mech, true_motors)
        controller = VoltageDrive(law, plant, motors, bandwidth, step)
        q0, v0 = np.r_[case["q0"], np.zeros(len(motors))], np.zeros(plant.space.nv)
    else:
        plant, controller = CoupledChainPlant(plant_mech, 100.0), law
        q0, v0 = case["q0"], np.zeros(len(case["q0"]))
    result = finished(run_plant(plant, q0, v0, duration, step, "rkmk4", controller))
    tel = result.telemetry
    n = len(case["q0"])
    e, s = law.sliding_variables(tel.t, tel.q[:, :n], tel.v[:, :n])
    late = tel.t > after
    current = tel.v[:, n:] if voltage else tel.efforts
    effort = true_motors.effort(current) if voltage else tel.efforts
    out = {"law": law_kind, "input": "voltage" if voltage else "torque", "status": result.status,
           "wall_s": time.perf_counter() - start,
           "error_max": np.abs(e[late]).max(axis=0).tolist(), "error_rms": np.sqrt((e[late] ** 2).mean(axis=0)).tolist(),
           "error_norm_max": float(np.linalg.norm(e[late], axis=1).max()),
           "effort_peak": np.abs(effort).max(axis=0).tolist(), "chattering": chattering(tel.t, tel.efforts, s, after)}
    if voltage:
        out.update(voltage_peak=np.abs(tel.efforts).max(axis=0).tolist(), current_peak=np.abs(current).max(axis=0).tolist(),
                   current_rms=np.sqrt((current[late] ** 2).mean(axis=0)).tolist())
    every = max(1, round(1e-3 / step))
    window = (tel.t >= WINDOW[0]) & (tel.t <= WINDOW[1])
    out["series"] = {"t": tel.t[::every].tolist(), "e_norm_mm": (1e3 * np.linalg.norm(e[::every], axis=1)).tolist(),
                     "efforts": tel.efforts[::every].tolist(), "current": current[::every].tolist(),
                     "window": {"t": tel.t[window].tolist(), "effort_1": tel.efforts[window, 0].tolist(),
                                "current_1": current[window, 0].tolist()}}
    return out


def mechanism(case: dict, quick: bool) -> dict:
    """Both designs and the case's runs (:data:`RUNS`; quick: the first four, 0.25 s)."""
    gains = {True: design(case, True), False: design(case, False)}
    duration, after = (0.25, case["after"]) if quick else (case["duration"], case["after"])
    runs = {label: run_case(case, law, voltage, gains[voltage_gains][0], duration, after)
            for label, law, voltage, voltage_gains in (RUNS[:4] if quick else RUNS)}
    return {"design": {"voltage": gains[True][1], "torque": gains[False][1]}, "duration": duration, "after": after,
            "runs": runs}


def aim(part: dict) -> dict:
    """Voltage-input over torque-input sliding mode's error after the window's start: the norm's
    and each axis's ratio, and whether the norm's is within :data:`AIM`."""
    v, t = part["runs"]["sliding mode, voltage"], part["runs"]["sliding mode, torque"]
    ratio = v["error_norm_max"] / t["error_norm_max"]
    return {"norm_ratio": ratio, "axis_ratios": (np.array(v["error_max"]) / np.array(t["error_max"])).tolist(),
            "holds": bool(ratio <= AIM)}


def reproduce(out: Path, quick: bool = False) -> dict:
    """The 5R (and, in full, the 2RSU+PPaP): designs, runs, the aim; report and figure in ``out``."""
    start = time.perf_counter()
    cases = (five_bar_case(),) if quick else (five_bar_case(), rsu_ppap_case())
    parts = {case["name"]: mechanism(case, quick) for case in cases}
    report = {"settings": {"quick": quick, "lambda": LAMBDA, "eta": ETA, "plant_and_motor_error": ERROR,
                           "bandwidth_per_s": BANDWIDTH, "step_s": 1e-4, "integrator": "rkmk4", "aim": AIM},
              "mechanisms": parts, "aim": {name: aim(part) for name, part in parts.items()}}
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "errors.png", dpi=110)
    return report


def _fmt(xs, k: float = 1.0) -> str:
    return " / ".join(f"{k * x:.3g}" for x in xs)


def markdown(report: dict) -> str:
    """One table of designs and one of runs per mechanism, then the aim."""
    lines = ["# Sliding mode with the voltage as input, against torque input and computed torque", "",
             f"Settings {report['settings']}; wall time {report['wall_time_s']:.0f} s.", ""]
    for name, part in report["mechanisms"].items():
        d = part["design"]
        lines += [f"## {name} ({part['duration']} s, errors after {part['after']} s)", "",
                  f"Gains n: voltage design {_fmt(d['voltage']['n'])}, torque design {_fmt(d['torque']['n'])}; "
                  f"spectral radius of the worst Delta {d['voltage']['spectral_radius']:.3f} / "
                  f"{d['torque']['spectral_radius']:.3f}.", "",
                  "| run | max error per axis (mm) | max norm (mm) | RMS (mm) | peak effort | peak voltage (V) "
                  "| peak current (A) | median jump of the held effort | sign changes of s per s |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for label, r in part["runs"].items():
            lines.append(f"| {label} | {_fmt(r['error_max'], 1e3)} | {1e3 * r['error_norm_max']:.3g} | "
                         f"{_fmt(r['error_rms'], 1e3)} | {_fmt(r['effort_peak'])} | "
                         f"{_fmt(r['voltage_peak']) if 'voltage_peak' in r else '-'} | "
                         f"{_fmt(r['current_peak']) if 'current_peak' in r else '-'} | "
                         f"{_fmt(r['chattering']['effort_jump_median'])} | "
                         f"{_fmt(r['chattering']['s_sign_changes_per_s'])} |")
        a = report["aim"][name]
        lines += ["", f"Aim (voltage within {AIM:g}x torque input's error): norm ratio {a['norm_ratio']:.3f}, "
                      f"per axis {_fmt(a['axis_ratios'])}: {'holds' if a['holds'] else 'fails'}.", ""]
    return "\n".join(lines)


def draw(report: dict) -> Figure:
    """Top: each mechanism's error norm (mm, log) under every run. Below, when the runs reach
    :data:`WINDOW` (not ``--quick``): the 5R's motor 1 over it, its current under voltage-input
    sliding mode against the current the torque-input law's effort would take (tau / (N k_t)),
    and its terminal voltage; the 2RSU+PPaP's voltages and currents under voltage-input sliding
    mode."""
    parts = report["mechanisms"]
    five_bar = parts["5R"]["runs"]
    detail = len(five_bar["sliding mode, voltage"]["series"]["window"]["t"]) > 0 and "2RSU+PPaP" in parts
    fig = Figure(figsize=(6 * len(parts), 8.0 if detail else 4.2))
    FigureCanvasAgg(fig)
    axes = fig.subplots(2 if detail else 1, len(parts), squeeze=False)
    for ax, (name, part) in zip(axes[0], parts.items()):
        for label, r in part["runs"].items():
            ax.semilogy(r["series"]["t"], np.maximum(r["series"]["e_norm_mm"], 1e-6), lw=0.9, label=label)
        ax.axvline(part["after"], color="k", lw=0.5, ls=":")
        ax.set(title=f"{name}: tracking error, 15 % plant and motors", xlabel="t (s)", ylabel="|e| (mm)")
        ax.legend(fontsize=7)
    if detail:
        voltage, torque = five_bar["sliding mode, voltage"]["series"]["window"], five_bar["sliding mode, torque"]["series"]["window"]
        motor = five_bar_motors().motors[0]
        ax = axes[1, 0]
        ax.plot(voltage["t"], voltage["current_1"], lw=0.8, label="current, voltage input")
        ax.plot(torque["t"], np.array(torque["effort_1"]) / (motor.gear_ratio * motor.torque_constant), lw=0.8,
                label="tau / (N k_t), torque input")
        ax.set(xlabel="t (s)", ylabel="motor 1 current (A)", title="5R, sliding mode: motor 1 over 20 ms")
        twin = ax.twinx()
        twin.plot(voltage["t"], voltage["effort_1"], lw=0.5, color="grey", alpha=0.6)
        twin.set_ylabel("terminal voltage (V), grey")
        ax.legend(fontsize=7, loc="upper left")
        series = parts["2RSU+PPaP"]["runs"]["sliding mode, voltage"]["series"]
        volts, amps = np.array(series["efforts"]), np.array(series["current"])
        ax = axes[1, 1]
        for j, name in enumerate(("crank 1", "crank 2", "rail")):
            line, = ax.plot(series["t"], volts[:, j], lw=0.8, label=f"{name}: V")
            ax.plot(series["t"], amps[:, j], lw=0.8, ls=":", color=line.get_color(), label=f"{name}: A")
        ax.set(xlabel="t (s)", ylabel="V (solid), A (dotted)", title="2RSU+PPaP, sliding mode, voltage input")
        ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    return fig


def sweep(bandwidths: list[float]) -> list[dict]:
    """The 5R's voltage-input sliding mode (0.4 s, errors after 0.2 s) at each current-loop
    bandwidth (1/s)."""
    case = five_bar_case()
    gains = design(case, True)[0]
    out = []
    for bandwidth in bandwidths:
        r = run_case(case, "sliding_mode", True, gains, case["duration"], case["after"], bandwidth)
        out.append({"bandwidth": bandwidth, **{k: r[k] for k in ("error_max", "error_norm_max", "voltage_peak",
                                                                "current_peak")},
                    "s_sign_changes_per_s": r["chattering"]["s_sign_changes_per_s"]})
    return out
