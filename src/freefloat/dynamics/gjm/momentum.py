"""Momentum about the inertial origin: the corrected form and the dissertation's printed eq 182.

The dissertation (sec 3.9.3, appendix B) splits the total momentum about the inertial origin as
``M = (H0 + H0^C) x0dot + (H0m + H0m^C) qdot`` (eq 184). Angular momentum about the origin is the
angular momentum about the base CoM plus ``r0 x P``, which gives

.. math::
    H_0^C = \\begin{bmatrix} 0 & 0 \\\\ m_T r_0^\\times & -m_T r_0^\\times r_{0C}^\\times \\end{bmatrix},
    \\qquad H_{0m}^C = \\begin{bmatrix} 0 \\\\ r_0^\\times J_{TS} \\end{bmatrix}.

Eq 182 as printed has ``+m_T r_{0C}^\\times r_0^\\times`` in the lower-right block: eq 180 treats
the skew matrices as anticommuting (``r0^x r0i^x = -r0i^x r0^x``), which is false. The two differ
by ``m_T (r_{0C} r_0^T + r_0 r_{0C}^T - 2 (r_0 \\cdot r_{0C}) I)``, zero only when r0 or r0C is.
Eq 183 (``-J_TS^x r0``, column by column) equals ``r0^x J_TS`` and is correct.
"""

from __future__ import annotations

import numpy as np

from ...errors import UnknownName
from ...robot.conventions import skew
from .model import GJMState

#: Variants of H0^C: the corrected one and eq 182 as printed.
H0C_VARIANTS = ("corrected", "printed_eq182")


def unskew(S: np.ndarray) -> np.ndarray:
    """The vector x of a cross-product matrix ``S = [x]x`` (3,)."""
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


def base_momentum_matrices(state: GJMState, variant: str = "corrected") -> tuple[np.ndarray, np.ndarray]:
    """``(H0^C, H0m^C)`` (6, 6), (6, n) of eqs 182-183.

    Args:
        state: GJM quantities at the state.
        variant: ``"corrected"`` or ``"printed_eq182"``.
    """
    if variant not in H0C_VARIANTS:
        raise UnknownName("H0^C variant", variant, H0C_VARIANTS)
    total = state.H0[0, 0]
    r0 = state.kinematics.r0
    r0C = unskew(state.H0[3:, :3]) / total  # H0 lower-left block is M r0C^x (eq 23)
    H0C = np.zeros((6, 6))
    H0C[3:, :3] = total * skew(r0)
    H0C[3:, 3:] = (-total * skew(r0) @ skew(r0C) if variant == "corrected"
                   else total * skew(r0C) @ skew(r0))
    H0mC = np.zeros_like(state.H0m)
    H0mC[3:] = skew(r0) @ state.H0m[:3]
    return H0C, H0mC


def momentum_about_origin(state: GJMState, variant: str = "corrected") -> np.ndarray:
    """``M = (H0 + H0^C) x0dot + (H0m + H0m^C) qdot`` (6,), eq 184: [P; L about the origin]."""
    H0C, H0mC = base_momentum_matrices(state, variant)
    return (state.H0 + H0C) @ state.x0dot + (state.H0m + H0mC) @ state.qdot

