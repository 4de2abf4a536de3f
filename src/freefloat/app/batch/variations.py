"""What a batch varies from run to run, and the seeded draws that vary it.

A band is ``KEY=WIDTH`` (the ``--vary`` flag): each varied number of run ``i`` is its nominal
value plus a uniform draw in ``[-WIDTH, WIDTH]`` (``mass``: a factor ``1 + U(-WIDTH, WIDTH)``).

Each run has its own seed, recorded in its row: run 0's is the batch's seed ``S``, and run
``i + 1``'s is drawn from run ``i``'s (:func:`next_seed`). A run with seed ``s`` draws key ``k``
(its place in :data:`VARIES`) from ``numpy.random.default_rng(SeedSequence(s, spawn_key=(k,)))``:
the same run gets the same values whatever the number of runs, the other keys varied, or the
process that runs it, and a row's seed given as ``--seed`` runs that row again (with ``--runs N``,
the N rows from it).
"""

from __future__ import annotations

import dataclasses
from typing import Any, NamedTuple

import numpy as np

from ...errors import InvalidArgument, did_you_mean, spelled
from ...robot.robot import Robot
from ..experiments.robot_run import joint_table
from ..scenes import MechanismScene, Scene
from .bands import MAX_RUNS, MECHANISM_KEYS, ROBOT_KEYS, VARIES, Band

#: Run seeds drawn by :func:`next_seed` are below this (whole numbers a double holds exactly, so a
#: spreadsheet reads the seed column unchanged).
SEED_LIMIT = 2**53


def next_seed(seed: int) -> int:
    """The seed of the run after the one with ``seed``: drawn from ``SeedSequence(seed)``, in
    [0, :data:`SEED_LIMIT`)."""
    return int(np.random.SeedSequence(seed).generate_state(1, np.uint64)[0]) % SEED_LIMIT


def run_seeds(seed: int, runs: int) -> list[int]:
    """The seeds of the ``runs`` runs of a batch with ``seed`` (the first is ``seed``)."""
    seeds = [seed]
    while len(seeds) < runs:
        seeds.append(next_seed(seeds[-1]))
    return seeds


class RunPlan(NamedTuple):
    """What run ``index`` of a batch runs: its own seed, its scene (initial state varied), the
    plant's mass factor per Pinocchio body (by joint name; empty: the nominal plant) and the values
    it drew, flat (``{"initial.base_angular_velocity[2]": 8.4, "mass.arm1_joint1": 1.03}``)."""

    index: int
    seed: int
    scene: Scene | MechanismScene
    masses: dict[str, float]
    varied: dict[str, float]


def check_bands(scene: Scene | MechanismScene, bands: list[Band]) -> None:
    """Refuse bands the scene cannot take.

    Raises:
        InvalidArgument: naming ``bands`` (``--vary``) and the key for a key given twice, a robot
            key on a mechanism scene (or the reverse), or ``mass`` on a capture scene or a scene
            with wheels.
    """
    seen: set[str] = set()
    vary = spelled("band", "--vary")
    for band in bands:
        if band.key in seen:
            raise InvalidArgument(f"{vary} {band.key}: given twice")
        seen.add(band.key)
        valid = MECHANISM_KEYS if isinstance(scene, MechanismScene) else ROBOT_KEYS
        if band.key not in valid:
            raise InvalidArgument(f"{vary} {band.key}: not a key of {scene.kind} scene '{scene.name}'"
                                  f"{did_you_mean(band.key, valid)}")
        if band.key == "mass" and scene.kind in ("capture", "capture_identification"):
            raise InvalidArgument(f"{vary} mass: scene '{scene.name}' is a capture scene (its robot changes at the "
                                  "grasp); mass varies joint-space and detumbling scenes")
        if band.key == "mass" and getattr(scene, "wheels", None):
            raise InvalidArgument(f"{vary} mass: scene '{scene.name}' has [[wheels]], whose momentum balance is "
                                  "computed on the nominal robot; mass varies scenes without wheels")


def plan_runs(scene: Scene | MechanismScene, nominal: Any, bands: list[Band], runs: int, seed: int) -> list[RunPlan]:
    """The ``runs`` runs of a batch, each with its seeded draws.

    Args:
        nominal: the scene prepared once (``runner.prepare``): its robot or mechanism gives the
            joints, bodies and platform coordinates to vary.

    Raises:
        InvalidArgument: for ``runs`` outside [1, :data:`MAX_RUNS`] or ``seed`` < 0 (named as the
            caller spells them), or a band the scene cannot take (see :func:`check_bands`).
    """
    if not 1 <= runs <= MAX_RUNS:
        raise InvalidArgument(f"{spelled('runs', '--runs')} must be from 1 to {MAX_RUNS}, got {runs} (the runs are "
                              "planned up front; split a bigger study into batches)")
    if seed < 0:
        raise InvalidArgument(f"{spelled('seed', '--seed')} must be >= 0, got {seed}")
    check_bands(scene, bands)
    return [_plan(scene, nominal, bands, i, s) for i, s in enumerate(run_seeds(seed, runs))]


def _plan(scene: Scene | MechanismScene, nominal: Any, bands: list[Band], index: int, seed: int) -> RunPlan:
    """Run ``index``, whose own seed is ``seed``."""
    initial: dict[str, Any] = {}
    masses: dict[str, float] = {}
    varied: dict[str, float] = {}
    for band in bands:
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(list(VARIES).index(band.key),)))
        if band.key == "mass":
            names = nominal.robot.model.names[1:]
            masses = dict(zip(names, 1.0 + rng.uniform(-band.width, band.width, len(names))))
            varied.update({f"mass.{name}": float(f) for name, f in masses.items()})
        else:
            field, values = _draw(scene, nominal, band, rng)
            initial[field] = values
            varied.update(_flat(f"initial.{field}", values))
    varied_scene = dataclasses.replace(scene, initial=dataclasses.replace(scene.initial, **initial))
    return RunPlan(index, seed, varied_scene, masses, varied)


def _draw(scene: Scene | MechanismScene, nominal: Any, band: Band, rng: np.random.Generator) -> tuple[str, Any]:
    """The scene ``[initial]`` field ``band`` varies and its drawn value (scene units)."""
    width = band.width
    if band.key in ("joint_angle", "joint_rate"):
        field = "joint_positions" if band.key == "joint_angle" else "joint_velocities"
        robot: Robot = nominal.robot
        start = joint_table(robot, getattr(scene.initial, field), 1.0, f"initial.{field}")
        offsets = rng.uniform(-width, width, robot.n_joints)
        values = {}
        for j, name in enumerate(robot.joint_names, start=2):
            first = robot.model.idx_vs[j] - robot.n_base  # one offset per joint, on all its coordinates
            values[name] = float(start[first] + offsets[first])
        return field, values
    if band.key in ("base_rate", "base_velocity"):
        field = "base_angular_velocity" if band.key == "base_rate" else "base_linear_velocity"
        planar = nominal.robot.base == "planar"
        free = [2] if planar and band.key == "base_rate" else [0, 1] if planar else [0, 1, 2]
        values = np.array(getattr(scene.initial, field), float)
        values[free] += rng.uniform(-width, width, len(free))
        return field, tuple(float(v) for v in values)
    p = nominal.setup.nominal.p
    if band.key == "platform":
        start = nominal.controller.reference(0.0) if scene.initial.platform is None else scene.initial.platform
        return "platform", tuple(float(v) for v in np.asarray(start, float) + rng.uniform(-width, width, p))
    rates = np.zeros(p) if scene.initial.platform_velocity is None else np.asarray(scene.initial.platform_velocity)
    return "platform_velocity", tuple(float(v) for v in rates + rng.uniform(-width, width, p))


def _flat(prefix: str, values: Any) -> dict[str, float]:
    """``{prefix.name: v}`` for a table, ``{prefix[i]: v}`` for a vector."""
    if isinstance(values, dict):
        return {f"{prefix}.{k}": v for k, v in values.items()}
    return {f"{prefix}[{i}]": v for i, v in enumerate(values)}
