"""The kinds of map of ``freefloat atlas KIND``: one registry of objects, :data:`KINDS`.

Each :class:`AtlasKind` names the module that computes it (imported when the kind runs, so the
command line's help stays cheap); the module's contract is in the package's docstring. A new
kind is one module plus one ``KINDS.register`` line at the end of this file.
"""

from __future__ import annotations

import dataclasses
import importlib
from dataclasses import dataclass
from types import ModuleType

from ...errors import InvalidArgument, spelled
from ...registry import Registry


@dataclass(frozen=True)
class Options:
    """What the command line hands every kind; ``None`` is "the kind's default". A kind reads the
    fields named in its module's ``OPTIONS``.

    Attributes:
        grid: points per grid axis.
        axes: names of the grid's axes (joints of the mapped arm, ...), in grid order.
        end_effector: the end-effector mapped (a frame name of the robot).
        momentum: the system's momentum [P; L about the system CoM], inertial frame, N s and
            N m s (6,), or a planar [Px, Py, Lz] (3,).
        tolerance: the kind's threshold (e.g. sigma_min / sigma_max below which a Jacobian counts
            as singular).
        base: floating base of a robot loaded by name or file: ``"free"`` or ``"planar"``.
        posture: ``(joint, value)`` pairs overriding the held joints' reference positions (deg
            for a revolute joint, m for a prismatic one).
    """

    grid: int | None = None
    axes: tuple[str, ...] | None = None
    end_effector: str | None = None
    momentum: tuple[float, ...] | None = None
    tolerance: float | None = None
    base: str | None = None
    posture: tuple[tuple[str, float], ...] | None = None

    def __post_init__(self) -> None:
        if self.grid is not None and (isinstance(self.grid, bool) or not isinstance(self.grid, int) or self.grid < 1):
            raise InvalidArgument(f"{spelled('grid', '--grid')} (points per axis) must be an integer >= 1, "
                                  f"got {self.grid!r}")

    def given(self) -> list[str]:
        """Names of the fields set (not None)."""
        return [f.name for f in dataclasses.fields(self) if getattr(self, f.name) is not None]

    def as_dict(self) -> dict:
        """The fields as JSON-able values (for the journal and the summary)."""
        return {k: [list(x) if isinstance(x, tuple) else x for x in v] if isinstance(v, tuple) else v
                for k, v in dataclasses.asdict(self).items()}


@dataclass(frozen=True)
class AtlasKind:
    """One kind of map.

    Attributes:
        name: the ``KIND`` argument of ``freefloat atlas``.
        help: one line for the command's help.
        target: what ``TARGET`` names for it (one line for the help).
        module: its module, relative to this package (or absolute).
    """

    name: str
    help: str
    target: str
    module: str

    def load(self) -> ModuleType:
        """The kind's module (imported now)."""
        return importlib.import_module(self.module, __package__)

    def check_options(self, options: Options) -> ModuleType:
        """The kind's module, once every option given is one it reads.

        Raises:
            InvalidArgument: naming the options it does not take and those it does.
        """
        module = self.load()
        extra = [name for name in options.given() if name not in module.OPTIONS]
        if extra:
            flags = ", ".join("--" + name.replace("_", "-") for name in extra)
            takes = ", ".join("--" + name.replace("_", "-") for name in sorted(module.OPTIONS)) or "none"
            raise InvalidArgument(f"atlas kind '{self.name}' does not take {flags} (it takes: {takes})")
        return module


#: Every kind, by name, in the order the command's help lists them.
KINDS: Registry[AtlasKind] = Registry("atlas kind")

KINDS.register(AtlasKind("workspace", "free-floating workspace of an end-effector (reachable, path-independent and "
                   "path-dependent), beside the fixed-base one", "a robot: name or URDF file", ".workspace"))
KINDS.register(AtlasKind("singularities", "dynamic singularities (rank loss of J*) against the fixed-base ones of Jm, "
                   "condition number and manipulability of both", "a robot: name or URDF file", ".singularities"))
KINDS.register(AtlasKind("feasibility", "where the worst-case sliding-mode gain design has a solution (eq 161) over the "
                   "uncertainty set", "a closed-chain mechanism: five_bar or rsu_ppap", ".feasibility"))
KINDS.register(AtlasKind("mechanism", "a closed-chain mechanism's workspace, type I and type II singularity loci and its "
                   "working / assembly modes", "a closed-chain mechanism: five_bar or rsu_ppap", ".mechanism_maps"))
KINDS.register(AtlasKind("capture_envelope", "where a planned capture scene's target can be grasped within the limits "
                   "(meeting points over a plane of reach offsets, each planned and checked)",
                   "a one-hand capture scene with [approach]: name or file", ".capture_envelope"))
KINDS.register(AtlasKind("contact_envelope", "where a capture by contact latches, rebounds or neither, by approach speed "
                   "and contact stiffness (a short simulation each)", "a capture-by-contact scene with [latch]: name or "
                   "file", ".contact_envelope"))
