"""The GJM quantities of a robot at one state (dissertation secs 3.2-3.4)."""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from ...arguments import MAX_MAGNITUDE
from ...errors import UnknownName
from ...robot.conventions import base_state, cross3
from ...robot.joints import JointCoordinates
from ...robot.robot import Robot
from ...robot.state import UNIT_TOLERANCE, check_state
from .._core import GJMCore
from .kinematics import BodyKinematics, TreeStructure, forward_kinematics
from .matrices import end_effector_jacobians, end_effector_points, inertia_matrices, point_jacobians

#: Implementations of :meth:`GJM.compute`: the compiled core (default) and the numpy reference.
BACKENDS = ("compiled", "numpy")


class GJMState(NamedTuple):
    """GJM matrices and momenta at one state. ``n`` actuated joints, ``k`` end-effectors.

    Attributes:
        H0: base inertia matrix (6, 6), eq 23, for ``x0dot = [v0; w0]`` (base CoM, inertial).
        H0m: coupling inertia matrix (6, n), eq 22.
        Hm: manipulator inertia matrix (n, n), eq 19.
        Hstar: generalized inertia ``Hm - H0m^T H0^-1 H0m`` (n, n), eq 92.
        J0: base Jacobian ``-H0^-1 H0m`` (6, n), eq 71: ``x0dot = J0 qdot`` at zero momentum.
        Jm: end-effector Jacobians for a fixed base (6k, n), eq 76; one block [v_E; w_E] per
            end-effector in ``robot.end_effectors`` order, at the frame origin, inertial frame.
        J0E: base-to-end-effector maps (6k, 6), eq 78: ``[v_E; w_E] = J0E x0dot`` for each
            end-effector frame origin, from the base twist [v0; w0] of the base CoM, inertial frame.
        Jstar: generalized Jacobian ``Jm - J0E H0^-1 H0m`` (6k, n), eqs 82 and 89 (E-GJM).
        momentum_base: ``M = H0 x0dot + H0m qdot = [P; L about the base CoM]`` (6,), eq 69.
        momentum_origin: ``[P; L about the inertial origin] = [P; L_base + r0 x P]`` (6,).
        x0dot: the base twist [v0; w0] (6,).
        qdot: joint rates (n,).
        ee_position: end-effector frame origins (k, 3), inertial frame.
        kinematics: the body kinematics the matrices were built from.
    """

    H0: np.ndarray
    H0m: np.ndarray
    Hm: np.ndarray
    Hstar: np.ndarray
    J0: np.ndarray
    Jm: np.ndarray
    J0E: np.ndarray
    Jstar: np.ndarray
    momentum_base: np.ndarray
    momentum_origin: np.ndarray
    x0dot: np.ndarray
    qdot: np.ndarray
    ee_position: np.ndarray
    kinematics: BodyKinematics

    def end_effector_velocity(self) -> np.ndarray:
        """``x_Edot = J* qdot + J0E H0^-1 M`` (6k,), eq 88: exact for any momentum M."""
        return self.Jstar @ self.qdot + self.J0E @ np.linalg.solve(self.H0, self.momentum_base)


class GJM:
    """Hand-built GJM model of a robot; the structure is read once.

    Two implementations give the same numbers: the numpy code of this package (``"numpy"``, the
    equation-by-equation reference) and the compiled core ``freefloat.dynamics._core``
    (``"compiled"``, the default), which receives the tree as arrays.

    Args:
        robot: a robot with a free-flyer or planar base and 1-DOF joints.

    Attributes:
        ee_body: index of each end-effector's body, 0 = first body after the base (k,).
        ee_offset: each end-effector frame origin in its body's (parent-joint) frame, m (k, 3).
        moved: ``moved[i, j]`` whether joint j moves point i (n + 1 + k, n) bool; points ordered
            [base CoM; body CoMs; end-effector origins].
        shapes: the shapes of q and v, ``((nq,), (nv,))``.
    """

    def __init__(self, robot: Robot):
        self.robot = robot
        self.tree = TreeStructure.of(robot)
        self.coords = JointCoordinates(robot)
        frames = [robot.model.frames[fid] for fid in robot.end_effector_frame_ids]
        self.ee_body = np.array([f.parentJoint - 1 for f in frames], dtype=int)
        self.ee_offset = np.array([f.placement.translation for f in frames]).reshape(-1, 3)
        self.moved = np.vstack((self.tree.ancestor, self.tree.ancestor[self.ee_body]))
        self.shapes = ((robot.model.nq,), (robot.model.nv,))
        self.core = compiled_core(robot, self.tree, self.ee_body, self.ee_offset)

    def __getstate__(self) -> dict:
        """Pickled without the compiled core (rebuilt from the tree on unpickling), so models
        travel to worker processes."""
        state = self.__dict__.copy()
        del state["core"]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self.core = compiled_core(self.robot, self.tree, self.ee_body, self.ee_offset)

    def admissible(self, q: np.ndarray, v: np.ndarray) -> bool:
        """Whether float arrays q (nq,), v (nv,) pass :func:`~freefloat.robot.state.check_state`,
        checked in the compiled core (a fraction of check_state's cost; False for wrong shapes)."""
        return (q.shape, v.shape) == self.shapes and self.core.admissible(q, v, UNIT_TOLERANCE, MAX_MAGNITUDE)

    def kinematics(self, q: np.ndarray) -> BodyKinematics:
        """Body kinematics at configuration q (nq,)."""
        return forward_kinematics(self.robot, self.tree, self.coords, q)

    def compute(self, q: np.ndarray, v: np.ndarray, backend: str = "compiled") -> GJMState:
        """All GJM quantities at state (q, v) in Pinocchio's convention (see :func:`compute`)."""
        if backend == "compiled":
            return state_of(self.core.compute(q, v))
        if backend != "numpy":
            raise UnknownName("GJM backend", backend, BACKENDS)
        kin = self.kinematics(q)
        r_E = end_effector_points(kin, self.ee_body, self.ee_offset)
        nb = len(self.tree.mass)
        # one pass for the body CoMs and the end-effector points
        JT, JR = point_jacobians(self.tree, kin, np.vstack((kin.com, r_E)), self.moved)
        H0, H0m, Hm = inertia_matrices(self.tree, kin, JT[:nb], JR[:nb])
        Jm, J0E = end_effector_jacobians(kin.r0, r_E, JT[nb:], JR[nb:])
        solved = np.linalg.solve(H0, H0m)
        x0dot, qdot = base_state(self.robot, q, v)[2], v[self.robot.n_base:]
        momentum = H0 @ x0dot + H0m @ qdot
        origin = momentum.copy()
        origin[3:] += cross3(kin.r0, momentum[:3])
        Hstar = Hm - H0m.T @ solved
        return GJMState(
            H0=H0, H0m=H0m, Hm=Hm, Hstar=0.5 * (Hstar + Hstar.T), J0=-solved, Jm=Jm, J0E=J0E,
            Jstar=Jm - J0E @ solved, momentum_base=momentum, momentum_origin=origin,
            x0dot=x0dot, qdot=qdot, ee_position=r_E, kinematics=kin,
        )


def compiled_core(robot: Robot, tree: TreeStructure, ee_body: np.ndarray, ee_offset: np.ndarray) -> GJMCore:
    """The compiled core of a robot, handed the tree as arrays (Pinocchio joint order)."""
    model = robot.model
    joints = range(2, model.njoints)
    return GJMCore(
        parent=tree.parent, placement=tree.placement, axis=tree.axis, revolute=tree.revolute,
        mass=tree.mass, com=tree.com, inertia=tree.inertia,
        q_index=np.array([model.idx_qs[j] for j in joints], dtype=np.int64),
        circle=np.array([model.nqs[j] == 2 for j in joints], dtype=bool),
        free_base=robot.base == "free", base_com=robot.base_com, base_com_rotation=robot.base_com_rotation,
        ee_body=ee_body, ee_offset=ee_offset, nq=model.nq, nv=model.nv,
    )


def state_of(out: tuple) -> GJMState:
    """A :class:`GJMState` from the compiled core's tuple (fields in order, kinematics last);
    ``tuple.__new__`` skips the named tuples' argument parsing (a third of this call)."""
    return tuple.__new__(GJMState, (*out[:-1], tuple.__new__(BodyKinematics, out[-1])))


def egjm_blocks(state: GJMState, robot: Robot) -> dict[tuple[int, int], np.ndarray]:
    """E-GJM blocks (eqs 89-91): ``(i, i)`` is J_S^i, ``(i, j)`` with i != j is J_C^{i,j}.

    Block (i, j) holds end-effector i's rows and arm j's joint columns (6, m_j). Where arms share
    joints (a tree branching mid-arm) the column sets overlap and J_C^{i,j} is not pure coupling.
    """
    columns = [arm.v_indices - robot.n_base for arm in robot.arms]
    return {(i, j): state.Jstar[6 * i:6 * i + 6][:, cols]
            for i in range(len(columns)) for j, cols in enumerate(columns)}


@functools.lru_cache(maxsize=32)
def model_of(robot: Robot) -> GJM:
    """The cached :class:`GJM` of a robot (robots hash by identity)."""
    return GJM(robot)


def checked_state(robot: Robot, q: np.ndarray, v: np.ndarray) -> tuple[GJM, np.ndarray, np.ndarray]:
    """The robot's cached :class:`GJM` and (q, v) as float arrays, checked: the core's
    :meth:`GJM.admissible` first, :func:`~freefloat.robot.state.check_state` (which names the
    problem) only when that fails.

    Raises:
        InvalidArgument: as check_state.
    """
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    gjm = model_of(robot)
    if not gjm.admissible(q, v):
        check_state(robot, q, v)
    return gjm, q, v


def compute(robot: Robot, q: np.ndarray, v: np.ndarray, backend: str = "compiled") -> GJMState:
    """GJM quantities of ``robot`` at Pinocchio state (q, v).

    Args:
        robot: the robot (free-flyer or planar base; planar states are embedded in 3-D).
        q: configuration (nq,), free-flyer base quaternion.
        v: velocity (nv,), Pinocchio's local base velocity; converted to ``x0dot = [v0; w0]``.
        backend: ``"compiled"`` (default) or ``"numpy"``, the reference; see :data:`BACKENDS`.

    Raises:
        InvalidArgument: for q or v of the wrong size, not finite, or a non-unit quaternion (a
            zero quaternion used to be read as the identity).
    """
    gjm, q, v = checked_state(robot, q, v)
    return gjm.compute(q, v, backend)
