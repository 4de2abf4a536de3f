"""MuJoCo on a closed-chain bench scene: the spanning tree and its closures from
:mod:`.mechanism_mjcf`, the same held law applied as generalized forces on the actuated joints.

Each control period the state is read from MuJoCo (``qpos``, ``qvel``: one coordinate per hinge
or slide, matched to the tree's joints by name), the law evaluated on Orsino's coordinates read off
the tree (:meth:`SpanningTree.orsino_state`) and its efforts written to ``qfrc_applied`` for
``hold`` calls of ``mj_step``.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin

from ...errors import FreefloatError
from ...parallel.closed_loop import steps_per_period
from ...parallel.sliding_mode import PlatformControl
from .mechanism_mjcf import mechanism_mjcf
from .mechanism_plants import SpanningTree

#: MuJoCo's warnings of an unstable simulation (it resets the state after them).
UNSTABLE = (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQACC)
#: Largest relative difference allowed between MuJoCo's joint-space mass matrix and Pinocchio's.
MASS_MATRIX_TOL = 1e-12


class MujocoMechanism:
    """One MuJoCo model of ``tree`` at integrator ``integrator`` and step ``step`` s.

    Attributes:
        model, data: MuJoCo's.
        q_index, v_index: MuJoCo's ``qpos`` and ``qvel`` index of each tree coordinate (nq,), (nv,):
            tree ``q = qpos[q_index]``, ``v = qvel[v_index]``.
    """

    def __init__(self, tree: SpanningTree, integrator: str, step: float) -> None:
        self.tree = tree
        self.model = mujoco.MjModel.from_xml_string(mechanism_mjcf(tree.model, tree.constraints, step, integrator))
        self.data = mujoco.MjData(self.model)
        self.q_index, self.v_index = np.empty(tree.model.nq, dtype=int), np.empty(tree.model.nv, dtype=int)
        for j in range(1, tree.model.njoints):
            joint = self.model.joint(tree.model.names[j]).id
            self.q_index[tree.model.idx_qs[j]] = self.model.jnt_qposadr[joint]
            self.v_index[tree.model.idx_vs[j]] = self.model.jnt_dofadr[joint]

    def mass_matrix_gap(self, q: np.ndarray) -> float:
        """Largest difference between MuJoCo's joint-space mass matrix and Pinocchio's CRBA at tree
        configuration ``q``, relative to the largest entry."""
        self.data.qpos[self.q_index] = q
        mujoco.mj_forward(self.model, self.data)
        full = np.zeros((self.model.nv, self.model.nv))
        mujoco.mj_fullM(self.model, self.data, full)
        pinocchio = pin.crba(self.tree.model, self.tree.model.createData(), q)
        pinocchio = np.triu(pinocchio) + np.triu(pinocchio, 1).T
        mine = full[np.ix_(self.v_index, self.v_index)]
        return float(np.abs(mine - pinocchio).max() / np.abs(pinocchio).max())

    def check_inertias(self, q: np.ndarray) -> None:
        """Raises FreefloatError when MuJoCo's mass matrix differs from Pinocchio's at ``q``."""
        gap = self.mass_matrix_gap(q)
        if gap > MASS_MATRIX_TOL:
            raise FreefloatError(f"MuJoCo's mass matrix of the {self.tree.model.name} tree differs from Pinocchio's by "
                                 f"{gap:.3g} (relative): the MJCF does not carry the same inertias")

    def run(self, control: PlatformControl, q0: np.ndarray, v0: np.ndarray, duration: float, period: float,
            step: float) -> tuple[np.ndarray, np.ndarray]:
        """The held-law loop from tree state ``(q0, v0)``.

        Returns:
            Tree configurations after every step, the start first (N + 1, nq), and the final tree
            rates (nv,).

        Raises:
            FloatingPointError: when MuJoCo finds its state unstable (a non-finite or huge
                position, velocity or acceleration, after which it resets the state), naming the time.
        """
        m, d, tree = self.model, self.data, self.tree
        mujoco.mj_resetData(m, d)
        d.qpos[self.q_index], d.qvel[self.v_index] = q0, v0
        actuated = self.v_index[tree.actuated]
        hold = steps_per_period(period, step)
        periods = round(duration / period)
        rows = np.empty((periods * hold + 1, m.nq))
        rows[0] = d.qpos
        for n in range(periods):
            q, v = d.qpos[self.q_index], d.qvel[self.v_index]
            d.qfrc_applied[actuated] = control.torque(n * period, *tree.orsino_state(q, v))
            for k in range(hold):
                mujoco.mj_step(m, d)
                rows[n * hold + k + 1] = d.qpos
            if any(d.warning[w].number for w in UNSTABLE):
                raise FloatingPointError(f"MuJoCo found the simulation unstable by t = {(n + 1) * period:.6g} s")
        return rows[:, self.q_index], d.qvel[self.v_index]
