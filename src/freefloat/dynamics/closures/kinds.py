"""Loop-closure kinds, one registry: which relative motions of two frames a closure stops.

Rows are taken from the relative motion of frame 2 with respect to frame 1, in frame 1's axes:
three translation rows (the two origins coincide) and three rotation rows (the relative angular
velocity). A revolute closure frees the rotation about frame 1's z axis, the hinge; Pinocchio has
point (``CONTACT_3D``) and weld (``CONTACT_6D``) closures but no revolute one (its issue #2729).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ClosureKind:
    """One kind of loop closure.

    Attributes:
        name: registry name (closure tables' ``kind``).
        description: one line.
        rotation_rows: rows of the relative angular velocity (frame 1 axes) that are stopped:
            ``()`` point, ``(0, 1)`` revolute about z, ``(0, 1, 2)`` weld.
    """

    name: str
    description: str
    rotation_rows: tuple[int, ...]

    @property
    def size(self) -> int:
        """Constraint rows: 3 + the stopped rotation rows (3 point, 5 revolute, 6 weld)."""
        return 3 + len(self.rotation_rows)


#: Registry: name -> :class:`ClosureKind`.
KINDS: dict[str, ClosureKind] = {kind.name: kind for kind in (
    ClosureKind("point", "the two frame origins coincide (3 rows; a spherical joint)", ()),
    ClosureKind("revolute", "origins coincide and the z axes align (5 rows; a hinge about frame 1's z)", (0, 1)),
    ClosureKind("weld", "the two frames coincide (6 rows; a rigid grasp)", (0, 1, 2)),
)}

#: Other names a closure table may use: ``frame`` (the mechanisms' closure files) is a weld.
ALIASES = {"frame": "weld"}


def closure_kind(name: str) -> ClosureKind | None:
    """The kind called ``name`` (or one of its :data:`ALIASES`), None when there is none."""
    return KINDS.get(ALIASES.get(name, name))
