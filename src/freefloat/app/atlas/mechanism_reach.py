"""Mapped mechanism points reached by a simulated motion: the plant (Orsino's coupled chains,
:class:`~freefloat.dynamics.plants.CoupledChainPlant` on the one loop, RKMK4) driven by computed
torque in platform coordinates (eq 190) along a quintic line from the built-in scenes' start to a
map point in the scenes' working mode; where it arrives, and in which mode, is compared with the
map (:mod:`freefloat.parallel.maps`). Shared by tests/test_parallel_maps.py and
scripts/mechanism_reach_check.py."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...parallel.closed_loop import track
from ...parallel.maps.jacobians import closure, partition, singularity
from ...parallel.maps.modes import working_label, working_modes
from ...parallel.sliding_mode import PlatformControl
from ...space.control import QuinticTrajectory
from .mechanism_targets import MECHANISMS, scene_of, setup_of

#: The motion: a quintic line of MOVE_S s, then SETTLE_S s held; step STEP s; eq 190's lambda.
MOVE_S, SETTLE_S, STEP, LAM = 0.3, 0.2, 1e-3, 40.0
#: Points checked along a candidate line (the scenes' mode must exist at each, on one side of type II).
LINE_POINTS = 25


class Arrival(NamedTuple):
    """Where a simulated motion ended.

    Attributes:
        q: the plant's coordinates at the end (n_q,).
        mode: its working mode's name.
        status: the run's status (``"completed"`` unless it diverged).
    """

    q: np.ndarray
    mode: str
    status: str


def drive_to(mechanism: str, target: np.ndarray) -> Arrival:
    """Simulate the motion from the scenes' start to the platform point ``target`` (p,), m."""
    mech = setup_of(mechanism).nominal
    start, q0, _ = scene_of(mechanism)
    control = PlatformControl(mech, QuinticTrajectory(start, np.asarray(target, float), MOVE_S), LAM)
    result = track(mech, control, q0, MOVE_S + SETTLE_S, STEP, None, integrator="rkmk4")
    q = result.telemetry.q[-1]
    return Arrival(q, str(working_label(mech, q)), result.status)


def targets(mechanism: str, count: int, seed: int = 0, half: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``count`` platform points (count, p), m, drawn uniformly in the map's box (or within
    ``half`` m of the scenes' start) and kept when the scenes' working mode exists all along the
    line from the start with the direct block's sign unchanged (no type II crossing); and the
    map's solution there in that mode (count, n_q)."""
    mech = setup_of(mechanism).nominal
    part = partition(mech)
    start, q0, _ = scene_of(mechanism)
    mode = str(working_label(mech, q0))
    side = np.sign(singularity(part, closure(mech, q0)[1]).direct)
    box = np.array(MECHANISMS[mechanism].ranges) if half is None else np.column_stack((start - half, start + half))
    rng = np.random.default_rng(seed)
    kept, solutions = [], []
    while len(kept) < count:
        target = rng.uniform(box[:, 0], box[:, 1])
        line = start + np.linspace(0.0, 1.0, LINE_POINTS)[:, None] * (target - start)
        q, found = working_modes(mech, line, count=MECHANISMS[mechanism].starts[0]).mode(mode)
        if found.all() and np.all(np.sign(singularity(part, closure(mech, q)[1]).direct) == side):
            kept.append(target)
            solutions.append(q[-1])
    return np.array(kept), np.array(solutions)
