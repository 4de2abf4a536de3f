"""Which figures a run draws and in which formats: every figure's name (a registry with what each
shows), the lean default set, and the check of a scene's ``[output] figures`` and
``figure_formats`` or of ``freefloat simulate --figures``. Light (no matplotlib), so scenes are
checked and the command line parses without it.

``[output] figures`` is ``true`` (the default set, :data:`DEFAULT`), ``false`` or ``[]`` (none),
or a list of names from :data:`FIGURES`, ``"all"`` standing for every one. A run draws the chosen
figures it has (a torque-free run has no ``torques``, a robot run no ``platform_tracking``).
``[output] figure_formats`` lists the files each figure is written as: ``["png"]`` by default,
``["png", "pdf"]`` adds the vector copy to print.
"""

from __future__ import annotations

from typing import Union

from ..errors import FreefloatError, did_you_mean

#: Every figure a run can draw, by file stem: what it shows.
FIGURES: dict[str, str] = {
    "joint_errors": "joint tracking error per arm (runs with joint references)",
    "approach_joint_errors": "joint tracking error of a planned capture's approach, against its plan",
    "torques": "joint torques per arm",
    "base_trajectory": "base CoM position, attitude and path",
    "end_effector_paths": "the robot at start and end with the end-effector and base CoM paths",
    "end_effector_displacement": "each end-effector's displacement from its start",
    "com_drift": "CoM and momentum drift from their free motion (runs without external wrenches)",
    "conservation_balance": "momentum and energy against what the external wrenches applied",
    "angular_rates": "base and end-effector spin decaying (capture and detumbling runs)",
    "angular_momentum": "L(t) about the CoM and the origin (capture and detumbling runs)",
    "closed_loop": "loop closure drift (and the two-hand capture's squeeze)",
    "reaction_wheels": "reaction wheels' stored momentum and torque against their limits (runs with [[wheels]])",
    "platform_tracking": "mechanism platform path and tracking error",
    "efforts": "mechanism actuator efforts",
    "loop_closure_drift": "mechanism loop closure drift",
    "sliding_variables": "mechanism law's sliding variables",
    "base_attitude": "a moving-base mechanism's base rotation and displacement",
    "momentum": "a moving-base mechanism's momentum drift",
}
#: The lean set a scene draws unless it says otherwise: each kind of run's own figures, less the
#: robot's motion (base trajectory, end-effector paths and displacement), which the page shows.
DEFAULT = ("joint_errors", "approach_joint_errors", "torques", "com_drift", "conservation_balance", "angular_rates", "angular_momentum",
           "closed_loop", "reaction_wheels", "platform_tracking", "efforts", "loop_closure_drift", "sliding_variables",
           "base_attitude", "momentum")
#: The name that stands for every figure.
ALL = "all"
#: Formats a figure can be written in: PNG to look at, PDF (vector) to print.
FORMATS = ("png", "pdf")

#: ``[output] figures``: True (the default set), False (none), or names.
FigureChoice = Union[bool, tuple[str, ...]]
#: ``[output] figure_formats``: one or more of :data:`FORMATS`.
FigureFormats = tuple[str, ...]


def selected(choice: FigureChoice) -> frozenset[str]:
    """The figure names ``choice`` (a checked :data:`FigureChoice`) selects."""
    if choice is True:
        return frozenset(DEFAULT)
    if not choice:
        return frozenset()
    return frozenset(FIGURES) if ALL in choice else frozenset(choice)


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
