"""freefloat's dynamics kernel (``cpp/kernel``): the articulated-body algorithm specialised at load
time to one robot's tree, for one state or for :data:`LANES` states of the tree at once.

The compiled loop's plant (:mod:`.compiled`, :data:`~.compiled.TREE_ABA`) takes it wherever the
tree has only joints it has: a free-flyer, a planar or no root joint; revolute (bounded, or
continuous with ``q = (cos, sin)``) and prismatic joints, on an axis of the joint frame or any unit
axis (fixed joints are merged into their parent body by Pinocchio's URDF parser). Any other joint
leaves the plant to Pinocchio's ABA. The tree is read once from the model's arrays into flat arrays
(parents, joint kinds and axes, placements, inertias), which one compiled function walks with a
code path per joint kind; nothing is compiled per robot and nothing is allocated per call.

Spatial quantities are in world axes at the root joint's origin (Featherstone's algorithm in a
frame that moves with the robot, as Pinocchio's WORLD convention at a nearer point), so the
numbers do not depend on where the robot is. Pinocchio's ``aba`` stays the reference: the kernel
equals it to 1e-12 relative on random trees (tests/test_kernel.py).

The lockstep evaluation advances :data:`LANES` states in the lanes of one SIMD register per
number: AVX2 on a CPU that has it, the platform's baseline code otherwise (:func:`isa`). Every
path rounds every product and sum on its own (no fused multiply-add), so that a state gets the same
numbers bit for bit alone or in a lane, in either instruction set (tested).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from . import _sim
from .compiled import joint_arrays

__all__ = ["LANES", "Kernel", "isa", "refusal", "set_isa"]

#: States one lockstep evaluation advances.
LANES: int = _sim.KERNEL_LANES


def refusal(model: pin.Model) -> str | None:
    """Why the kernel cannot take ``model`` (its first joint of a kind the kernel does not have), or
    None when it can."""
    try:
        _sim.Kernel(**joint_arrays(model))
    except ValueError as exc:
        return str(exc)
    return None


def isa() -> str:
    """The instruction set every kernel evaluates with: ``"avx2"`` or ``"baseline"``."""
    return _sim.Kernel.isa


def set_isa(name: str) -> None:
    """Make every kernel of the process evaluate with ``name``: ``"baseline"`` (the platform's
    baseline code, as on a CPU without AVX2) or ``"avx2"`` (the default where the CPU has it). For
    tests and benchmarks that compare the two.

    Raises:
        InvalidArgument: another name, or ``"avx2"`` on a CPU without it.
    """
    try:
        _sim.Kernel.isa = name
    except ValueError as exc:
        raise InvalidArgument(f"kernel instruction set {name!r}: {exc}") from None


class Kernel:
    """The dynamics kernel of a Pinocchio model (its numbers copied at construction).

    Vectors are in Pinocchio's order: ``q`` (nq,), ``v``, ``tau`` and accelerations (nv,); a free
    root's velocity and acceleration ``[linear; angular]`` in its own frame, as ``pin.aba`` gives
    them. External wrenches ``fext`` are Pinocchio's, per joint 1..njoints-1: ``[force; torque]``
    (6,) in the joint's frame, the torque about its origin.

    Raises:
        InvalidArgument: naming the first joint the kernel does not have (:func:`refusal`).
    """

    def __init__(self, model: pin.Model):
        try:
            self._kernel = _sim.Kernel(**joint_arrays(model))
        except ValueError as exc:
            raise InvalidArgument(f"the dynamics kernel cannot take this model: {exc}") from None
        self.nq, self.nv, self.bodies = model.nq, model.nv, model.njoints - 1

    @property
    def root(self) -> str:
        """The root joint: ``"free"``, ``"planar"`` or ``"fixed"`` (none)."""
        return self._kernel.root

    def aba(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, fext: np.ndarray | None = None) -> np.ndarray:
        """Accelerations (nv,) at ``(q, v)`` under ``tau`` and ``fext`` (njoints - 1, 6) or None."""
        return self._kernel.aba(q, v, tau, fext)

    def aba_lanes(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, fext: np.ndarray | None = None) -> np.ndarray:
        """Accelerations (LANES, nv) of :data:`LANES` states in lockstep: ``q`` (LANES, nq), ``v``
        and ``tau`` (LANES, nv), ``fext`` (LANES, njoints - 1, 6) or None."""
        return self._kernel.aba_lanes(q, v, tau, fext)

    def set_bodies(self, model: pin.Model) -> None:
        """The bodies (masses, CoMs, rotational inertias) of ``model``, a model of this tree."""
        self._kernel.set_bodies(np.array([np.r_[b.mass, b.lever, b.inertia.ravel()] for b in model.inertias[1:]]))

    def time_aba(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, calls: int) -> float:
        """Seconds per :meth:`aba` in C++ (no Python between calls), mean of ``calls`` calls."""
        return self._kernel.time_aba(q, v, tau, calls)

    def time_aba_lanes(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, calls: int) -> float:
        """Seconds per :meth:`aba_lanes` (:data:`LANES` states) in C++, mean of ``calls`` calls."""
        return self._kernel.time_aba_lanes(q, v, tau, calls)
