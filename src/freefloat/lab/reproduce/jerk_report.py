"""``freefloat reproduce jerk``: the jerk by the composition of motion (thesis proposal eqs 4-5,
19-21; :mod:`freefloat.robot.jerk`) against finite differences of Pinocchio's accelerations, on
serial chains: the 5R's two RR chains (``urdf/five_bar.urdf``) and the UR5.

At seeded random states (q, qdot, qddot, qdddot; 20, ``--quick`` 3) the joints move along the
polynomial ``q(t) = q + qdot t + qddot t^2/2 + qdddot t^3/6`` (exact for these revolute joints); the
link centres of mass' and the last frame's (the end-effector's) jerks and angular jerks are
compared with 4th-order central differences of Pinocchio's classical linear and angular
accelerations (``getFrameClassicalAcceleration``, ``getFrameAcceleration``) at steps h of 1e-2,
1e-3 and 1e-4 s, as the largest difference over the largest jerk; beside them, eq 4 as printed
(``alpha x (alpha x r)``). Writes ``report.json``, ``report.md`` and ``jerk.png``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ...app.outputs import write_report
from ...paths import URDF_DIR
from ...robot.catalog import find_robot
from ...robot.jerk import com_motions, frame_motion

#: The finite-difference steps, s.
STEPS = (1e-2, 1e-3, 1e-4)
#: The chains: name -> URDF.
CHAINS = {"5R spanning tree (two RR chains)": lambda: URDF_DIR / "five_bar.urdf", "UR5": lambda: find_robot("ur5")}


def with_com_frames(model: pin.Model) -> tuple[list[int], int]:
    """Add an operational frame at each link's CoM; their ids and the end-effector's (the model's
    last frame before them)."""
    end_effector = model.nframes - 1
    frames = [model.addFrame(pin.Frame(f"com{i}", i, model.getFrameId(model.names[i]),
                                       pin.SE3(np.eye(3), model.inertias[i].lever), pin.FrameType.OP_FRAME))
              for i in range(1, model.njoints)]
    return frames, end_effector


def accelerations(model: pin.Model, data: pin.Data, q, v, a, frames: list[int]) -> np.ndarray:
    """Pinocchio's classical linear and angular accelerations of ``frames`` (F, 6), N's axes."""
    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    return np.array([np.r_[pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).linear,
                           pin.getFrameAcceleration(model, data, f, pin.LOCAL_WORLD_ALIGNED).angular] for f in frames])


def along(model: pin.Model, q0: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray, t: float) -> tuple:
    """(q, qdot, qddot) at time ``t`` (s) of the polynomial joint motion of constant jerk ``j``
    from (``q0``, ``v``, ``a``)."""
    return pin.integrate(model, q0, v * t + a * t**2 / 2 + j * t**3 / 6), v + a * t + j * t**2 / 2, a + j * t


def chain_rows(urdf: Path, states: int, seed: int = 0) -> dict:
    """The largest relative differences (over the states) of the CoMs' and end-effector's jerks
    from the finite differences at each step, and of eq 4 as printed at the finest step."""
    model = pin.buildModelFromUrdf(str(urdf))
    coms, end_effector = with_com_frames(model)
    data, rng = model.createData(), np.random.default_rng(seed)
    out = {"links": model.njoints - 1, "com": {str(h): 0.0 for h in STEPS}, "end_effector": {str(h): 0.0 for h in STEPS},
           "printed_eq4_com": 0.0}
    for _ in range(states):
        q0 = pin.integrate(model, pin.neutral(model), rng.uniform(-np.pi, np.pi, model.nv))  # seeded, any joint
        v, a, j = rng.normal(size=(3, model.nv))
        tip = frame_motion(model, q0, v, a, j, end_effector)
        ours = {"com": np.array([np.r_[m.jerk, m.angular_jerk] for m in com_motions(model, q0, v, a, j)]),
                "end_effector": np.r_[tip.jerk, tip.angular_jerk][None]}
        printed = np.array([np.r_[m.jerk, m.angular_jerk] for m in com_motions(model, q0, v, a, j, "printed_eq4")])
        for h in STEPS:
            samples = [accelerations(model, data, *along(model, q0, v, a, j, k * h), coms + [end_effector])
                       for k in (-2, -1, 1, 2)]
            fd = (samples[0] - 8.0 * samples[1] + 8.0 * samples[2] - samples[3]) / (12.0 * h)
            for key, rows in (("com", slice(0, len(coms))), ("end_effector", slice(len(coms), None))):
                out[key][str(h)] = max(out[key][str(h)], float(np.abs(ours[key] - fd[rows]).max() / np.abs(fd[rows]).max()))
            if h == STEPS[-1]:
                out["printed_eq4_com"] = max(out["printed_eq4_com"],
                                             float(np.abs(printed - fd[: len(coms)]).max() / np.abs(fd[: len(coms)]).max()))
    return out


def reproduce(out: Path, quick: bool = False) -> dict:
    """Every chain's rows; report and figure in ``out``."""
    start = time.perf_counter()
    states = 3 if quick else 20
    report = {"settings": {"quick": quick, "states": states, "steps_s": list(STEPS), "difference": "4th-order central"},
              "chains": {name: chain_rows(urdf(), states) for name, urdf in CHAINS.items()}}
    write_report(out, report, markdown, start)
    draw(report).savefig(out / "jerk.png", dpi=110)
    return report


def markdown(report: dict) -> str:
    """The table: per chain and point, the relative difference at each step."""
    lines = ["# Jerk by the composition of motion against finite differences of Pinocchio's accelerations", "",
             f"{report['settings']['states']} random states per chain; largest |jerk - finite difference| / largest "
             f"|finite difference|; wall time {report['wall_time_s']:.0f} s.", "",
             "| chain | points | " + " | ".join(f"h = {h:g} s" for h in STEPS) + " |", "|---|---|" + "---|" * len(STEPS)]
    for name, c in report["chains"].items():
        for key, label in (("com", f"{c['links']} link CoMs"), ("end_effector", "end-effector")):
            lines.append(f"| {name} | {label} | " + " | ".join(f"{c[key][str(h)]:.2g}" for h in STEPS) + " |")
        lines.append(f"| {name} | link CoMs, eq 4 as printed | | | {c['printed_eq4_com']:.2g} |")
    return "\n".join(lines) + "\n"


def draw(report: dict) -> Figure:
    """The relative difference against the finite-difference step (log-log), per chain and point;
    eq 4 as printed as a marker at the finest step."""
    fig = Figure(figsize=(7, 4.5))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    for k, (name, c) in enumerate(report["chains"].items()):
        for key, style in (("com", "o-"), ("end_effector", "s--")):
            ax.loglog(STEPS, [c[key][str(h)] for h in STEPS], style, color=f"C{k}", label=f"{name}, {key.replace('_', '-')}")
        ax.loglog([STEPS[-1]], [c["printed_eq4_com"]], "x", color=f"C{k}", markersize=10, label=f"{name}, eq 4 as printed")
    ax.set(xlabel="finite-difference step h (s)", ylabel="relative difference",
           title="Jerk (eqs 5, 19-21) vs 4th-order differences of Pinocchio's accelerations")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
