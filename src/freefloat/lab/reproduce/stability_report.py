"""``freefloat reproduce stability``: the largest stable step per integrator and scene.

For every case of :mod:`.stability_cases` (robots tumbling at increasing base rates, the
detumbling scenes after their impulse, the closed chains with and without Baumgarte), the step is
bisected (:func:`freefloat.dynamics.stability.largest_stable_step`) between a stable and an
unstable one, then, from the unstable one up, between a step whose run completes (whatever its
drift) and one that blows up. Writes ``report.json`` (settings, versions, rows), ``stability.csv``,
``report.md`` and ``stability.png`` (largest stable step against rate or scene, one curve per
integrator).
"""

from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np

from ...app.outputs import write_report
from ...dynamics.stability import largest_stable_step
from .stability_cases import CLOSURE_BOUND, DRIFT_BOUND, Case, ClosedChain, Detumbling, Tumbling

ROBOT_INTEGRATORS = ("euler", "rk4_naive", "rkmk4", "rkmk6", "rkmk8")
ROBOTS = {"four_arm": "four_arm_planar", "dual_arm": "dual_arm_satellite"}
DETUMBLING = ("detumble_impulse_arm1_joint3", "detumble_impulse_arm1_joint4", "detumble_impulse_arm2_joint4",
              "detumble_impulse_both_arms")
MECHANISMS = ("five_bar_computed_torque", "rsu_ppap_computed_torque")
#: The closed chains' integrators (every fixed-step one of the registry that the thesis contrasts
#: or that reaches a higher order) and Baumgarte lambdas (1/s; None: the document's 1/h).
CHAIN_INTEGRATORS = ("euler", "explicit_euler", "rkmk4", "rkmk6", "rkmk8")
CHAIN_LAMBDAS = (0.0, 100.0, None)
#: Step brackets searched, s: tumbling in units of 1/rate.
TUMBLING_BRACKET, DETUMBLING_BRACKET, CHAIN_BRACKET = (1e-4, 1.0), (5e-6, 0.05), (1e-5, 0.1)


def cases(quick: bool) -> list[tuple[dict, Case, tuple[float, float]]]:
    """``(labels, case, (low, high))`` of the study: labels name the group, scene, the swept value
    (base rate, rad/s, or Baumgarte lambda, 1/s) and the integrator."""
    rates = (3.0, 30.0) if quick else (1.0, 3.0, 10.0, 30.0)
    robot_integrators = ("euler", "rkmk4") if quick else ROBOT_INTEGRATORS
    out: list[tuple[dict, Case, tuple[float, float]]] = []
    for scene, robot in ROBOTS.items():
        for rate in rates:
            for name in robot_integrators:
                low, high = (x / rate for x in TUMBLING_BRACKET)
                out.append(({"group": "tumbling", "scene": scene, "value": rate, "integrator": name},
                             Tumbling(robot, rate, name), (low, high)))
    for scene in DETUMBLING[-1:] if quick else DETUMBLING:
        for name in ("rkmk4",) if quick else ROBOT_INTEGRATORS:  # Euler's limit here takes 14 us steps: slow
            out.append(({"group": "detumbling", "scene": scene, "value": None, "integrator": name},
                        Detumbling(scene, name), DETUMBLING_BRACKET))
    for scene in MECHANISMS:
        for lam in (0.0, 100.0) if quick else CHAIN_LAMBDAS:
            for name in ("euler", "rkmk4") if quick else CHAIN_INTEGRATORS:
                out.append(({"group": "closed chain", "scene": scene, "value": "1/h" if lam is None else lam,
                             "integrator": name},
                            ClosedChain(scene, name, lam), CHAIN_BRACKET))
    return out


def search(case: Case, low: float, high: float, rtol: float) -> dict:
    """Bisect one case twice: for the largest stable step, then, from there up, for the largest
    step whose run completes (no blow-up, whatever its drift). The row: both brackets and the
    case's measurements at the first one's ends."""
    seen: dict[float, dict] = {}

    def measured(h: float) -> dict:
        if h not in seen:
            seen[h] = case.measure(h)
        return seen[h]

    start = time.perf_counter()
    limit = largest_stable_step(lambda h: case.passes(measured(h)), low, high, rtol)
    if limit.unstable is None:  # stable, so completing, up to high
        completes, blows_up = limit.stable, None
    elif measured(limit.unstable)["status"] != "completed":  # blew up right past the stable step
        completes, blows_up = limit.stable, limit.unstable
    else:
        blow_up = largest_stable_step(lambda h: measured(h)["status"] == "completed", limit.unstable, high, rtol)
        completes, blows_up = blow_up.stable, blow_up.unstable
    return {"stable_step": limit.stable, "unstable_step": limit.unstable, "evaluations": limit.evaluations,
            "completes_step": completes, "blows_up_step": blows_up,
            "runs": len(seen), "at_stable": seen.get(limit.stable), "at_unstable": seen.get(limit.unstable),
            "low": low, "high": high, "wall_time_s": time.perf_counter() - start}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Run every case; write the report, the CSV table and the figure into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    rtol = 0.1 if quick else 0.02
    rows = [{**labels, **search(case, low, high, rtol)} for labels, case, (low, high) in cases(quick)]
    report = {"settings": {"quick": quick, "rtol": rtol, "drift_bound": DRIFT_BOUND, "closure_bound_m": CLOSURE_BOUND,
                           "seed": 0, "definitions": DEFINITIONS}, "rows": rows}
    write_report(out, report, markdown, start)
    write_csv(rows, out / "stability.csv")
    figure(rows, out / "stability.png")
    return report


DEFINITIONS = {
    "tumbling": ("torque-free, free base, start rate about a seeded random axis, joints at seeded angles in +-0.5 rad "
                 "at rest relative to the base, 10 rad of base rotation; stable: completed, kinetic energy and angular "
                 "momentum about the origin within 1 % of their start values"),
    "detumbling": ("the scene for 0.5 s with one step per control period; stable: completed, angular momentum after "
                   "the impulse within 1 % (of the impulse) of what the held impulse gives exactly"),
    "closed chain": ("the scene (computed torque held over each step) for 0.3 s at Baumgarte lambda 'value'; stable: "
                     "completed, loop-closure drift max |qbar| <= 1 mm"),
}


def _step(x: float | None, bound: str) -> str:
    """``x`` (s) to three digits, or ``bound`` when the bracket is open there."""
    return bound if x is None else f"{x:.3g}"


def markdown(report: dict) -> str:
    """The table: per case, the largest stable step and the smallest unstable one, the largest step
    that completes and the smallest that blows up (s)."""
    lines = ["# Stability maps: the largest stable step per integrator and scene", "",
             (f"Bisection on the step to a relative bracket of {report['settings']['rtol']:g}; wall time "
              f"{report['wall_time_s']:.0f} s."), ""]
    lines += [f"- {group}: {text}." for group, text in report["settings"]["definitions"].items()]
    lines += ["", ("| group | scene | rate (rad/s) or lambda (1/s) | integrator | largest stable step (s) "
                   "| smallest unstable step (s) | largest step that completes (s) | smallest that blows up (s) | runs |"),
              "|---|---|---|---|---|---|---|---|---|"]
    for r in report["rows"]:
        value = _value(r["value"])
        below, above = "< {:.3g}".format(r["low"]), "> {:.3g}".format(r["high"])
        steps = (_step(r["stable_step"], below), _step(r["unstable_step"], above), _step(r["completes_step"], below),
                 _step(r["blows_up_step"], above))
        lines.append(f"| {r['group']} | {r['scene']} | {value} | {r['integrator']} | " + " | ".join(steps) + f" | {r['runs']} |")
    return "\n".join(lines) + "\n"


def write_csv(rows: list[dict], path: Path) -> Path:
    """One line per case: labels, both brackets (s, empty when open), the runs and the bracket searched."""
    keys = ("group", "scene", "value", "integrator", "stable_step", "unstable_step", "completes_step", "blows_up_step",
            "runs", "low", "high")
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(keys)
        for r in rows:
            writer.writerow(["" if r[k] is None else r[k] for k in keys])
    return path


def figure(rows: list[dict], path: Path) -> Path:
    """Largest stable step (log scale) against base rate (tumbling, one panel per robot) and
    against scene (detumbling, closed chains), one curve per integrator (marker and line style
    apart, as curves can coincide); an open bracket is drawn at its bound with a hollow marker.
    Dotted, in the same colour: the largest step whose run completes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("tumbling", scene) for scene in ROBOTS] + [("detumbling", None), ("closed chain", None)]
    panels = [(g, s) for g, s in panels if any(r["group"] == g and s in (None, r["scene"]) for r in rows)]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 4.0))
    for ax, (group, scene) in zip(np.atleast_1d(axes), panels):
        mine = [r for r in rows if r["group"] == group and scene in (None, r["scene"])]
        ticks = list(dict.fromkeys(_tick(r) for r in mine))
        for i, name in enumerate(dict.fromkeys(r["integrator"] for r in mine)):
            curve = [r for r in mine if r["integrator"] == name]
            x = [r["value"] if group == "tumbling" else ticks.index(_tick(r)) for r in curve]
            y = [r["stable_step"] if r["stable_step"] is not None else r["low"] for r in curve]
            line, = ax.plot(x, y, "osx^D"[i % 5], ls="-" if i % 2 == 0 else "--", label=name)
            ends = [(xi, r["completes_step"]) for xi, r in zip(x, curve) if r["completes_step"] is not None]
            ax.plot([e[0] for e in ends], [e[1] for e in ends], ".:", color=line.get_color(), lw=0.8)
            open_ = [i for i, r in enumerate(curve) if r["unstable_step"] is None or r["stable_step"] is None]
            ax.plot([x[i] for i in open_], [y[i] for i in open_], "o", mfc="white", color=line.get_color())
        if group == "tumbling":
            ax.set_xscale("log")
            ax.set_xlabel("base rate at the start (rad/s)")
            ax.set_title(f"tumbling, {scene}")
        else:
            ax.set_xticks(range(len(ticks)), ticks, rotation=30, ha="right", fontsize=7)
            ax.set_title(group)
        ax.set_yscale("log")
        ax.set_ylabel("largest stable step (s); dotted: completes")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _tick(row: dict) -> str:
    """The x label of a detumbling or closed-chain row."""
    scene = row["scene"].replace("detumble_impulse_", "").replace("_computed_torque", "")
    return scene if row["group"] != "closed chain" else f"{scene}, lambda {_value(row['value'])}"


def _value(value: float | str | None) -> str:
    """A row's swept value as written: a number, ``1/h``, or ``-`` for none."""
    return "-" if value is None else value if isinstance(value, str) else f"{value:g}"
