"""The Generalized Jacobian Matrix (GJM) framework, hand-built (dissertation ch. 3).

``compute(robot, q, v)`` gives H0, H0m, Hm, H*, the GJM/E-GJM and the momenta; every formula is
cross-checked against Pinocchio in :mod:`freefloat.dynamics.verify` and the tests. Two backends
give the same numbers: the compiled core (``backend="compiled"``, the default; C++ in ``cpp/``)
and the numpy modules here (``backend="numpy"``), which are the equation-by-equation reference.
"""

from .derivatives import GJMDerivatives, derivatives, state_and_derivatives
from .jacobian_rates import GJMRates, jacobian_rates, state_and_rates
from .model import BACKENDS, GJM, GJMState, compute, egjm_blocks, model_of
from .momentum import H0C_VARIANTS, base_momentum_matrices, momentum_about_origin

__all__ = [
    "BACKENDS",
    "GJM",
    "H0C_VARIANTS",
    "GJMDerivatives",
    "GJMRates",
    "GJMState",
    "base_momentum_matrices",
    "compute",
    "derivatives",
    "egjm_blocks",
    "jacobian_rates",
    "model_of",
    "momentum_about_origin",
    "state_and_derivatives",
    "state_and_rates",
]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
