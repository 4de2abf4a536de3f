"""Mechanism scenes: a closed-chain mechanism from :mod:`freefloat.parallel.registry`, a platform
trajectory, a controller in platform coordinates, simulation settings.

A scene file with a ``[mechanism]`` section is one of these (see
:func:`freefloat.app.scenes.parse_scene`). Platform coordinates ``q#`` are in SI units (m, or
rad for angles), times in s. Values whose sizes depend on the mechanism (p platform
coordinates) are checked when the mechanism is loaded (:func:`freefloat.app.experiments.mechanism.prepare`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...dynamics.integrators import INTEGRATORS
from ...dynamics.plants import PLANTS
from ...errors import SceneError, did_you_mean
from ...parallel.free_base import BASES, base_problem
from ...parallel.registry import REGISTRY
from .. import controllers  # its registry is read when a scene is parsed (the module may still be loading now)
from .fields import (
    MAX_HTML_FPS,
    EntrySection,
    OutputSection,
    PluginsFirst,
    Rules,
    at_most,
    parse_entry,
    parse_section,
    reject_unknown,
    typed,
    whole_number_of,
)
from .kinds import Kinded


@dataclass(frozen=True)
class MechanismSection:
    """``[mechanism]``: registry ``name``, ``closure`` file (absolute, relative to the scene file,
    or a file in ``urdf/``) and the ``plant``'s parameter set (one of the entry's plants).

    ``base``: ``"fixed"`` (the URDF's root link is the inertial frame), ``"planar"`` (a base moving
    in the inertial xy-plane) or ``"free"`` (6 DOF; :mod:`freefloat.parallel.free_base`). A moving
    base's body: ``base_mass`` (kg), ``base_inertia`` (principal moments about its CoM, kg m^2),
    ``base_com`` (in the root link's frame, m); each defaults to the URDF root link's.
    ``gravity`` (m/s^2, inertial frame) replaces the closure file's (a satellite: zero).
    ``dynamics``: the plant (:data:`freefloat.dynamics.plants.PLANTS`): ``"coupled_chain"``
    (Orsino's subsystem coupling, fixed base only), ``"constraint_dynamics"`` (Pinocchio's, on the
    spanning tree), ``"closed_tree"`` (freefloat's constrained dynamics on the spanning tree, any
    closure kind) or ``"auto"``: coupled_chain on a fixed base, closed_tree on a moving one (there the
    compiled robot loop runs it; as accurate as constraint_dynamics, see docs/parallel.md)."""

    name: str
    closure: str
    plant: str = "nominal"
    base: str = "fixed"
    base_mass: float | None = None
    base_inertia: tuple[float, ...] | None = None
    base_com: tuple[float, ...] | None = None
    gravity: tuple[float, ...] | None = None
    dynamics: str = "auto"

    @property
    def plant_kind(self) -> str:
        """The plant ``dynamics`` resolves to (``"auto"``: see the class docstring)."""
        if self.dynamics != "auto":
            return self.dynamics
        return "coupled_chain" if self.base == "fixed" else "closed_tree"


@dataclass(frozen=True)
class PlatformStart:
    """``[initial]``: platform coordinates q# (p,) and rates (p,) at t = 0; default: the
    reference's position at t = 0, at rest. The chains assemble from the registry's guess."""

    platform: tuple[float, ...] | None = None
    platform_velocity: tuple[float, ...] | None = None


@dataclass(frozen=True)
class TrajectorySection:
    """``[trajectory]``: ``kind = "circle"``: ``q#_d(t) = center + radius (cos(rate t) e_a +
    sin(rate t) e_b)`` with ``(a, b) = axes`` (0-based platform coordinates), center (p,)."""

    center: tuple[float, ...]
    radius: float
    rate: float
    kind: str = "circle"
    axes: tuple[int, int] = (0, 1)


@dataclass(frozen=True)
class MechanismSimulation:
    """``[simulation]``: duration and step (s; efforts held over each step), Baumgarte lambda
    (1/s, eq 129), integrator (any name of ``freefloat.dynamics.integrators.INTEGRATORS``; ``rk4``
    is the classical Runge-Kutta 4, which ``rkmk4`` is on these Euclidean coordinates), and
    dopri5's tolerances."""

    duration: float
    step: float
    baumgarte: float = 100.0
    integrator: str = "rk4"
    rtol: float = 1e-10
    atol: float = 1e-12


@dataclass(frozen=True)
class MetricsSection:
    """``[metrics]``: the tracking error is reported after ``reaching_phase`` s."""

    reaching_phase: float = 0.0


@dataclass(frozen=True)
class MechanismScene(PluginsFirst, Kinded):
    """A validated mechanism scene. ``source`` is the file it came from; ``plugins`` the modules
    it imported first (files as absolute paths, or module names); ``named_kind`` its top-level
    ``kind`` (see :class:`~freefloat.app.scenes.schema.Scene`)."""

    name: str
    mechanism: MechanismSection
    trajectory: TrajectorySection
    controller: EntrySection
    simulation: MechanismSimulation
    description: str = ""
    initial: PlatformStart = PlatformStart()
    metrics: MetricsSection = MetricsSection()
    output: OutputSection = OutputSection()
    source: Path | None = None
    plugins: tuple[str, ...] = ()
    named_kind: str = ""


#: Integrator names a mechanism scene may use besides the registry's: ``rk4`` (the thesis's
#: classical RK4) is ``rkmk4``, identical on Euclidean coordinates.
ALIASES = {"rk4": "rkmk4"}

#: The scene key of each field of :func:`freefloat.parallel.free_base.base_problem`.
BASE_KEYS = {"kind": "base", "mass": "base_mass", "inertia": "base_inertia", "com": "base_com", "gravity": "gravity"}

SECTIONS = {"mechanism": MechanismSection, "initial": PlatformStart, "trajectory": TrajectorySection,
            "simulation": MechanismSimulation,
            "metrics": MetricsSection, "output": OutputSection}
RULES = Rules(
    choices={("mechanism", "name"): lambda: tuple(REGISTRY), ("mechanism", "base"): BASES,
             ("mechanism", "dynamics"): lambda: ("auto", *(name for name, spec in PLANTS.items() if spec.closed)), ("trajectory", "kind"): ("circle",),
             ("simulation", "integrator"): lambda: (*ALIASES, *INTEGRATORS)},
    positive={("mechanism", "base_mass"), ("simulation", "duration"), ("simulation", "step"), ("simulation", "rtol"), ("simulation", "atol"), ("output", "html_fps")},
    non_negative={("simulation", "baumgarte"), ("metrics", "reaching_phase"), ("trajectory", "radius")},
)


def parse_mechanism_scene(raw: dict[str, Any], source: Path | None = None) -> MechanismScene:
    """Validate a mechanism scene given as a dict (the parsed TOML).

    Raises:
        SceneError: naming the file and the key for unknown keys, wrong types, impossible values,
            a plant the mechanism does not list, a base body that is no rigid body (or given to a
            fixed base), gains missing for sliding mode or given to computed torque, and a step
            longer than the duration.
    """
    where = f"{source}: " if source else "scene: "
    reject_unknown(where, "", raw, {"name", "kind", "description", "plugins", "controller", *SECTIONS})
    missing = [s for s in ("name", "trajectory", "controller", "simulation") if s not in raw]
    if missing:
        raise SceneError(f"{where}a mechanism scene needs '{missing[0]}'")
    sections = {s: parse_section(where, s, cls, raw[s], RULES) for s, cls in SECTIONS.items() if s in raw}
    sections["controller"] = parse_entry(where, "controller", raw["controller"], controllers.serving("mechanism"),
                                         None, RULES)
    scene = MechanismScene(name=typed(where, "name", raw["name"], str),
                           named_kind=typed(where, "kind", raw.get("kind", ""), str),
                           description=typed(where, "description", raw.get("description", ""), str),
                           source=source, **sections)
    plants = REGISTRY[scene.mechanism.name].plants
    if scene.mechanism.plant not in plants:
        raise SceneError(f"{where}'mechanism.plant' is {scene.mechanism.plant!r}"
                         f"{did_you_mean(scene.mechanism.plant, plants, f'valid for {scene.mechanism.name!r}')}")
    mech = scene.mechanism
    problem = base_problem(mech.base, mech.base_mass, mech.base_inertia, mech.base_com, mech.gravity)
    if problem is not None:
        raise SceneError(f"{where}'mechanism.{BASE_KEYS[problem[0]]}' {problem[1]}")
    if mech.dynamics == "coupled_chain" and mech.base != "fixed":
        raise SceneError(f"{where}'mechanism.dynamics' is 'coupled_chain', which models a fixed base; on a "
                         f"'{mech.base}' base use 'constraint_dynamics' or 'closed_tree'")
    ctrl = scene.controller
    if ctrl.kind == "sliding_mode" and (ctrl.n is None or ctrl.T is None):
        raise SceneError(f"{where}controller.kind 'sliding_mode' needs 'controller.n' and 'controller.T'")
    if ctrl.kind == "computed_torque" and (ctrl.n is not None or ctrl.T is not None or ctrl.n_ij):
        raise SceneError(f"{where}'controller.n', 'T' and 'n_ij' are sliding-mode gains; "
                         "controller.kind 'computed_torque' does not use them")
    if scene.simulation.step > scene.simulation.duration:
        raise SceneError(f"{where}'simulation.step' ({scene.simulation.step} s) is longer than "
                         f"'simulation.duration' ({scene.simulation.duration} s)")
    whole_number_of(where, scene.simulation.duration, scene.simulation.step, "simulation.duration", "simulation.step")
    if scene.metrics.reaching_phase >= scene.simulation.duration:
        raise SceneError(f"{where}'metrics.reaching_phase' ({scene.metrics.reaching_phase} s) is not shorter than "
                         f"'simulation.duration' ({scene.simulation.duration} s): no tracking error would be measured")
    at_most(where, scene.output.html_fps, MAX_HTML_FPS, "output.html_fps")
    return scene
