"""``freefloat reproduce friction``: joint friction and actuator inertias (thesis proposal sec 9,
items 4-5) on the 5R, with the rotors and drive trains of ``urdf/five_bar.motors.toml``
(:func:`freefloat.parallel.drives.motorised`: ``N^2 J_m`` on each base joint's diagonal, the
drive train's viscous and regularised Coulomb friction).

1. Energy balance: the motorised 5R falling from a moving start (0.3 s; ``--quick``: 0.1 s; RK4 at
   0.1 ms, no Baumgarte, zero efforts). The energy is Pinocchio's on the spanning tree with the
   same armature (``1/2 v^T M v`` from CRBA, plus the potential), the friction's work Simpson's
   rule on the recorded rates: the energy lost equals the work of friction.
2. Tracking: sec 5.6's circle on the motorised 15 % plant, computed torque (eq 190) and sliding
   mode (the torque-input drive design's gains over the start and 12 points of the circle,
   :mod:`freefloat.parallel.drive_gain_design`), each with the nominal model without the terms
   and with them; 0.4 s (``--quick``: 0.25 s), errors after 0.2 s.

Writes ``report.json``, ``report.md`` and ``friction.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from scipy.integrate import simpson

from ...app.outputs import write_report
from ...dynamics.motors import add_armature
from ...dynamics.plants import CoupledChainPlant
from ...dynamics.simulation import run_plant
from ...parallel.closed_chain import load_closed_chain
from ...parallel.drives import five_bar_motors, motorised
from ...parallel.five_bar import TRUE_PARAMETERS, FiveBarParameters, elbow_guess, five_bar
from ...parallel.sliding_mode import PlatformControl, circle_reference
from ...paths import URDF_DIR
from .interrupts import finished
from .printed import START
from .voltage_sliding_report import LAMBDA, design, five_bar_case

#: The falling run's start: the platform point (m) and the base joints' rates (rad/s).
FALL_POINT, FALL_RATES = np.array([0.07, 0.17]), np.array([0.5, -0.4])


def energy_balance(duration: float, step: float = 1e-4) -> dict:
    """The motorised 5R falling for ``duration`` s: energy (J) over time, its loss and friction's
    work, and their difference."""
    chain = load_closed_chain(URDF_DIR / "five_bar.closure.toml")
    motors = five_bar_motors().motors
    mech = motorised(chain.mechanism, motors)
    model = pin.Model(chain.model)
    add_armature(model, [model.idx_vs[j] for j in chain.actuated], motors)
    data = model.createData()
    q0 = mech.assemble(FALL_POINT, elbow_guess(FiveBarParameters(), FALL_POINT))
    qd0 = mech.velocity_map(q0) @ np.linalg.solve(mech.velocity_map(q0)[mech.actuated], FALL_RATES)
    tel = finished(run_plant(CoupledChainPlant(mech, 0.0), q0, qd0, duration, step, "rkmk4")).telemetry

    def energy(q: np.ndarray, qd: np.ndarray) -> float:
        qp, vp = chain.pinocchio_q(q), chain.pinocchio_q(qd)
        return float(0.5 * vp @ pin.crba(model, data, qp) @ vp + pin.computePotentialEnergy(model, data, qp))

    E = np.array([energy(q, qd) for q, qd in zip(tel.q, tel.v)])
    power = (mech.joint_friction(tel.v) * tel.v).sum(axis=1)
    work = np.array([simpson(power[: k + 1], x=tel.t[: k + 1]) if k else 0.0 for k in range(0, len(tel.t), 10)])
    lost = float(E[0] - E[-1])
    friction_work = float(simpson(power, x=tel.t))
    return {"duration_s": duration, "step_s": step, "armature": np.atleast_1d(motors.armature).tolist(),
            "energy_lost_J": lost, "friction_work_J": friction_work, "difference_J": lost - friction_work,
            "t": tel.t[::10].tolist(), "energy_J": E[::10].tolist(), "work_J": work.tolist()}


def run_law(gains, with_terms: bool, duration: float, step: float = 1e-4) -> dict:
    """Sec 5.6's circle on the motorised 15 % plant, the law's nominal model with or without the
    rotors and drive trains; errors after 0.2 s (m), peak efforts (N m), the error every ms."""
    motors = five_bar_motors().motors
    plant = motorised(five_bar(TRUE_PARAMETERS), motors)
    nominal = five_bar(FiveBarParameters())
    law = PlatformControl(motorised(nominal, motors) if with_terms else nominal, circle_reference, LAMBDA, gains)
    point = np.array(START)
    q0 = plant.assemble(point, elbow_guess(TRUE_PARAMETERS, point))
    tel = finished(run_plant(CoupledChainPlant(plant, 100.0), q0, np.zeros(len(q0)), duration, step, "rkmk4",
                             law)).telemetry
    e = law.sliding_variables(tel.t, tel.q, tel.v)[0]
    late, every = tel.t > 0.2, max(1, round(1e-3 / step))
    return {"error_max_m": np.abs(e[late]).max(axis=0).tolist(), "effort_peak": np.abs(tel.efforts).max(axis=0).tolist(),
            "t": tel.t[::every].tolist(), "e_norm_m": np.linalg.norm(e[::every], axis=1).tolist()}


def reproduce(out: Path, quick: bool = False) -> dict:
    """The energy balance and the four closed loops; report and figure in ``out``."""
    start = time.perf_counter()
    gains, record = design(five_bar_case(), False)
    duration = 0.25 if quick else 0.4
    runs = {f"{law}, model {'with' if terms else 'without'} the terms": run_law(g, terms, duration)
            for law, g in (("computed torque", None), ("sliding mode", gains)) for terms in (False, True)}
    report = {"settings": {"quick": quick, "lambda": LAMBDA, "tracking_duration_s": duration, "step_s": 1e-4},
              "energy": energy_balance(0.1 if quick else 0.3), "gains": {"n": record["n"], "T": record["T"]},
              "runs": runs}
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "friction.png", dpi=110)
    return report


def markdown(report: dict) -> str:
    """The balance, then one row per closed loop."""
    e = report["energy"]
    lines = ["# Joint friction and actuator inertias: the motorised 5R", "",
             f"Armature N^2 J_m {e['armature']} kg m^2; wall time {report['wall_time_s']:.0f} s.", "",
             f"Falling {e['duration_s']} s: energy lost {e['energy_lost_J']:.6g} J, friction's work "
             f"{e['friction_work_J']:.6g} J, difference {e['difference_J']:.2g} J.", "",
             "| law on the motorised 15 % plant | max error after 0.2 s, x / y (m) | peak efforts (N m) |", "|---|---|---|"]
    lines += [f"| {name} | {' / '.join(f'{x:.3g}' for x in r['error_max_m'])} | "
              f"{', '.join(f'{x:.3g}' for x in r['effort_peak'])} |" for name, r in report["runs"].items()]
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """Left: energy lost and friction's work over time; right: the error norms of the four laws."""
    e = report["energy"]
    fig = Figure(figsize=(12, 4.2))
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    a1.plot(e["t"], e["energy_J"][0] - np.array(e["energy_J"]), label="energy lost (Pinocchio, with armature)")
    a1.plot(e["t"], e["work_J"], "--", label="work of friction")
    a1.set(xlabel="t (s)", ylabel="J", title="The 5R falling with rotors and drive-train friction")
    a1.legend(fontsize=8)
    for name, r in report["runs"].items():
        a2.semilogy(r["t"], np.maximum(r["e_norm_m"], 1e-9), lw=0.9, label=name)
    a2.set(xlabel="t (s)", ylabel="|e| (m)", title="Tracking on the motorised 15 % plant")
    a2.legend(fontsize=7)
    fig.tight_layout()
    return fig
