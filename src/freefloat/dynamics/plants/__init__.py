"""Plants: what the one simulation loop integrates (:func:`freefloat.dynamics.simulation.run_plant`).

A plant is a state on a configuration Lie group (``space``, a Pinocchio model the integrators of
:mod:`freefloat.dynamics.integrators` step on), a forward dynamics ``acceleration(q, v, u)`` under
held efforts ``u``, and the constraint residuals it reports (zero for a tree). Registry of the
plant kinds: :data:`PLANTS`. A robot's tree runs through :func:`~freefloat.dynamics.simulation.run`
with any model of :data:`freefloat.dynamics.models.MODELS` (``exact`` is Pinocchio's ABA); the
closed chains are the plants of this package.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...registry import Registry
from .base import Plant
from .closed_tree import ClosedTreePlant
from .constraint_dynamics import ConstraintDynamicsPlant
from .coupled_chain import CoupledChainPlant
from .vector_space import vector_space


@dataclass(frozen=True)
class PlantSpec:
    """One plant kind.

    Attributes:
        name: registry name.
        description: one line.
        closed: True when the plant has loop-closure constraints (and reports their drift).
        compiled: True when the compiled loop has it (``cpp/sim/chain_loop.hpp`` or ``loop.hpp``).
    """

    name: str
    description: str
    closed: bool
    compiled: bool


#: Registry of plant kinds: name -> :class:`PlantSpec`.
PLANTS: Registry[PlantSpec] = Registry("plant")
for _spec in (
    PlantSpec("tree", "a floating- or fixed-base tree: Pinocchio's ABA or a hand-built GJM model (models.MODELS)",
              False, True),
    PlantSpec(CoupledChainPlant.name, "a closed chain by Orsino's subsystem coupling, eq 129, Baumgarte-stabilised",
              True, True),
    PlantSpec(ConstraintDynamicsPlant.name, "a closed chain by Pinocchio's constraintDynamics on its spanning tree "
              "(the reference; a revolute closure as two point contacts on its hinge)", True, False),
    PlantSpec(ClosedTreePlant.name, "a closed chain by freefloat's constrained dynamics on its spanning tree: point, "
              "revolute and weld closures, redundant rows allowed (freefloat.dynamics.closures)", True, False),
):
    PLANTS.register(_spec)

__all__ = ["PLANTS", "ClosedTreePlant", "ConstraintDynamicsPlant", "CoupledChainPlant", "Plant", "PlantSpec", "vector_space"]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
