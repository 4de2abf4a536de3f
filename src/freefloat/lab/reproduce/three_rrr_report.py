"""``freefloat reproduce three_rrr``: angular constraints with P != 0 (thesis proposal eqs
101-102), the 3-RRR whose platform turns (:mod:`freefloat.parallel.three_rrr`), Orsino's model
against Pinocchio's constraint dynamics (``pin.constraintDynamics``, two 6-D welds, proximal
mu 1e-12) on the same URDF and closure file.

1. Forward dynamics (eq 129) at random assembled poses (rz up to +-0.6 rad), rates and efforts
   (30; ``--quick``: 5): the largest difference relative to the accelerations' size.
2. Free motion: falling and turning from (0.01, -0.02, 0.3) with the platform spinning at 2 rad/s,
   RK4 at 1 ms without stabilisation, 0.1 s (``--quick``: 0.05 s), both models: the largest joint
   difference, and the same at half the step (RK4's own error on the two coordinate sets).

Writes ``report.json``, ``report.md`` and ``three_rrr.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...dynamics.plants import ConstraintDynamicsPlant, CoupledChainPlant
from ...dynamics.simulation import run_plant
from ...parallel.three_rrr import ThreeRRRParameters, assembly_guess, load_three_rrr
from .interrupts import finished

#: The free motion's start pose (x, y m; rz rad) and platform rates.
START, SPIN = np.array([0.01, -0.02, 0.3]), np.array([0.0, 0.0, 2.0])


def assembled(mech, pose: np.ndarray, rates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Assembled q (12,) at ``pose`` (x, y, rz) and qd = C qd# for platform ``rates`` (3,)."""
    q = mech.assemble(np.asarray(pose, float), assembly_guess(ThreeRRRParameters(), pose))
    return q, mech.velocity_map(q) @ np.asarray(rates, float)


def forward_differences(loaded, count: int, seed: int = 0) -> list[float]:
    """Per random state: max |Orsino's qddot - Pinocchio's| / max |Pinocchio's|."""
    model, mech = loaded.model, loaded.mechanism
    plant = ConstraintDynamicsPlant(model, loaded.constraints, [model.idx_vs[j] for j in loaded.actuated], accuracy=1e-14)
    rng, out = np.random.default_rng(seed), []
    for _ in range(count):
        pose = np.r_[rng.uniform(-0.02, 0.02, 2), rng.uniform(-0.6, 0.6)]
        q, qd = assembled(mech, pose, rng.normal(size=3))
        tau = 0.5 * rng.normal(size=3)
        expected = plant.acceleration(loaded.pinocchio_q(q), loaded.pinocchio_q(qd), tau)
        out.append(float(np.abs(loaded.pinocchio_q(mech.forward(q, qd, tau)) - expected).max() / np.abs(expected).max()))
    return out


def free_motion(loaded, duration: float, step: float) -> dict:
    """Both models falling and turning from :data:`START`: times, the platform angle (Orsino's),
    the joint difference over time (rad)."""
    mech, model = loaded.mechanism, loaded.model
    q0, qd0 = assembled(mech, START, SPIN)
    orsino = finished(run_plant(CoupledChainPlant(mech, 0.0), q0, qd0, duration, step, "rkmk4")).telemetry
    plant = ConstraintDynamicsPlant(model, loaded.constraints, [], accuracy=1e-14)
    pinocchio = finished(run_plant(plant, loaded.pinocchio_q(q0), loaded.pinocchio_q(qd0), duration, step,
                                   "rkmk4")).telemetry
    difference = np.array([np.abs(p - loaded.pinocchio_q(o)).max() for p, o in zip(pinocchio.q, orsino.q)])
    return {"t": orsino.t.tolist(), "rz": orsino.q[:, 2].tolist(), "difference_rad": difference.tolist(),
            "largest_rad": float(difference.max()), "turned_rad": float(orsino.q[-1, 2] - orsino.q[0, 2])}


def reproduce(out: Path, quick: bool = False) -> dict:
    """The forward-dynamics comparison and the free motion at two steps; report and figure in ``out``."""
    start = time.perf_counter()
    loaded = load_three_rrr()
    duration = 0.05 if quick else 0.1
    forward = forward_differences(loaded, 5 if quick else 30)
    report = {"settings": {"quick": quick, "states": len(forward), "duration_s": duration, "start": START.tolist(),
                           "spin": SPIN.tolist(), "integrator": "rkmk4"},
              "forward_relative_max": max(forward), "forward_relative": forward,
              "free_motion": {str(step): free_motion(loaded, duration, step) for step in (1e-3, 5e-4)}}
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "three_rrr.png", dpi=110)
    return report


def markdown(report: dict) -> str:
    """The comparison's numbers."""
    s = report["settings"]
    lines = ["# The 3-RRR (P != 0): Orsino's model against Pinocchio's constraint dynamics", "",
             f"Forward dynamics at {s['states']} random turned states: largest relative difference "
             f"{report['forward_relative_max']:.2g}.", "",
             "| step (s) | platform turned (rad) | largest joint difference over the run (rad) |", "|---|---|---|"]
    lines += [f"| {step} | {m['turned_rad']:.3f} | {m['largest_rad']:.2g} |" for step, m in report["free_motion"].items()]
    lines += ["", f"Wall time {report['wall_time_s']:.0f} s."]
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """Left: the platform angle over the free motion; right: the joint difference between the two
    models over time at both steps (log)."""
    fig = Figure(figsize=(12, 4.2))
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    first = next(iter(report["free_motion"].values()))
    a1.plot(first["t"], first["rz"])
    a1.set(xlabel="t (s)", ylabel="rz (rad)", title="3-RRR falling and turning: the platform angle")
    for step, m in report["free_motion"].items():
        a2.semilogy(m["t"], np.maximum(m["difference_rad"], 1e-18), label=f"RK4 at {float(step) * 1e3:g} ms")
    a2.set(xlabel="t (s)", ylabel="max |q_Orsino - q_Pinocchio| (rad)", title="Orsino's model vs pin.constraintDynamics")
    a2.legend(fontsize=8)
    fig.tight_layout()
    return fig
