"""Dynamics models behind one interface, one registry of objects: :data:`MODELS`.

Each entry names a model, says what it is and in which regime it matches the exact dynamics (as
measured by ``freefloat reproduce models`` and pinned by tests/test_models.py), whether the
compiled core has it (``_core.MODELS`` lists the core's names; a test checks both agree), and
builds it for a robot. A new model is one module plus one :func:`register` call.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ...arguments import an_object
from ...errors import UnknownName
from ...registry import Registry
from ...robot.robot import Robot
from .base import DynamicsModel
from .exact import ExactModel

#: ``build(robot, backend) -> DynamicsModel``; backend ``"compiled"`` or ``"numpy"``.
Build = Callable[[Robot, str], DynamicsModel]


@dataclass(frozen=True)
class ModelSpec:
    """One dynamics model of the registry.

    Attributes:
        name: registry name (scene keys ``simulation.model``, ``controller.model``).
        description: one line: what it is and where it is exact.
        compiled: True when the compiled core (``cpp/gjm/models.hpp``) has it; ``exact`` is
            Pinocchio's ABA, which the compiled loop runs.
        build: makes it for a robot.
    """

    name: str
    description: str
    compiled: bool
    build: Build


#: Registry: name -> :class:`ModelSpec`.
MODELS: Registry[ModelSpec] = Registry("dynamics model")


def register(spec: ModelSpec) -> ModelSpec:
    """Add ``spec`` to :data:`MODELS` (a name already there is replaced)."""
    return MODELS.register(spec, replace=True)


def _underactuated(full_hdot: bool, corrected_c0: bool) -> Build:
    def build(robot: Robot, backend: str) -> DynamicsModel:
        from .underactuated import UnderactuatedGJM

        return UnderactuatedGJM(robot, full_hdot=full_hdot, corrected_c0=corrected_c0, backend=backend)
    return build


def _nidc(translation: bool) -> Build:
    def build(robot: Robot, backend: str) -> DynamicsModel:
        from .underactuated import NIDCModel

        return NIDCModel(robot, translation=translation, backend=backend)
    return build


def _generalized(variant: str) -> Build:
    def build(robot: Robot, backend: str) -> DynamicsModel:
        from .generalized import GeneralizedInertiaModel

        return GeneralizedInertiaModel(robot, variant, backend)
    return build


for _spec in (
    ModelSpec("exact", "Pinocchio ABA: the exact reference", True, lambda robot, backend: ExactModel(robot)),
    ModelSpec("standard", "FM-ST-A as printed: dx0/dq = 0, Hdot over the joints only, c0 = 0 (eqs 97-115)", True,
              _underactuated(False, False)),
    ModelSpec("standard_full_hdot", "FM-ST-A with the full Hdot but c0 = 0 (sec 3.5): zero linear momentum", True,
              _underactuated(True, False)),
    ModelSpec("standard_corrected", "FM-ST-A with the full Hdot and c0 = [0; v0 x P]: exact", True,
              _underactuated(True, True)),
    ModelSpec("nidc", "FM-NIC-A: FM-ST-A plus the integrated non-inertial dynamic coupling (eqs 59-67, 122)", True,
              _nidc(False)),
    ModelSpec("nidc_translation", "FM-NIC-A read with the base translation kept in dr0i/dq (eqs 55-58)", True,
              _nidc(True)),
    ModelSpec("reduced", "stand-alone model on H* (eqs 92-94): zero momentum", True, _generalized("reduced")),
    ModelSpec("momentum_mono", "conserved non-zero momentum, mono-state Lagrangian (eq 127)", True,
              _generalized("momentum_mono")),
    ModelSpec("momentum_multi", "conserved non-zero momentum, multi-state Lagrangian (eq 128)", True,
              _generalized("momentum_multi")),
    ModelSpec("momentum_routh", "conserved non-zero momentum, Routhian (corrected): zero linear momentum", True,
              _generalized("momentum_routh")),
):
    register(_spec)


def make_model(name: str, robot: Robot, backend: str = "compiled") -> DynamicsModel:
    """The dynamics model called ``name`` for ``robot``.

    ``backend`` picks the implementation of the GJM variants: ``"compiled"`` (default, the
    compiled core) or ``"numpy"`` (the reference in this package); ``exact`` is Pinocchio's ABA
    either way.

    Raises:
        UnknownName: for an unknown name, listing the valid ones.
        InvalidArgument: for ``robot`` not a :class:`~freefloat.robot.robot.Robot`.
    """
    spec = MODELS.get(name, None) if isinstance(name, str) else None
    if spec is None:
        raise UnknownName("dynamics model", name, MODELS)
    an_object("robot", robot, "a Robot (freefloat.load_robot)", (Robot,))
    return spec.build(robot, backend)


__all__ = ["MODELS", "DynamicsModel", "ExactModel", "ModelSpec", "make_model", "register"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
