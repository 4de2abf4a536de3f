"""MuJoCo on a closed-chain bench scene: the spanning tree and its closures from
:mod:`.mechanism_mjcf` (on a fixed, planar or free base), the same held law applied as
generalized forces on the actuated joints.

Each control period the state is read from MuJoCo (``qpos``, ``qvel``: one coordinate per hinge
or slide, matched to the tree's joints by name; a moving base's root joint mapped to Pinocchio's
convention, :class:`RootMap`), the law evaluated at the tree's state (a controller with
``torque(t, q, v)`` on the tree: :class:`~..scenes.mechanism_plants.ObservedController` on a fixed base,
:class:`~freefloat.parallel.free_base.BaseFrameControl` on a moving one) and its efforts written
to ``qfrc_applied`` for ``hold`` calls of ``mj_step``.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import pinocchio as pin

from ....errors import FreefloatError
from ....parallel.closed_loop import steps_per_period
from .mechanism_mjcf import mechanism_mjcf
from .state import from_mujoco, to_mujoco, velocity_map

#: MuJoCo's warnings of an unstable simulation (it resets the state after them).
UNSTABLE = (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQACC)
#: Largest relative difference allowed between MuJoCo's joint-space mass matrix and Pinocchio's.
MASS_MATRIX_TOL = 1e-12


class RootMap:
    """A moving base's root joint, Pinocchio's coordinates against MuJoCo's (the first ``qpos``
    and ``qvel`` entries, :mod:`.mechanism_mjcf` writes the root body first).

    Planar: Pinocchio ``q = [x, y, cos t, sin t]``, ``v = [v_local (2,); w]`` (the root frame's
    origin velocity in its own axes); MuJoCo ``qpos = [x, y, t]``, ``qvel = [xdot, ydot, tdot]``
    (inertial). Free flyer: :mod:`.state`'s map. Fixed base: nothing (``nq = nv = 0``).

    Attributes:
        kind: ``"planar"``, ``"free"`` or ``"fixed"``.
        nq, nv: Pinocchio's sizes of the root joint; mj_nq, mj_nv: MuJoCo's.
    """

    SIZES = {"fixed": (0, 0, 0, 0), "planar": (4, 3, 3, 3), "free": (7, 6, 7, 6)}

    def __init__(self, model: pin.Model):
        names = {"JointModelPlanar": "planar", "JointModelFreeFlyer": "free"}
        self.kind = names.get(model.joints[1].shortname(), "fixed") if model.njoints > 1 else "fixed"
        self.nq, self.nv, self.mj_nq, self.mj_nv = self.SIZES[self.kind]

    def to_mujoco(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's root ``(qpos, qvel)`` of Pinocchio's root ``(q, v)``."""
        if self.kind == "free":
            return to_mujoco(q, v)
        if self.kind == "planar":
            c, s = q[2], q[3]
            return (np.array([q[0], q[1], np.arctan2(s, c)]),
                    np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]))
        return np.zeros(0), np.zeros(0)

    def positions(self, qpos: np.ndarray) -> np.ndarray:
        """Pinocchio's root ``q`` (N, nq) of MuJoCo's root ``qpos`` rows (N, mj_nq)."""
        if self.kind == "free":
            return qpos[:, [0, 1, 2, 4, 5, 6, 3]]
        if self.kind == "planar":
            return np.column_stack((qpos[:, :2], np.cos(qpos[:, 2]), np.sin(qpos[:, 2])))
        return qpos[:, :0]

    def from_mujoco(self, qpos: np.ndarray, qvel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pinocchio's root ``(q, v)`` of MuJoCo's root ``(qpos, qvel)``; inverse of :meth:`to_mujoco`."""
        if self.kind == "free":
            return from_mujoco(qpos, qvel)
        q = self.positions(qpos[None])[0]
        if self.kind == "planar":
            c, s = q[2], q[3]
            return q, np.array([c * qvel[0] + s * qvel[1], -s * qvel[0] + c * qvel[1], qvel[2]])
        return q, np.zeros(0)

    def velocity_map(self, q: np.ndarray) -> np.ndarray:
        """``S`` (nv, nv) of the root with ``v = S qvel`` (MuJoCo's mass matrix is ``S^T M S``)."""
        if self.kind == "free":
            return velocity_map(q, 6)
        s = np.eye(self.nv)
        if self.kind == "planar":
            s[:2, :2] = [[q[2], q[3]], [-q[3], q[2]]]
        return s

    def acceleration(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """MuJoCo's root ``qacc`` of Pinocchio's root acceleration ``a`` at ``(q, v)``: the origin's
        inertial acceleration ``R (a_lin + w x v_lin)``, the angular part as Pinocchio's (free:
        local axes; planar: about z)."""
        if self.kind == "fixed":
            return np.zeros(0)
        if self.kind == "free":
            return np.concatenate((self.velocity_map(q)[:3, :3].T @ (a[:3] + np.cross(v[3:], v[:3])), a[3:]))
        local = a[:2] + v[2] * np.array([-v[1], v[0]])  # w x v_lin with w = (0, 0, v[2])
        return np.concatenate((self.velocity_map(q)[:2, :2].T @ local, a[2:]))


class MujocoMechanism:
    """One MuJoCo model of ``tree`` at integrator ``integrator`` and step ``step`` s.

    Args:
        tree: the Pinocchio tree with its closures: ``model`` (fixed base, or a planar or
            free-flyer root joint), ``constraints`` (``RigidConstraintModel`` s) and ``actuated``
            (velocity index of each effort) (:class:`~..scenes.mechanism_plants.SpanningTree`,
            :class:`~freefloat.parallel.free_base.FloatingMechanism`).

    Attributes:
        model, data: MuJoCo's.
        root: the root joint's map (:class:`RootMap`).
        q_index, v_index: MuJoCo's ``qpos`` and ``qvel`` index of each tree coordinate after the
            root's (nq - root.nq,), (nv - root.nv,): ``q[root.nq:] = qpos[q_index]``.
    """

    def __init__(self, tree: Any, integrator: str, step: float) -> None:
        self.tree, model = tree, tree.model
        self.model = mujoco.MjModel.from_xml_string(mechanism_mjcf(model, tree.constraints, step, integrator))
        self.data = mujoco.MjData(self.model)
        self.root = RootMap(model)
        self.q_index = np.empty(model.nq - self.root.nq, dtype=int)
        self.v_index = np.empty(model.nv - self.root.nv, dtype=int)
        for j in range(2 if self.root.nq else 1, model.njoints):
            joint = self.model.joint(model.names[j]).id
            self.q_index[model.idx_qs[j] - self.root.nq] = self.model.jnt_qposadr[joint]
            self.v_index[model.idx_vs[j] - self.root.nv] = self.model.jnt_dofadr[joint]

    def set_state(self, q: np.ndarray, v: np.ndarray) -> None:
        """MuJoCo's state at the tree's ``(q, v)``."""
        root, d = self.root, self.data
        d.qpos[:root.mj_nq], d.qvel[:root.mj_nv] = root.to_mujoco(q[:root.nq], v[:root.nv])
        d.qpos[self.q_index], d.qvel[self.v_index] = q[root.nq:], v[root.nv:]

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The tree's ``(q, v)`` at MuJoCo's state."""
        root, d = self.root, self.data
        q, v = root.from_mujoco(d.qpos[:root.mj_nq], d.qvel[:root.mj_nv])
        return np.concatenate((q, d.qpos[self.q_index])), np.concatenate((v, d.qvel[self.v_index]))

    def _velocity_map(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``S`` (nv, nv) with the tree's ``v = S qvel[order]``, and ``order`` (nv,)."""
        nv, root = self.tree.model.nv, self.root
        S = np.eye(nv)
        S[:root.nv, :root.nv] = root.velocity_map(q[:root.nq])
        return S, np.concatenate((np.arange(root.mj_nv), self.v_index))

    def mass_matrix_gap(self, q: np.ndarray) -> float:
        """Largest difference between MuJoCo's joint-space mass matrix and Pinocchio's CRBA
        (``S^T M S`` in MuJoCo's velocity coordinates) at tree configuration ``q``, relative to
        the largest entry."""
        self.set_state(q, np.zeros(self.tree.model.nv))
        mujoco.mj_forward(self.model, self.data)
        full = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, self.data, full)
        pinocchio = pin.crba(self.tree.model, self.tree.model.createData(), q)
        pinocchio = np.triu(pinocchio) + np.triu(pinocchio, 1).T
        S, order = self._velocity_map(q)
        pinocchio = S.T @ pinocchio @ S
        return float(np.abs(full[np.ix_(order, order)] - pinocchio).max() / np.abs(pinocchio).max())

    def free_acceleration_gap(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> float:
        """Largest difference between MuJoCo's acceleration with its equality constraints off and
        Pinocchio's ABA on the open tree, at the tree's state ``(q, v)`` with efforts ``u`` on the
        actuated joints (gravity the model's), relative to the largest entry; in MuJoCo's
        coordinates (:meth:`RootMap.acceleration`)."""
        tree, root, m, d = self.tree.model, self.root, self.model, self.data
        tau = np.zeros(tree.nv)
        tau[self.tree.actuated] = u
        a = pin.aba(tree, tree.createData(), q, v, tau)
        self.set_state(q, v)
        _, order = self._velocity_map(q)
        d.qfrc_applied[:] = 0.0
        d.qfrc_applied[order] = self._velocity_map(q)[0].T @ tau
        flags = m.opt.disableflags
        m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
        try:
            mujoco.mj_forward(m, d)
        finally:
            m.opt.disableflags = flags
        expected = np.concatenate((root.acceleration(q[:root.nq], v[:root.nv], a[:root.nv]), a[root.nv:]))
        return float(np.abs(d.qacc[order] - expected).max() / np.abs(expected).max())

    def check_inertias(self, q: np.ndarray) -> None:
        """Raises FreefloatError when MuJoCo's mass matrix differs from Pinocchio's at ``q``."""
        gap = self.mass_matrix_gap(q)
        if gap > MASS_MATRIX_TOL:
            # base class: a failed cross-check of the two engines
            raise FreefloatError(f"MuJoCo's mass matrix of the {self.tree.model.name} tree differs from Pinocchio's by "
                                 f"{gap:.3g} (relative): the MJCF does not carry the same inertias")

    def run(self, control: Any, q0: np.ndarray, v0: np.ndarray, duration: float, period: float,
            step: float) -> tuple[np.ndarray, np.ndarray]:
        """The held-law loop from tree state ``(q0, v0)``; ``control.torque(t, q, v)`` gives the
        efforts (k,) at the tree's state.

        Returns:
            Tree configurations after every step, the start first (N + 1, nq), and the final tree
            rates (nv,).

        Raises:
            FloatingPointError: when MuJoCo finds its state unstable (a non-finite or huge
                position, velocity or acceleration, after which it resets the state), naming the time.
        """
        m, d, root = self.model, self.data, self.root
        mujoco.mj_resetData(m, d)
        self.set_state(q0, v0)
        _, order = self._velocity_map(q0)
        actuated = order[self.tree.actuated]
        hold = steps_per_period(period, step)
        periods = round(duration / period)
        rows = np.empty((periods * hold + 1, m.nq))
        rows[0] = d.qpos
        for n in range(periods):
            d.qfrc_applied[actuated] = control.torque(n * period, *self.state())
            for k in range(hold):
                mujoco.mj_step(m, d)
                rows[n * hold + k + 1] = d.qpos
            if any(d.warning[w].number for w in UNSTABLE):
                raise FloatingPointError(f"MuJoCo found the simulation unstable by t = {(n + 1) * period:.6g} s")
        return np.column_stack((root.positions(rows[:, :root.mj_nq]), rows[:, self.q_index])), self.state()[1]
