"""Lie-algebra corrections for Runge-Kutta-Munthe-Kaas (RKMK) steps on Pinocchio configurations.

Pinocchio composes on the right: ``integrate(q, theta) = q * exp(theta)`` with ``theta`` in the
local frame. Along ``q(t) = q0 * exp(theta(t))`` the local velocity ``V`` and ``theta`` satisfy

.. math::
    \\dot\\theta = \\mathrm{dexp}^{-1}_{-\\theta}(V)
    = V + \\tfrac12 [\\theta, V] + \\tfrac1{12} [\\theta, [\\theta, V]]
      - \\tfrac1{720} \\mathrm{ad}_\\theta^4 V + O(|\\theta|^6),

which is what an RK method must integrate in the chart to keep its order on the group
(Munthe-Kaas 1999). Only non-commutative joints need it: the free-flyer (se(3)), the planar joint
(se(2), embedded in se(3)) and the spherical joint (so(3)); revolute and prismatic joints commute.
The series is used rather than Pinocchio's ``Jlog6``, which loses precision at small angles.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...robot.conventions import skew


def _ad_se3(theta: np.ndarray) -> np.ndarray:
    """``ad`` of a twist [v; w] (6, 6): ``ad(x) y = [w x v' + v x w'; w x w']``."""
    a, b, c, x, y, z = theta.tolist()
    return np.array([
        [0.0, -z, y, 0.0, -c, b], [z, 0.0, -x, c, 0.0, -a], [-y, x, 0.0, -b, a, 0.0],
        [0.0, 0.0, 0.0, 0.0, -z, y], [0.0, 0.0, 0.0, z, 0.0, -x], [0.0, 0.0, 0.0, -y, x, 0.0],
    ])


def _dexpinv_se2(theta: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """``dexp^{-1}_{-theta}`` on se(2), Pinocchio's planar ordering [vx, vy, wz], in closed form.

    ``ad_theta`` maps (a, b, c) to u = (y c - w b, w a - x c, 0) and acts on such translations
    as ``w J`` (J: rotation by 90 deg), so ``ad^2 v = w J u`` and ``ad^4 v = -w^3 J u``.
    """
    x, y, w = theta
    a, b, c = velocity
    u1, u2 = y * c - w * b, w * a - x * c  # ad v
    k = 1.0 / 12.0 + w * w / 720.0
    return np.array([a + 0.5 * u1 - w * u2 * k, b + 0.5 * u2 + w * u1 * k, c])


def _dexpinv_matrix(ad_of):
    """``dexp^{-1}_{-theta}`` through an ``ad`` matrix: ``v + ad v / 2 + ad^2 v / 12 - ad^4 v / 720``."""

    def apply(theta: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        ad = ad_of(theta)
        x1 = ad @ velocity
        x2 = ad @ x1
        return velocity + 0.5 * x1 + x2 / 12.0 - (ad @ (ad @ x2)) / 720.0

    return apply


#: Per non-commutative joint kind: (velocity size, dexp^-1 function).
AD_BY_JOINT = {
    "JointModelFreeFlyer": (6, _dexpinv_matrix(_ad_se3)),
    "JointModelPlanar": (3, _dexpinv_se2),
    "JointModelSpherical": (3, _dexpinv_matrix(skew)),
    "JointModelSphericalZYX": (3, _dexpinv_matrix(skew)),
}


class ChartCorrection:
    """Applies ``dexp^{-1}_{-theta}`` to the non-commutative joints of a model.

    Args:
        model: Pinocchio model.
    """

    def __init__(self, model: pin.Model):
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
        """``dexp^{-1}_{-theta}(velocity)`` joint by joint (nv,), up to ``ad^4``."""
        out = velocity.copy()
        for rows, dexpinv in self._blocks:
            out[rows] = dexpinv(theta[rows], velocity[rows])
        return out
