"""A tree with loop closures of any kind (point, revolute, weld) as a plant: freefloat's
constrained dynamics (:func:`freefloat.dynamics.closures.solve`), the numpy reference."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument
from ..closures import Closure, closure_drift, solve
from ..friction import JointFriction


class ClosedTreePlant:
    """The constrained dynamics of a spanning tree (fixed or floating base) with its closures,
    Baumgarte-stabilised, efforts on chosen joints.

    Args:
        model: the spanning tree, gravity set.
        closures: the closures (:class:`~freefloat.dynamics.closures.Closure`).
        actuated: velocity index of each actuated joint (k,): efforts ``u`` act there.
        baumgarte: beta, 1/s (``Kp = beta^2``, ``Kd = 2 beta``).
        max_drift: a closure gap above this (m) is a blow-up.
        friction: joint friction over the model's velocity coordinates (nv,), the generalised
            force ``-f(v)``; None: none. The armature is the model's own (``model.armature``).

    Raises:
        InvalidArgument: for a friction of another size than nv.
    """

    name = "closed_tree"

    def __init__(self, model: pin.Model, closures: Sequence[Closure], actuated: Sequence[int], baumgarte: float = 0.0,
                 max_drift: float = 1.0, friction: JointFriction | None = None):
        if friction is not None and friction.n != model.nv:
            raise InvalidArgument(f"closed tree plant: the friction is for {friction.n} coordinates, the model has "
                                  f"nv = {model.nv}")
        self.space, self.closures = model, tuple(closures)
        self.friction = friction if friction else None
        self.actuated = np.asarray(actuated, dtype=int)
        self.n_efforts, self.baumgarte, self.max_drift = len(self.actuated), float(baumgarte), float(max_drift)
        self.data = model.createData()
        self.tau = np.zeros(model.nv)

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Accelerations (nv,) under efforts ``u`` (k,) on the actuated joints.

        Raises:
            SimulationDiverged: when the mass matrix is singular or the result not finite.
        """
        self.tau[self.actuated] = u
        tau = self.tau if self.friction is None else self.tau - self.friction.force(v)
        return solve(self.space, self.data, q, v, tau, self.closures, self.baumgarte).acceleration

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """Largest closure position residual (m) and rotation residual (rad) at ``q``."""
        return closure_drift(self.space, self.data, q, self.closures)
