"""The under-actuated GJM model (dissertation secs 3.5, 3.7; eqs 97-100, 106-115) and its variants.

.. math::
    \\begin{bmatrix} H_0 & H_{0m} \\\\ H_{0m}^T & H_m \\end{bmatrix}
    \\begin{bmatrix} \\ddot x_0 \\\\ \\ddot q \\end{bmatrix}
    + \\begin{bmatrix} \\dot H_0 & \\dot H_{0m} \\\\ \\dot H_{0m}^T & \\dot H_m \\end{bmatrix}
    \\begin{bmatrix} \\dot x_0 \\\\ \\dot q \\end{bmatrix}
    + \\begin{bmatrix} c_0 \\\\ c_m \\end{bmatrix} = \\begin{bmatrix} F \\\\ \\tau \\end{bmatrix}

solved for qddot first (eq 107), then xddot0 (eq 106). The variants differ in ``Hdot`` and ``c0``:

- ``standard`` (FM-ST-A, as printed): ``dx0/dq = 0``, so ``Hdot = sum_k dH/dq_k qdot_k`` (the
  base's own rotation does not enter) and ``c0 = 0`` (sec 3.5's claim).
- ``standard_full_hdot``: the full time derivative of H (joints and base rotation at w0) but
  still ``c0 = 0``: isolates sec 3.5's claim, exact only while ``v0 x P = 0``.
- ``standard_corrected``: the full time derivative (joints and base rotation at w0) and
  ``c0 = [0; v0 x P]``: the rate of the angular momentum about the MOVING base CoM is the torque
  minus ``v0 x P``. This is the exact dynamics.
- ``nidc`` (FM-NIC-A): ``standard`` plus the non-inertial dynamic coupling of eqs 59-67: the
  sensitivities ``D_k = dx0/dq_k`` are integrated once per control period by eq 67 (explicit
  Euler, from zero) with ``dxdot0/dq_k`` from eq 64; their rotational part turns the inertial-frame
  matrices in the partials (``dH0 += Delta_k H0 - H0 Delta_k``, ``dH0m += Delta_k H0m``), and
  ``c_m`` gains ``c_m^0 = 2 (dxdot0/dq_k) . M`` (eq 25).
"""

from __future__ import annotations

import numpy as np

from ...robot.conventions import cross3
from ...robot.robot import Robot
from ..gjm.matrices import skew_batch
from .gjm_base import GJMModelBase, Terms, quadratic_form


class UnderactuatedGJM(GJMModelBase):
    """FM-ST-A as printed, or with its errors corrected one at a time.

    Args:
        robot: the robot.
        full_hdot: use the full time derivative of H (base rotation included).
        corrected_c0: use ``c0 = [0; v0 x P]`` instead of the printed ``c0 = 0``.
        backend: ``"compiled"`` or ``"numpy"``, the reference.
    """

    def __init__(self, robot: Robot, full_hdot: bool = False, corrected_c0: bool = False, backend: str = "compiled"):
        super().__init__(robot, backend)
        self.full_hdot, self.corrected = full_hdot, corrected_c0
        names = {(False, False): "standard", (True, False): "standard_full_hdot", (True, True): "standard_corrected"}
        if (full_hdot, corrected_c0) not in names:
            raise ValueError("the corrected c0 needs the full Hdot (corrected_c0 implies full_hdot)")
        self.name = names[(full_hdot, corrected_c0)]

    def rates(self, t: Terms) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(H0dot, H0mdot, Hmdot)`` of this variant."""
        if self.full_hdot:
            return t.d.H0dot, t.d.H0mdot, t.d.Hmdot
        qd = t.s.qdot
        return np.tensordot(qd, t.d.dH0, 1), np.tensordot(qd, t.d.dH0m, 1), np.tensordot(qd, t.d.dHm, 1)

    def c0(self, t: Terms) -> np.ndarray:
        """Base-row non-inertial term (6,): zero as printed, ``[0; v0 x P]`` corrected."""
        if not self.corrected:
            return np.zeros(6)
        return np.concatenate((np.zeros(3), cross3(t.s.x0dot[:3], t.s.momentum_base[:3])))

    def c_m(self, t: Terms) -> np.ndarray:
        return t.c_m

    def base_bias(self, t: Terms) -> np.ndarray:
        """``H0dot x0dot + H0mdot qdot + c0 - F`` (6,)."""
        H0dot, H0mdot, _ = self.rates(t)
        return H0dot @ t.s.x0dot + H0mdot @ t.s.qdot + self.c0(t) - t.F

    def joint_space(self, t: Terms) -> tuple[np.ndarray, np.ndarray]:
        _, H0mdot, Hmdot = self.rates(t)
        s = t.s
        c = H0mdot.T @ s.x0dot + Hmdot @ s.qdot + self.c_m(t) - s.H0m.T @ t.solve0(self.base_bias(t))
        return s.Hstar, c

    def base_acceleration(self, t: Terms, qddot: np.ndarray) -> np.ndarray:
        return -t.solve0(t.s.H0m @ qddot + self.base_bias(t))


class NIDCModel(UnderactuatedGJM):
    """FM-NIC-A: the standard model with the integrated non-inertial dynamic coupling.

    State: ``D`` (n, 6), row k the sensitivity dx0/dq_k = [d r0 (translation); d theta0
    (rotation)] of the base CoM pose, inertial frame; zero at the start, advanced by
    :meth:`end_period` once per control period (eq 67).

    Args:
        robot: the robot.
        translation: the second reading of eqs 55-58 (``nidc_translation``): ``dr0i/dq_k`` also
            gets ``-dr0/dq_k`` while the links' own positions do not move with the base, so the
            base translation does not cancel in ``r0i = r_i - r0``. With eq 122 (the default) the
            base moves the links too and only its rotation remains.
        backend: ``"compiled"`` or ``"numpy"``, the reference.
    """

    def __init__(self, robot: Robot, translation: bool = False, backend: str = "compiled"):
        super().__init__(robot, backend=backend)
        self.translation = translation
        self.name = "nidc_translation" if translation else "nidc"
        self.D = np.zeros((robot.n_joints, 6))

    def sensitivities(self) -> np.ndarray:
        """``D`` (n, 6), handed to the compiled core."""
        return self.D

    def augmented(self, t: Terms) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Partials with the base turned by the rotational part of D: ``dH0, dH0m, dHm``."""
        s = t.s
        Delta = np.zeros((len(self.D), 6, 6))
        Delta[:, :3, :3] = Delta[:, 3:, 3:] = skew_batch(self.D[:, 3:])
        dH0, dH0m = t.d.dH0 + Delta @ s.H0 - s.H0 @ Delta, t.d.dH0m + Delta @ s.H0m
        if self.translation:
            extra_H0, extra_H0m = self._translation_terms(t)
            dH0, dH0m = dH0 + extra_H0, dH0m + extra_H0m
        return dH0, dH0m, t.d.dHm

    def _translation_terms(self, t: Terms) -> tuple[np.ndarray, np.ndarray]:
        """Changes of dH0, dH0m when every link's r0i moves by ``-delta_k = -D_k[:3]`` (eqs 55-58)."""
        tree, kin = self.gjm.tree, t.s.kinematics
        m = tree.mass[1:]
        S = m @ (kin.com[1:] - kin.r0)                        # sum over links of m_i r0i
        J_TS = t.s.H0m[:3]                                    # the base body has no joint columns
        delta = skew_batch(self.D[:, :3])                     # (n, 3, 3)
        SX = skew_batch(S)
        dH0 = np.zeros((len(self.D), 6, 6))
        dH0[:, :3, 3:] = m.sum() * delta
        dH0[:, 3:, :3] = -m.sum() * delta
        dH0[:, 3:, 3:] = delta @ SX + SX @ delta
        dH0m = np.zeros((len(self.D), 6, J_TS.shape[1]))
        dH0m[:, 3:] = -delta @ J_TS
        return dH0, dH0m

    def xdot0_sensitivity(self, t: Terms) -> np.ndarray:
        """``dxdot0/dq_k = H0^-1 (dH0_k H0^-1 H0m - dH0m_k) qdot`` of eq 64 (n, 6), augmented partials."""
        dH0, dH0m, _ = self.augmented(t)
        s = t.s
        base_rate = t.solve0(s.H0m @ s.qdot)  # H0^-1 H0m qdot
        return t.solve0((dH0 @ base_rate - dH0m @ s.qdot).T).T

    def rates(self, t: Terms):
        qd = t.s.qdot
        dH0, dH0m, dHm = self.augmented(t)
        return np.tensordot(qd, dH0, 1), np.tensordot(qd, dH0m, 1), np.tensordot(qd, dHm, 1)

    def c_m(self, t: Terms) -> np.ndarray:
        c_mm = quadratic_form(t.s, *self.augmented(t))
        c_m0 = 2.0 * self.xdot0_sensitivity(t) @ t.s.momentum_base
        return -0.5 * (c_mm + c_m0)

    def end_period(self, q: np.ndarray, v: np.ndarray, dt: float) -> None:
        """Eq 67: ``D <- D + dt dxdot0/dq`` evaluated at the period's start state."""
        if self.backend == "compiled":
            self.D += dt * self.gjm.core.sensitivity(q, v, self.translation, self.D)
        else:
            self.D += dt * self.xdot0_sensitivity(self.terms(q, v))
