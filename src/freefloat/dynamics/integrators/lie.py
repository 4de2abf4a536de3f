"""Lie-algebra corrections for Runge-Kutta-Munthe-Kaas (RKMK) steps on Pinocchio configurations.

Pinocchio composes on the right: ``integrate(q, theta) = q * exp(theta)`` with ``theta`` in the
local frame. Along ``q(t) = q0 * exp(theta(t))`` the local velocity ``V`` and ``theta`` satisfy

.. math::
    \\dot\\theta = \\mathrm{dexp}^{-1}_{-\\theta}(V)
    = V + \\tfrac12 [\\theta, V] + \\tfrac1{12} [\\theta, [\\theta, V]]
      - \\tfrac1{720} \\mathrm{ad}_\\theta^4 V + \\tfrac1{30240} \\mathrm{ad}_\\theta^6 V
      + O(|\\theta|^8),

which is what an RK method must integrate in the chart to keep its order on the group
(Munthe-Kaas 1999). Only non-commutative joints need it: the free-flyer (se(3)), the planar joint
(se(2), embedded in se(3)) and the spherical joint (so(3)); revolute and prismatic joints commute.
The series is used rather than Pinocchio's ``Jlog6``, which loses precision at small angles. An
RKMK method of order p needs the terms up to ``ad^(p-2)`` (Hairer, Lubich & Wanner, Sec. IV.8):
``degree`` 4 carries order 6, ``degree`` 6 order 8.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...robot.conventions import skew


def _ad_se3(t: list[float], u: list[float] | tuple[float, ...]) -> tuple[float, ...]:
    """``ad_t u`` for twists [v; w] as 6 floats: ``[w_t x v_u + v_t x w_u; w_t x w_u]``."""
    a1, a2, a3, w1, w2, w3 = t
    u1, u2, u3, m1, m2, m3 = u
    return (w2 * u3 - w3 * u2 + a2 * m3 - a3 * m2, w3 * u1 - w1 * u3 + a3 * m1 - a1 * m3,
            w1 * u2 - w2 * u1 + a1 * m2 - a2 * m1, w2 * m3 - w3 * m2, w3 * m1 - w1 * m3, w1 * m2 - w2 * m1)


def _dexpinv_se3(theta: np.ndarray, velocity: np.ndarray, degree: int = 4) -> np.ndarray:
    """``dexp^{-1}_{-theta}`` on se(3) by the series to ``ad^degree``, in scalar arithmetic (3x
    faster here than through 6x6 matrices)."""
    t, v = theta.tolist(), velocity.tolist()
    x1 = _ad_se3(t, v)
    x2 = _ad_se3(t, x1)
    x4 = _ad_se3(t, _ad_se3(t, x2))
    if degree < 6:
        return np.array([a + 0.5 * b + c / 12.0 - d / 720.0 for a, b, c, d in zip(v, x1, x2, x4)])
    x6 = _ad_se3(t, _ad_se3(t, x4))
    return np.array([a + 0.5 * b + c / 12.0 - d / 720.0 + e / 30240.0 for a, b, c, d, e in zip(v, x1, x2, x4, x6)])


def _dexpinv_se2(theta: np.ndarray, velocity: np.ndarray, degree: int = 4) -> np.ndarray:
    """``dexp^{-1}_{-theta}`` on se(2), Pinocchio's planar ordering [vx, vy, wz], in closed form.

    ``ad_theta`` maps (a, b, c) to u = (y c - w b, w a - x c, 0) and acts on such translations
    as ``w J`` (J: rotation by 90 deg), so ``ad^2 v = w J u``, ``ad^4 v = -w^3 J u`` and
    ``ad^6 v = w^5 J u`` (the last kept when ``degree >= 6``).
    """
    x, y, w = theta
    a, b, c = velocity
    u1, u2 = y * c - w * b, w * a - x * c  # ad v
    k = 1.0 / 12.0 + w * w / 720.0 + (w**4 / 30240.0 if degree >= 6 else 0.0)
    return np.array([a + 0.5 * u1 - w * u2 * k, b + 0.5 * u2 + w * u1 * k, c])


def _dexpinv_matrix(ad_of):
    """``dexp^{-1}_{-theta}`` through an ``ad`` matrix (so(3): ``skew``):
    ``v + ad v / 2 + ad^2 v / 12 - ad^4 v / 720 (+ ad^6 v / 30240 when degree >= 6)``."""

    def apply(theta: np.ndarray, velocity: np.ndarray, degree: int = 4) -> np.ndarray:
        ad = ad_of(theta)
        x1 = ad @ velocity
        x2 = ad @ x1
        x4 = ad @ (ad @ x2)
        out = velocity + 0.5 * x1 + x2 / 12.0 - x4 / 720.0
        return out + (ad @ (ad @ x4)) / 30240.0 if degree >= 6 else out

    return apply


#: Per non-commutative joint kind: (velocity size, dexp^-1 function).
AD_BY_JOINT = {
    "JointModelFreeFlyer": (6, _dexpinv_se3),
    "JointModelPlanar": (3, _dexpinv_se2),
    "JointModelSpherical": (3, _dexpinv_matrix(skew)),
    "JointModelSphericalZYX": (3, _dexpinv_matrix(skew)),
}


class ChartCorrection:
    """Applies ``dexp^{-1}_{-theta}`` to the non-commutative joints of a model.

    Args:
        model: Pinocchio model.
        degree: highest power of ``ad`` kept, 4 or 6.

    Raises:
        ValueError: for another degree.
    """

    def __init__(self, model: pin.Model, degree: int = 4):
        if degree not in (4, 6):
            raise ValueError(f"dexp^-1 series degree must be 4 or 6, got {degree}")
        self.degree = degree
        self._blocks = []
        for j in range(1, model.njoints):
            entry = AD_BY_JOINT.get(model.joints[j].shortname())
            if entry is not None:
                size, dexpinv = entry
                self._blocks.append((slice(model.idx_vs[j], model.idx_vs[j] + size), dexpinv))

    @property
    def needed(self) -> bool:
        """Whether any joint of the model is non-commutative."""
        return bool(self._blocks)

    def apply(self, theta: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """``dexp^{-1}_{-theta}(velocity)`` joint by joint (nv,), up to ``ad^degree``."""
        out = velocity.copy()
        for rows, dexpinv in self._blocks:
            out[rows] = dexpinv(theta[rows], velocity[rows], self.degree)
        return out
