"""The closed-chain bench's plants and the coordinates every method is judged in.

Two formulations of one mechanism's forward dynamics under held actuator efforts, both plants of
the one loop (:mod:`freefloat.dynamics.plants`):

* :class:`~freefloat.dynamics.plants.CoupledChainPlant`: Orsino's coupled model, eq 129, on
  ``q = [q#; q°]``, Baumgarte-stabilised with ``lambda``;
* :class:`~freefloat.dynamics.plants.ConstraintDynamicsPlant`: Pinocchio's ``constraintDynamics``
  on the spanning tree with the closure file's ``RigidConstraintModel``s, Baumgarte gains
  ``Kp = lambda^2``, ``Kd = 2 lambda`` (the same correction as eq 129), on the tree's joint
  coordinates (:func:`constraint_dynamics_plant`), its controller reading Orsino's coordinates
  through :class:`ObservedController`.

Both are judged in the spanning tree (:class:`SpanningTree`): Orsino's coordinates map onto the
tree's joints (q# dropped), and the shared coordinates, the constraint drift and the
controller's view of the state are all computed there, one way for every method.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from ....dynamics.plants import ConstraintDynamicsPlant
from ....errors import InvalidArgument
from ....parallel.closed_chain import AXES, ClosedChain
from ....parallel.five_bar import five_bar_spec
from ....parallel.registry import FIVE_BAR_PLANTS
from ....robot.builders import build_urdf, urdf_xml


@dataclass
class SpanningTree:
    """Pinocchio's tree of the simulated plant, with its closures, and the maps to Orsino's ``q``.

    Attributes:
        model: fixed-base tree model (the plant's inertias), gravity set.
        constraints: one ``RigidConstraintModel`` per closure (the closure file's).
        platform_frame: frame id of the platform point whose coordinates are q#.
        axes: which inertial coordinates (0 x, 1 y, 2 z) of that point form q# (p,).
        actuated: tree coordinate index of each actuated joint (k,).
        from_orsino: Orsino coordinate index of each tree coordinate (nq,); a joint that shares
            a coordinate (the parallelogram's second bar) repeats it.
        to_orsino: tree coordinate index of each of Orsino's joint coordinates q° (n_q - p,).
    """

    model: pin.Model
    constraints: list
    platform_frame: int
    axes: list[int]
    actuated: np.ndarray
    from_orsino: np.ndarray
    to_orsino: np.ndarray
    data: pin.Data = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data = self.model.createData()

    def platform(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Platform coordinates q# (p,), m, and their rates (p,), m/s, inertial frame, at tree
        state ``(q, v)`` (nq,)."""
        pin.forwardKinematics(self.model, self.data, q, v)
        frame = pin.updateFramePlacement(self.model, self.data, self.platform_frame)
        rate = pin.getFrameVelocity(self.model, self.data, self.platform_frame, pin.LOCAL_WORLD_ALIGNED).linear
        return frame.translation[self.axes].copy(), rate[self.axes].copy()

    def shared(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The coordinates every method is judged in, at tree state ``(q, v)``:
        ``[q#; q_a; qdot#; qdot_a]`` (2 (p + k),): platform point (m, inertial frame), actuated
        joints (rad or m), then their rates."""
        x, xd = self.platform(q, v)
        return np.concatenate((x, q[self.actuated], xd, v[self.actuated]))

    def orsino_state(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Orsino's ``(q, qdot)`` (n_q,) at tree state ``(q, v)``: q# and its rate from the
        platform frame, q° from the tree's joints (what a controller written for Orsino's
        coordinates reads)."""
        x, xd = self.platform(q, v)
        return np.concatenate((x, q[self.to_orsino])), np.concatenate((xd, v[self.to_orsino]))

    def gap(self, q: np.ndarray) -> float:
        """Largest distance (m) between the two points of any closure at tree configuration ``q``."""
        pin.forwardKinematics(self.model, self.data, q)
        worst = 0.0
        for cm in self.constraints:
            a = self.data.oMi[cm.joint1_id].act(cm.joint1_placement.translation)
            b = self.data.oMi[cm.joint2_id].act(cm.joint2_placement.translation)
            worst = max(worst, float(np.linalg.norm(a - b)))
        return worst


def spanning_tree(chain: ClosedChain, model: pin.Model, platform: str, coordinates: list[str]) -> SpanningTree:
    """The tree of ``chain`` (its closures and coordinate map) with the plant's ``model``
    (same joints as ``chain.model``, possibly other inertias); q# = ``coordinates`` of frame ``platform``."""
    p = chain.mechanism.p
    from_orsino = np.empty(model.nq, dtype=int)
    owner: dict[int, int] = {}
    for j, i in sorted(chain.joint_coordinates.items()):
        from_orsino[model.idx_qs[j]] = i
        owner.setdefault(i, model.idx_qs[j])
    return SpanningTree(model=model, constraints=chain.constraints, platform_frame=model.getFrameId(platform),
                        axes=[AXES[c] for c in coordinates],
                        actuated=np.array([model.idx_qs[j] for j in chain.actuated]), from_orsino=from_orsino,
                        to_orsino=np.array([owner[p + i] for i in range(len(owner))]))


def plant_model(chain: ClosedChain, mechanism: str, plant: str) -> pin.Model:
    """Pinocchio's tree with the plant's inertias: the closure file's model for ``"nominal"``,
    else (the 5R's ``true_15``, ``true_50``) the same tree built from those parameters.

    Raises:
        FreefloatError: for another mechanism's non-nominal plant.
    """
    if plant == "nominal":
        return chain.model
    if mechanism != "five_bar" or plant not in FIVE_BAR_PLANTS:
        raise InvalidArgument(f"bench: no Pinocchio tree for mechanism '{mechanism}' with plant '{plant}'")
    true = pin.buildModelFromXML(urdf_xml(build_urdf(five_bar_spec(FIVE_BAR_PLANTS[plant]))))
    model = pin.Model(chain.model)
    for j in range(1, model.njoints):
        model.inertias[j] = true.inertias[j]
    return model


@dataclass(frozen=True)
class ObservedController:
    """A controller written for Orsino's coordinates driving a plant on the tree's: it reads
    ``(q, qdot)`` through :meth:`SpanningTree.orsino_state`."""

    control: Any
    tree: SpanningTree

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The controller's efforts (k,) at tree state ``(q, v)``."""
        return self.control.torque(t, *self.tree.orsino_state(q, v))

    def reference(self, t: float) -> np.ndarray:
        """The controller's reference."""
        return self.control.reference(t)


def constraint_dynamics_plant(tree: SpanningTree, baumgarte: float) -> ConstraintDynamicsPlant:
    """Pinocchio's ``constraintDynamics`` on ``tree`` with its closures, efforts on the actuated
    joints (the tree's joints have one coordinate each: nq = nv)."""
    return ConstraintDynamicsPlant(tree.model, tree.constraints, tree.actuated, baumgarte)
