"""What the atlas kind ``mechanism`` maps (:mod:`.mechanism_maps`): the mechanisms by name, where
their grids lie, the built-in scenes' start and mode, shared by the kind, its figures
(:mod:`.mechanism_figures`) and the simulated check (:mod:`.mechanism_reach`)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ...paths import URDF_DIR


@dataclass(frozen=True)
class MechanismSpace:
    """Where a mechanism is mapped.

    Attributes:
        coordinates: its platform coordinates' names (p,).
        ranges: each platform coordinate's range, m (p, 2).
        scene: the built-in scene whose start (held coordinates) and path the maps use.
        axes: default axes (platform coordinates).
        points: default points per axis.
        joint_ranges: range of each actuated joint, rad or m (k, 2), in ``mechanism.actuated`` order.
        starts: Newton starts per point (task space, joint space).
    """

    coordinates: tuple[str, ...]
    ranges: tuple[tuple[float, float], ...]
    scene: str
    axes: tuple[str, ...]
    points: int
    joint_ranges: tuple[tuple[float, float], ...]
    starts: tuple[int, int]


#: The mechanisms this kind maps, by name (the ``TARGET``; their models come from
#: :data:`freefloat.parallel.registry.REGISTRY`).
MECHANISMS = {
    "five_bar": MechanismSpace(("x", "y"), ((-0.33, 0.33), (-0.33, 0.33)), "five_bar_computed_torque", ("x", "y"), 61,
                               ((-np.pi, np.pi), (-np.pi, np.pi)), (12, 16)),
    "rsu_ppap": MechanismSpace(("x", "y", "z"), ((-0.33, 0.12), (-0.25, 0.25), (0.05, 0.65)), "rsu_ppap_computed_torque",
                               ("x", "z"), 31, ((-np.pi, np.pi), (-np.pi, np.pi), (-0.25, 0.25)), (32, 64)),
}


@dataclass(frozen=True)
class MechanismMapContext:
    """The target, the space mapped (``"task"`` or ``"joint"``), the mapped coordinates (indices
    into the platform coordinates or the actuated joints) and their names."""

    mechanism: str
    space: str
    axes: tuple[int, ...]
    names: tuple[str, ...]


@functools.cache
def setup_of(mechanism: str):
    """The mechanism's :class:`~freefloat.parallel.registry.MechanismSetup` (nominal plant), built
    once per process."""
    from ...parallel.registry import REGISTRY

    return REGISTRY[mechanism].build(URDF_DIR / f"{mechanism}.closure.toml", "nominal")


@functools.cache
def scene_of(mechanism: str) -> tuple[np.ndarray, np.ndarray, dict]:
    """The built-in scene's start: platform point (p,), its assembled coordinates (n_q,) and the
    scene's trajectory table."""
    from ...inputs import read_toml
    from ...paths import SCENES_DIR

    spec = read_toml(SCENES_DIR / f"{MECHANISMS[mechanism].scene}.toml", "scene")
    setup = setup_of(mechanism)
    start = np.array(spec["initial"]["platform"], float)
    return start, setup.nominal.assemble(start, setup.guess(start)), spec.get("trajectory", {})


def actuated_names(mechanism: str) -> tuple[str, ...]:
    """Names of the actuated joints, in ``mechanism.actuated`` order."""
    setup = setup_of(mechanism)
    by_coordinate = {i: setup.display.model.names[j] for j, i in setup.display.joint_coordinates.items()}
    return tuple(by_coordinate[int(i)] for i in setup.nominal.actuated)


def labels(context: MechanismMapContext) -> tuple[str, ...]:
    """The modes' names, in the order of the result's mode axis."""
    from ...parallel.maps.modes import ASSEMBLY_NAMES, working_names

    return working_names(setup_of(context.mechanism).nominal) if context.space == "task" else ASSEMBLY_NAMES


def scene_mode(context: MechanismMapContext) -> str:
    """The mode the built-in scenes run in (working mode in task space, assembly mode in joint space)."""
    from ...parallel.maps.modes import assembly_label, working_label

    mech = setup_of(context.mechanism).nominal
    q0 = scene_of(context.mechanism)[1]
    return str(working_label(mech, q0) if context.space == "task" else assembly_label(mech, q0))
