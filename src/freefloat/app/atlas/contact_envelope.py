"""Atlas kind ``contact_envelope``: where a capture by contact latches, rebounds or neither, by the
target's approach speed and the contact's stiffness (issue 39 item 3; docs/contact.md).

``freefloat atlas contact_envelope SCENE`` takes a capture-by-contact scene with a ``[latch]``
(``contact_capture``, ``contact_rebound_fast`` or a file: :mod:`..experiments.contact_capture`)
and runs it at each point of a plane: the approach speed (m/s, along the scene's target velocity,
from half the latch speed to ten times it) by the stiffness (N/m^n, a log10 axis from a tenth of
the scene's to a hundred times it, the damping scaled with it so that c / k stays). Each point is a
short simulation (:func:`~..experiments.contact_capture.capture` with ``until_decided``: it ends
at the latch, or once the shapes are apart and separating after touching, or at the scene's
duration). The map holds, per point, the outcome (0 latched, 1 rebound, 2 neither: no latch nor
separation within the duration), the peak contact force (N) and penetration (m) seen at a
period end, and the latch time (s, NaN without a latch). ``--grid`` points per axis (default 3).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import SceneError, SimulationDiverged
from .grid import Axis, Grid
from .kinds import Options
from .outcome_maps import cell_extent, outcome_panel, write_map

OPTIONS = frozenset({"grid"})
#: The unit of each summary key that has one (the terminal prints it).
SUMMARY_UNITS = {"fastest_latched": "m/s", "slowest_rebound": "m/s", "peak_force_max": "N", "max_penetration_max": "m"}
#: Points per axis of the default grid.
POINTS = 3
#: The speed axis's ends, times the scene's latch speed.
SPEEDS = (0.5, 10.0)
#: The stiffness axis's ends, times the scene's stiffness.
STIFFNESSES = (0.1, 100.0)
#: Fewest points per chunk (the engine's contract): a point is a simulation of about a second, so a
#: chunk is one point and an interrupt loses no more.
MIN_CHUNK = 1


@dataclass(frozen=True)
class ContactEnvelopeContext:
    """The scene (as named on the command line), the speed axis's ends (m/s) and the stiffness
    axis's ends (log10 of N/m^n)."""

    scene: str
    speeds: tuple[float, float]
    log_stiffnesses: tuple[float, float]


@functools.lru_cache(maxsize=4)
def _scene(name: str):
    """The scene ``name`` names, once per process.

    Raises:
        SceneError: for a scene that is not a capture by contact with a ``[latch]``.
    """
    from ..experiments import EXPERIMENTS  # noqa: F401  (registers the kinds the scene's kind is read from)
    from ..scenes import find_scene

    scene = find_scene(name)
    if getattr(scene, "sections", {}).get("latch") is None or scene.kind != "contact_capture":
        raise SceneError(f"atlas contact_envelope: scene '{scene.name}' is not a capture by contact with a [latch] "
                         "([free_target], e.g. contact_capture)")
    return scene


def prepare(target: str, options: Options) -> ContactEnvelopeContext:
    """Check the scene (a capture by contact with a ``[latch]``) and set the axes' ends from its
    latch speed and stiffness.

    Raises:
        SceneError: for a scene that is not one.
    """
    from ..experiments.contact_capture import prepare as prepare_scene

    scene = _scene(target)
    stiffness = prepare_scene(scene).settings.stiffness
    speed = scene.sections["latch"].speed
    return ContactEnvelopeContext(target, (SPEEDS[0] * speed, SPEEDS[1] * speed),
                                  (math.log10(STIFFNESSES[0] * stiffness), math.log10(STIFFNESSES[1] * stiffness)))


def grid(context: ContactEnvelopeContext, options: Options) -> Grid:
    """Approach speed by log10 stiffness, ``--grid`` points each (default :data:`POINTS`)."""
    n = options.grid or POINTS
    return Grid((Axis("approach_speed", *context.speeds, n, "m/s"),
                 Axis("log10_stiffness", *context.log_stiffnesses, n, "log10(N/m^n)")))


def evaluate(context: ContactEnvelopeContext, points: np.ndarray) -> dict[str, np.ndarray]:
    """Per point (m, 2) of (speed m/s, log10 stiffness): ``outcome`` (m,) int (index into
    :data:`~..experiments.contact_capture.OUTCOMES`), ``peak_force`` (N), ``max_penetration`` (m),
    ``latch_time`` (s, NaN without a latch) (m,).

    Raises:
        KeyboardInterrupt: a run interrupted (Ctrl-C, SIGTERM: the engine keeps the chunks journaled before).
        SimulationDiverged: a run that diverged, naming its point.
    """
    from ..experiments.contact_capture import OUTCOMES, at_approach, capture, contact_rows
    from ..experiments.contact_capture import prepare as prepare_scene

    scene = _scene(context.scene)
    out = {"outcome": np.zeros(len(points), int),
           **{key: np.full(len(points), np.nan) for key in ("peak_force", "max_penetration", "latch_time")}}
    for k, (speed, log_stiffness) in enumerate(points):
        setup = prepare_scene(at_approach(scene, float(speed), 10.0 ** float(log_stiffness)))
        done = capture(setup, until_decided=True)
        if done.result.status == "interrupted":  # Ctrl-C or SIGTERM: the chunk is not finished, nothing journaled
            raise KeyboardInterrupt
        if done.result.status == "diverged":
            raise SimulationDiverged(f"atlas contact_envelope {context.scene}: the run at {speed:g} m/s, stiffness "
                                     f"{10.0 ** log_stiffness:g} diverged: {done.result.message}")
        rows = contact_rows(setup.field, done.result.telemetry, done.latch_time)
        out["outcome"][k] = OUTCOMES.index(done.outcome)
        out["peak_force"][k], out["max_penetration"][k] = rows.force.max(), rows.depth.max()
        out["latch_time"][k] = np.nan if done.latch_time is None else done.latch_time
    return out


def summarise(context: ContactEnvelopeContext, grid: Grid, result: dict[str, np.ndarray]) -> dict:
    """The scene, the count of each outcome, the fastest latched and the slowest rebound approach
    (m/s), and the largest peak force (N) and penetration (m) over the map."""
    from ..experiments.contact_capture import OUTCOMES

    speeds = grid.points()[:, 0]
    outcome = result["outcome"]
    latched, rebound = outcome == OUTCOMES.index("latched"), outcome == OUTCOMES.index("rebound")
    return {"scene": _scene(context.scene).name, "points": grid.size,
            **{name: int((outcome == i).sum()) for i, name in enumerate(OUTCOMES)},
            "fastest_latched": float(speeds[latched].max()) if latched.any() else None,
            "slowest_rebound": float(speeds[rebound].min()) if rebound.any() else None,
            "peak_force_max": float(np.nanmax(result["peak_force"])),
            "max_penetration_max": float(np.nanmax(result["max_penetration"]))}


def figures(context: ContactEnvelopeContext, grid: Grid, result: dict[str, np.ndarray], out: Path) -> list[Path]:
    """``contact_envelope.png``: the outcome (latched, rebound, neither) and the peak contact force
    (log10 N) over approach speed and log10 stiffness."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..experiments.contact_capture import OUTCOMES

    a, b = grid.axes
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    outcome_panel(fig, axes[0], grid, result["outcome"], OUTCOMES, ["#2a9d8f", "#e76f51", "#8d99ae"],
                  "outcome of the contact", "auto")
    force = np.log10(np.maximum(result["peak_force"], 1e-16)).reshape(grid.shape).T
    image = axes[1].imshow(np.ma.masked_invalid(force), origin="lower", extent=cell_extent(grid), aspect="auto",
                           cmap="viridis")
    fig.colorbar(image, ax=axes[1], shrink=0.8)
    axes[1].set_title("log10 peak contact force (N)", fontsize=9)
    for ax in axes:
        ax.set_xlabel(f"approach speed ({a.unit})")
        ax.set_ylabel(f"stiffness, {b.unit}")
    return write_map(fig, f"contact envelope: {context.scene}", out / "contact_envelope.png")
