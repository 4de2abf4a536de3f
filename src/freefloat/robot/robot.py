"""The loaded robot: a Pinocchio model with a floating root joint plus the structure around it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

#: Number of base degrees of freedom per floating-joint kind.
BASE_DOFS = {"free": 6, "planar": 3}


@dataclass(frozen=True)
class Arm:
    """One kinematic chain from the base to an end-effector.

    Attributes:
        end_effector: name of the end-effector frame (the URDF link name).
        joints: names of the movable joints from the base outwards.
        v_indices: their indices in Pinocchio's velocity vector ``v`` (shape (m,)).
    """

    end_effector: str
    joints: tuple[str, ...]
    v_indices: np.ndarray


@dataclass(frozen=True, eq=False)
class Robot:
    """A free-floating robot loaded from a URDF (hashed and compared by identity).

    Attributes:
        model: Pinocchio model; joint 1 is the floating root joint (free-flyer or planar).
        visual_model: Pinocchio visual geometry, or None when it was not built or a mesh file
            could not be read.
        urdf_path: the file it was loaded from.
        base_link: name of the URDF root link.
        base: floating-joint kind, ``"free"`` (SE(3), 6 DOF) or ``"planar"`` (SE(2), 3 DOF).
        base_com: base-link centre of mass in the base-link frame, m (shape (3,)).
        base_com_rotation: rotation from the base CoM frame (URDF ``<inertial>`` origin) to the
            base-link frame (shape (3, 3)). The base reference frame of the dissertation and of
            SPART is this CoM frame.
        end_effectors: end-effector frame names, in the order used by every stacked quantity.
        arms: one :class:`Arm` per end-effector, same order.
        link_coms: CoM of every URDF link in its own link frame, m (3,) each.
        warnings: what the loader had to say about the file, to check (also emitted as
            :class:`~freefloat.errors.FreefloatWarning`).
        notes: what the loader states about the file that is so on purpose (freefloat's own
            robots' inertias; also emitted as :class:`~freefloat.errors.FreefloatNote`).
        missing_meshes: (link, filename as written) of each visual mesh whose file was not
            found; :attr:`visual_model` lacks those visuals, and a page draws those links as sticks.
    """

    model: pin.Model
    visual_model: pin.GeometryModel | None
    urdf_path: Path
    base_link: str
    base: str
    base_com: np.ndarray
    base_com_rotation: np.ndarray
    end_effectors: tuple[str, ...]
    arms: tuple[Arm, ...]
    link_coms: dict[str, np.ndarray]
    warnings: tuple[str, ...] = field(default=())
    notes: tuple[str, ...] = field(default=())
    missing_meshes: tuple[tuple[str, str], ...] = field(default=())

    @property
    def n_base(self) -> int:
        """Number of base velocity coordinates (6 free, 3 planar)."""
        return BASE_DOFS[self.base]

    @property
    def n_joints(self) -> int:
        """Number of actuated joint velocity coordinates (nv minus the base)."""
        return self.model.nv - self.n_base

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of the actuated joints, in Pinocchio's order (joint 2 onwards)."""
        return tuple(self.model.names[2:])

    @property
    def end_effector_frame_ids(self) -> tuple[int, ...]:
        """Pinocchio frame ids of :attr:`end_effectors`."""
        return tuple(self.model.getFrameId(name) for name in self.end_effectors)

    def neutral(self) -> np.ndarray:
        """Neutral configuration q (shape (nq,)): base at the origin, all joints at zero."""
        return pin.neutral(self.model)
