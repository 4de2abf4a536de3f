"""Fields of the environment a scene names: ``[[environment]] kind = "..."`` plus the entry's keys,
one entry of :data:`ENVIRONMENTS` per kind, built-in or a user's.

An entry (:class:`EnvironmentSpec`) carries what a scene may set (``settings``, a frozen
dataclass, checked by the scene schema with the entry's ``rules``) and builds, on the robot, a
:class:`~freefloat.dynamics.wrenches.WrenchField` (wrenches that may depend on time and state,
evaluated by the Python loop at every integrator stage) or an
:class:`~freefloat.dynamics.wrenches.ExternalWrench` (a profile on one link, which the compiled
loop applies too). An entry may also add summary keys measured from the run (``summarise``, with
their ``units``). The built-in ``wrench_profile`` is the old ``[[wrenches]]`` table (that
spelling is kept); the built-in ``orbit`` is the tidal gravity of a circular orbit
(:mod:`freefloat.space.orbit`, docs/orbit.md); the built-in ``contact`` a compliant contact between two
links (:mod:`freefloat.space.contact`, docs/contact.md); the built-in ``thrusters`` are thrusters on the
base that a thruster controller commands (:mod:`freefloat.space.thrusters`, docs/thrusters.md). A user's
module registers its own::

    ENVIRONMENTS.register(EnvironmentSpec("constant_wrench", "a constant inertial wrench on a link",
                                          ConstantWrenchSettings, ConstantWrench))
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..dynamics.wrenches import ExternalWrench, WrenchField
from ..errors import InvalidArgument
from ..registry import Registry
from ..robot.robot import Robot
from ..space.contact.field import ContactSettings, contact_field
from ..space.contact.shapes import SHAPES
from ..space.contact.summary import SUMMARY_UNITS as CONTACT_UNITS
from ..space.contact.summary import contact_summary
from ..space.orbit.field import orbit_field
from ..space.orbit.reference import OrbitSettings
from ..space.orbit.summary import SUMMARY_UNITS as ORBIT_UNITS
from ..space.orbit.summary import orbit_summary
from ..space.thrusters import SUMMARY_UNITS as THRUSTER_UNITS
from ..space.thrusters import ThrusterSet, ThrusterSettings, thruster_summary
from .scenes.fields import NO_RULES, Rules, check_settings


@dataclass(frozen=True)
class EnvironmentSpec:
    """One kind of environment field.

    Attributes:
        name: the ``[[environment]] kind`` that names it.
        description: one line for listings.
        settings: a frozen dataclass: its fields are the table's keys besides ``kind`` (defaults;
            the docstring gives each key's unit and meaning).
        build: ``build(robot, settings) -> WrenchField | ExternalWrench`` on the robot the loop
            simulates; raises :class:`~freefloat.errors.SceneError` or
            :class:`~freefloat.errors.InvalidArgument` naming what the scene got wrong.
        rules: choices and ranges of its settings, keyed ``("environment", key)``.
        summarise: None, or ``summarise(field, robot, telemetry) -> dict``: summary keys measured
            from a finished run (its :class:`~freefloat.dynamics.telemetry.Telemetry`, on the
            ``robot`` the field was built on), added to the run's ``summary.json`` and printed.
        units: the unit of each key ``summarise`` returns ("" for a pure number or a text), as an
            experiment declares its summary's (:attr:`~freefloat.app.experiments.Experiment.units`).
    """

    name: str
    description: str
    settings: type
    build: Callable[[Robot, Any], WrenchField | ExternalWrench]
    rules: Rules = NO_RULES
    summarise: Callable[[Any, Robot, Any], dict[str, Any]] | None = None
    units: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_settings("environment", self.name, self.settings)
        if not callable(self.build):
            raise InvalidArgument(f"environment '{self.name}': build must be callable, got {self.build!r}")
        if self.summarise is not None and not callable(self.summarise):
            raise InvalidArgument(f"environment '{self.name}': summarise must be callable, got {self.summarise!r}")
        if self.summarise is not None and not self.units:
            raise InvalidArgument(f"environment '{self.name}': a summarise needs the units of its keys (units)")


#: Every environment field kind by name.
ENVIRONMENTS: Registry[EnvironmentSpec] = Registry("environment")


@dataclass(frozen=True)
class WrenchProfile:
    """A wrench on ``link`` at its CoM (inertial frame, N and N m), from ``start`` to ``end`` s,
    rising linearly over ``rise`` s (the dissertation's capture model; sampled at the start of
    each control period)."""

    link: str
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)
    start: float = 0.0
    end: float = 1e9
    rise: float = 0.0


ENVIRONMENTS.register(EnvironmentSpec(
    "wrench_profile", "a wrench on a link's CoM, inertial frame, switched on and off with a linear rise",
    WrenchProfile, lambda robot, w: ExternalWrench(w.link, w.force, w.torque, w.start, w.end, w.rise),
    Rules({}, set(), {("environment", "start"), ("environment", "rise")})))

ENVIRONMENTS.register(EnvironmentSpec(
    "orbit", "tidal gravity and gravity-gradient torque of a circular orbit (altitude m or mean_motion rad/s, phase rad)",
    OrbitSettings, orbit_field, Rules({}, {("environment", "altitude"), ("environment", "mean_motion")}, set()),
    orbit_summary, ORBIT_UNITS))

ENVIRONMENTS.register(EnvironmentSpec(
    "contact", "compliant contact (Hunt-Crossley, regularised Coulomb friction) between shapes on two links (or a link and the world)",
    ContactSettings, contact_field,
    Rules({("environment", "first_shape"): tuple(SHAPES), ("environment", "second_shape"): tuple(SHAPES)},
          {("environment", "stiffness"), ("environment", "exponent"), ("environment", "slip_speed")},
          {("environment", "damping"), ("environment", "friction")}),
    contact_summary, CONTACT_UNITS))

ENVIRONMENTS.register(EnvironmentSpec(
    "thrusters", "thrusters on a free base (positions, directions, max_thrust N, min_impulse_bit N s, "
    "specific_impulse s), commanded by a thruster controller", ThrusterSettings, ThrusterSet,
    Rules({}, {("environment", "arm"), ("environment", "max_thrust"), ("environment", "specific_impulse")},
          {("environment", "min_impulse_bit")}),
    thruster_summary, THRUSTER_UNITS))


def environment_units(entries: Any) -> dict[str, str]:
    """The units of the summary keys the environment ``entries`` (a scene's ``environment``:
    sections with a ``kind``) add to a run's summary."""
    return {key: unit for e in entries for key, unit in ENVIRONMENTS[e.kind].units.items()}


__all__ = ["ENVIRONMENTS", "EnvironmentSpec", "WrenchProfile", "environment_units"]
