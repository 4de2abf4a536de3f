"""Which figures a run draws and in which formats: every figure's name (a registry with what each
shows and the runs that call for it), the lean default set, and the check of a scene's
``[output] figures`` and ``figure_formats`` or of ``freefloat simulate --figures``. Light (no
matplotlib), so scenes are checked and the command line parses without it.

``[output] figures`` is ``true`` (the default set, :data:`DEFAULT`), ``false`` or ``[]`` (none),
or a list of names from :data:`FIGURES`, ``"all"`` standing for every one. A run draws the chosen
figures its task and controller call for (:func:`called_for`: a torque-free run has no
``torques``, a robot run no ``platform_tracking``, a run with wrench profiles or fields of the
environment ``conservation_balance`` instead of ``com_drift``, a computed-torque law no
``sliding_variables``), less those whose data is identically zero (the summary's
``figures_not_drawn`` says why). ``[output] figure_formats`` lists the files each figure is
written as: ``["png"]`` by default, ``["png", "pdf"]`` adds the vector copy to print.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

from ..errors import FreefloatError, did_you_mean

#: Scene kinds of the robot runs that capture or detumble (their spin is drawn).
SPINNING = ("detumbling", "capture", "capture_identification", "two_hand_capture")
#: Scene kinds of the robot runs that track joint references throughout.
TRACKING = ("joint_space", "detumbling")
#: Scene kinds of the robot runs that fly in the fields of their ``[[environment]]`` (a one-hand
#: capture: in an orbit).
IN_FIELDS = (*TRACKING, "capture")


class Figure(NamedTuple):
    """A figure of the registry.

    Attributes:
        shows: what it draws, for the docs and error messages.
        called_for: whether a run of a scene (a ``Scene`` or a ``MechanismScene``) draws it.
    """

    shows: str
    called_for: Callable[[Any], bool]


def _robot(test: Callable[[Any], bool]) -> Callable[[Any], bool]:
    """``test`` on robot scenes; False on mechanism scenes."""
    return lambda scene: scene.kind != "mechanism" and test(scene)


def _mechanism(test: Callable[[Any], bool]) -> Callable[[Any], bool]:
    """``test`` on mechanism scenes; False on robot scenes."""
    return lambda scene: scene.kind == "mechanism" and test(scene)


#: Every figure a run can draw, by file stem: what it shows and the runs that call for it.
FIGURES: dict[str, Figure] = {
    "joint_errors": Figure("joint tracking error per arm (controlled joint-space and detumbling runs)",
                           _robot(lambda s: s.kind in TRACKING and s.controller.kind != "none")),
    "approach_joint_errors": Figure("joint tracking error of a planned capture's approach, against its plan",
                                    _robot(lambda s: s.approach is not None)),
    "torques": Figure("joint torques per arm (controlled runs)", _robot(lambda s: s.controller.kind != "none")),
    "base_trajectory": Figure("base CoM position, attitude and path", _robot(lambda s: True)),
    "end_effector_paths": Figure("the robot at start and end with the end-effector and base CoM paths",
                                 _robot(lambda s: True)),
    "end_effector_displacement": Figure("each end-effector's displacement from its start", _robot(lambda s: True)),
    "com_drift": Figure("CoM and momentum drift from their free motion (runs without external wrenches or fields)",
                        _robot(lambda s: not s.environment or s.kind not in IN_FIELDS)),
    "conservation_balance": Figure("momentum and energy against what the external wrenches and fields applied",
                                   _robot(lambda s: bool(s.environment) and s.kind in IN_FIELDS)),
    "angular_rates": Figure("base and end-effector spin decaying (capture and detumbling runs)",
                            _robot(lambda s: s.kind in SPINNING)),
    "angular_momentum": Figure("L(t) about the CoM and the origin (capture and detumbling runs)",
                               _robot(lambda s: s.kind in SPINNING)),
    "closed_loop": Figure("loop closure drift (runs with [[closures]]) and the two-hand capture's squeeze",
                          _robot(lambda s: bool(s.closures) or s.kind == "two_hand_capture")),
    "reaction_wheels": Figure("reaction wheels' stored momentum and torque against their limits (runs with [[wheels]])",
                              _robot(lambda s: bool(s.wheels))),
    "thrusters": Figure("thrust per thruster and propellant burnt (runs with thrusters)",
                        _robot(lambda s: any(e.kind == "thrusters" for e in s.environment))),
    "relative_orbit": Figure("the base (and a capture's target) in the LVLH frame: the relative orbit (runs in orbit)",
                             _robot(lambda s: any(e.kind == "orbit" for e in s.environment))),
    "contact": Figure("contact force and penetration over time (capture-by-contact runs)",
                      _robot(lambda s: s.kind == "contact_capture")),
    "identification": Figure("the captured target's mass, CoM and inertia identified, with 95 % intervals, against "
                             "the truth (captures with [identification])",
                             _robot(lambda s: s.kind == "capture_identification")),
    "platform_tracking": Figure("mechanism platform path and tracking error", _mechanism(lambda s: True)),
    "efforts": Figure("mechanism actuator efforts", _mechanism(lambda s: True)),
    "loop_closure_drift": Figure("mechanism loop closure drift", _mechanism(lambda s: True)),
    "sliding_variables": Figure("the sliding-mode law's sliding variables",
                                _mechanism(lambda s: s.controller.kind == "sliding_mode")),
    "base_attitude": Figure("a moving-base mechanism's base rotation and displacement",
                            _mechanism(lambda s: s.mechanism.base != "fixed")),
    "momentum": Figure("a moving-base mechanism's momentum drift", _mechanism(lambda s: s.mechanism.base != "fixed")),
}
#: The lean set a scene draws unless it says otherwise: each kind of run's own figures, less the
#: robot's motion (base trajectory, end-effector paths and displacement), which the page shows.
DEFAULT = ("joint_errors", "approach_joint_errors", "torques", "com_drift", "conservation_balance", "angular_rates", "angular_momentum",
           "closed_loop", "reaction_wheels", "thrusters", "relative_orbit", "contact", "identification", "platform_tracking",
           "efforts",
           "loop_closure_drift", "sliding_variables",
           "base_attitude", "momentum")
#: The name that stands for every figure.
ALL = "all"
#: Formats a figure can be written in: PNG to look at, PDF (vector) to print.
FORMATS = ("png", "pdf")

#: ``[output] figures``: True (the default set), False (none), or names.
FigureChoice = bool | tuple[str, ...]
#: ``[output] figure_formats``: one or more of :data:`FORMATS`.
FigureFormats = tuple[str, ...]


def selected(choice: FigureChoice) -> frozenset[str]:
    """The figure names ``choice`` (a checked :data:`FigureChoice`) selects."""
    if choice is True:
        return frozenset(DEFAULT)
    if not choice:
        return frozenset()
    return frozenset(FIGURES) if ALL in choice else frozenset(choice)


def called_for(scene: Any) -> tuple[str, ...]:
    """The figures a run of ``scene`` (a ``Scene`` or a ``MechanismScene``) draws when chosen, in
    registry order: those its kind, task, controller, wrenches, closures, wheels and base call
    for (each :class:`Figure`'s ``called_for``)."""
    return tuple(name for name, figure in FIGURES.items() if figure.called_for(scene))


def drawn(scene: Any) -> tuple[str, ...]:
    """The figures a run of ``scene`` draws, in registry order: chosen by its ``[output]
    figures`` and called for by its task (:func:`called_for`); a run leaves out those whose
    data is identically zero, naming them in its summary's ``figures_not_drawn``."""
    chosen = selected(scene.output.figures)
    return tuple(name for name in called_for(scene) if name in chosen)


def check_choice(value: object, where: str, error: type[FreefloatError]) -> FigureChoice:
    """``value`` as a :data:`FigureChoice`: a bool, or a list of names from :data:`FIGURES` (or
    ``"all"``). Raises ``error`` naming ``where`` (e.g. ``"scene.toml: 'output.figures'"``) and
    listing the choices for anything else."""
    if isinstance(value, bool):
        return value
    if not isinstance(value, (list, tuple)) or not all(isinstance(x, str) for x in value):
        raise error(f"{where} must be true, false or a list of figure names, got {value!r}")
    unknown = [x for x in value if x not in FIGURES and x != ALL]
    if unknown:
        raise error(f"{where}: unknown figure '{unknown[0]}'{did_you_mean(unknown[0], (ALL, *FIGURES), full_list='docs/commands.md')}")
    return tuple(dict.fromkeys(value))


def check_formats(value: object, where: str, error: type[FreefloatError]) -> FigureFormats:
    """``value`` as :data:`FigureFormats`: a non-empty list from :data:`FORMATS`; else ``error``
    naming ``where``."""
    if (not isinstance(value, (list, tuple)) or not value or not all(isinstance(x, str) for x in value)
            or any(x not in FORMATS for x in value)):
        raise error(f"{where} must be a non-empty list of {', '.join(FORMATS)}, got {value!r}")
    return tuple(dict.fromkeys(value))


def parse_names(text: str, where: str, error: type[FreefloatError]) -> FigureChoice:
    """The comma-separated names of a command-line option (``joint_errors,torques``, ``all``; an
    empty text: none) as a checked :data:`FigureChoice`."""
    return check_choice([name.strip() for name in text.split(",") if name.strip()], where, error)
