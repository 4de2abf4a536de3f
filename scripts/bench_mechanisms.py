"""Work against precision on the closed-chain bench scenes (5R sliding mode, 2RSU+PPaP), in one process.

Usage: ``python3 scripts/bench_mechanisms.py [five_bar] [rsu_ppap] [--quick] [--repeats N] [--out DIR]``.

For each scene of :mod:`freefloat.app.bench.mechanisms`: every method's median wall time over
``--repeats`` runs (the methods taking turns within each repeat, so that load from other
processes falls on all alike), its errors against the DOP853 reference, the cheapest method of
each package per accuracy band (:func:`freefloat.app.bench.summary.cheapest`), a log-log chart
(final-state error and constraint drift against wall time) per scene. Writes
``bench_mechanisms.json``, ``<scene>.png`` and ``summary.txt`` (default
``runs/bench-mechanisms-<time>``). BLAS is limited to one thread for the whole sweep (the numpy
backend's small matrices run 2x slower with more; a limit per run would cost 2-6 ms a run).
Until ``freefloat bench`` runs these scenes itself.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import asdict, dataclass

from bench_common import parser, write_json
from threadpoolctl import threadpool_limits

from freefloat.app.bench.mechanisms import MECHANISM_SCENES, mechanism_scene
from freefloat.app.bench.scene import Method
from freefloat.app.bench.summary import BANDS, cheapest

PACKAGES = ("freefloat", "pinocchio", "mujoco")
STYLES = {("freefloat", "compiled"): "-o", ("freefloat", "python"): ":o", ("pinocchio", "python"): "-.^",
          ("mujoco", "python"): "--s"}


@dataclass
class Measured:
    """One method on one scene: median wall time (s) and its errors (inf when it diverged)."""

    method: Method
    wall_time: float
    state_error: float
    constraint_drift: float
    tracking_error: float


def measure(scene, repeats: int) -> tuple[list[Measured], float]:
    """Every method of ``scene``, and the reference's wall time (s)."""
    start = time.perf_counter()
    ref = scene.reference()
    reference_time = time.perf_counter() - start
    methods = scene.methods()
    runs = [scene.run(m) for m in methods]
    times: list[list[float]] = [[] for _ in methods]
    results: list = [None] * len(methods)
    for _ in range(repeats):
        for i, run in enumerate(runs):
            start = time.perf_counter()
            try:
                results[i] = run()
            except ArithmeticError:
                results[i] = None
            times[i].append(time.perf_counter() - start)
    out = []
    for method, t, result in zip(methods, times, results):
        errors = (scene.errors(result, ref) if result is not None
                  else {"state_error": math.inf, "constraint_drift": math.inf, "tracking_error": math.inf})
        out.append(Measured(method, statistics.median(t), errors["state_error"], errors["constraint_drift"],
                            errors["tracking_error"]))
    return out, reference_time


def chart(scene, points: list[Measured], path) -> None:
    """Wall time against final-state error (left) and against the largest loop-closure gap (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5), sharey=True)
    curves: dict[str, list[Measured]] = {}
    for p in points:
        curves.setdefault(p.method.label, []).append(p)
    for ax, field, what in ((axes[0], "state_error", "final-state error [q#; q_a; rates] against DOP853"),
                            (axes[1], "constraint_drift", scene.secondary[1])):
        for label, curve in curves.items():
            curve = [p for p in sorted(curve, key=lambda p: -p.method.setting) if math.isfinite(getattr(p, field))]
            if curve:
                ax.loglog([getattr(p, field) for p in curve], [p.wall_time * 1e3 for p in curve],
                          STYLES[(curve[0].method.package, curve[0].method.loop)], label=label, ms=4)
        ax.set_xlabel(what)
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("wall time per run, ms (median)")
    axes[0].legend(fontsize=6, ncol=2)
    fig.suptitle(f"{scene.name}: work against precision (freefloat, a bare Pinocchio loop and MuJoCo in one process; "
                 f"{scene.duration:g} s, law held over {scene.period * 1e3:g} ms)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def bands(points: list[Measured]) -> list[dict]:
    """Per band, the cheapest method of each package (None where none reaches it)."""
    rows = []
    for band in BANDS:
        row: dict = {"band": band}
        for package in PACKAGES:
            found = cheapest(points, package, band)  # type: ignore[arg-type]
            row[package] = None if found is None else asdict(found)
        rows.append(row)
    return rows


def lines(name: str, rows: list[dict]) -> list[str]:
    """One readable line per band."""
    def say(side, package):
        if side is None:
            return f"{package} not reached"
        return f"{side['label']} {'at most ' if side['upper_bound'] else ''}{side['wall_time'] * 1e3:.3g} ms"
    return [f"{name} error <= {row['band']:.0e}: " + "; ".join(say(row[p], p) for p in PACKAGES) for row in rows]


def main() -> None:
    args = parser(__doc__, "mechanisms")
    args.add_argument("scenes", nargs="*", default=list(MECHANISM_SCENES))
    args.add_argument("--quick", action="store_true")
    args.add_argument("--repeats", type=int, default=3)
    ns = args.parse_args()
    report: dict = {"scenes": {}}
    summary: list[str] = []
    for name in ns.scenes:
        scene = mechanism_scene(name, quick=ns.quick)
        with threadpool_limits(limits=1, user_api="blas"):
            points, reference_time = measure(scene, ns.repeats)
        rows = bands(points)
        report["scenes"][name] = {"note": scene.note, "settings": scene.settings, "repeats": ns.repeats,
                                  "reference_wall_time_s": reference_time, "bands": rows,
                                  "points": [{**asdict(p.method), "label": p.method.label,
                                              **{k: (v if math.isfinite(v) else None) for k, v in asdict(p).items()
                                                 if k != "method"}} for p in points]}
        summary += lines(name, rows)
        ns.out.mkdir(parents=True, exist_ok=True)
        chart(scene, points, ns.out / f"{name}.png")
        print(f"{name}: {len(points)} points", flush=True)
    report["summary"] = summary
    write_json(ns.out, "mechanisms", report)
    (ns.out / "summary.txt").write_text("\n".join(summary) + "\n")
    print("\n".join(summary))
    print(f"written to {ns.out}")


if __name__ == "__main__":
    main()
