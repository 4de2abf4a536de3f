"""Dynamics models behind one interface, selectable by name."""

from __future__ import annotations

from ...robot.robot import Robot
from .base import DynamicsModel
from .exact import ExactModel

#: Registry names, one-line descriptions and the regime in which each matches the exact dynamics
#: (as measured by ``freefloat reproduce models`` and pinned by tests/test_models.py).
MODELS = {
    "exact": "Pinocchio ABA: the exact reference",
    "standard": "FM-ST-A as printed: dx0/dq = 0, Hdot over the joints only, c0 = 0 (eqs 97-115)",
    "standard_full_hdot": "FM-ST-A with the full Hdot but c0 = 0 (sec 3.5): zero linear momentum",
    "standard_corrected": "FM-ST-A with the full Hdot and c0 = [0; v0 x P]: exact",
    "nidc": "FM-NIC-A: FM-ST-A plus the integrated non-inertial dynamic coupling (eqs 59-67, 122)",
    "nidc_translation": "FM-NIC-A read with the base translation kept in dr0i/dq (eqs 55-58)",
    "reduced": "stand-alone model on H* (eqs 92-94): zero momentum",
    "momentum_mono": "conserved non-zero momentum, mono-state Lagrangian (eq 127)",
    "momentum_multi": "conserved non-zero momentum, multi-state Lagrangian (eq 128)",
    "momentum_routh": "conserved non-zero momentum, Routhian (corrected): zero linear momentum",
}


def make_model(name: str, robot: Robot, backend: str = "compiled") -> DynamicsModel:
    """The dynamics model called ``name`` for ``robot``.

    ``backend`` picks the implementation of the GJM variants: ``"compiled"`` (default, the
    compiled core) or ``"numpy"`` (the reference in this package); ``exact`` is Pinocchio's ABA
    either way.

    Raises:
        ValueError: for an unknown name, listing the valid ones.
    """
    from .generalized import VARIANTS, GeneralizedInertiaModel
    from .underactuated import NIDCModel, UnderactuatedGJM

    if name == "exact":
        return ExactModel(robot)
    if name in ("standard", "standard_full_hdot", "standard_corrected"):
        return UnderactuatedGJM(robot, full_hdot=name != "standard", corrected_c0=name == "standard_corrected",
                                backend=backend)
    if name in ("nidc", "nidc_translation"):
        return NIDCModel(robot, translation=name == "nidc_translation", backend=backend)
    if name in VARIANTS:
        return GeneralizedInertiaModel(robot, name, backend)
    raise ValueError(f"unknown dynamics model '{name}'; valid: {', '.join(MODELS)}")


__all__ = ["MODELS", "DynamicsModel", "ExactModel", "make_model"]
