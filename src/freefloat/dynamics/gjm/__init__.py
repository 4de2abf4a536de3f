"""The Generalized Jacobian Matrix (GJM) framework, hand-built (dissertation ch. 3).

``compute(robot, q, v)`` gives H0, H0m, Hm, H*, the GJM/E-GJM and the momenta; every formula is
cross-checked against Pinocchio in :mod:`freefloat.dynamics.verify` and the tests.
"""

from .derivatives import GJMDerivatives, derivatives
from .model import GJM, GJMState, compute, egjm_blocks, model_of
from .momentum import H0C_VARIANTS, base_momentum_matrices, momentum_about_origin

__all__ = [
    "GJM", "GJMDerivatives", "GJMState", "H0C_VARIANTS", "base_momentum_matrices", "compute", "derivatives",
    "egjm_blocks", "model_of", "momentum_about_origin",
]
