"""A closed chain by Pinocchio's ``constraintDynamics`` on its spanning tree: the reference plant
the coupled (Orsino) plant is compared with."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ...errors import InvalidArgument, SimulationDiverged
from ..friction import JointFriction


class ConstraintDynamicsPlant:
    """``pin.constraintDynamics`` on a tree's coordinates with rigid closures, by Pinocchio's
    proximal solver (mu 1e-12 unless given).

    Args:
        model: the spanning tree (fixed or floating base), gravity set.
        constraints: one ``pin.RigidConstraintModel`` per closure (copied; their Baumgarte
            correctors are set here).
        actuated: velocity index of each actuated joint (k,): efforts ``u`` act there.
        baumgarte: lambda, 1/s: every corrector gets ``Kp = lambda^2``, ``Kd = 2 lambda`` (the
            same correction as eq 129).
        max_drift: a closure gap above this (m) is a blow-up.
        accuracy, iterations: the proximal solver's accuracy and most iterations.
        mu: the proximal solver's regularisation (larger: better conditioned where closure rows
            are redundant, more iterations elsewhere).
        friction: joint friction over the model's velocity coordinates (nv,), applied as the
            generalised force ``-f(v)`` (Pinocchio itself ignores ``model.damping`` and
            ``model.friction``); None: none. The armature is the model's own (``model.armature``).

    Raises:
        InvalidArgument: for a friction of another size than nv.
    """

    name = "constraint_dynamics"

    def __init__(self, model: pin.Model, constraints: Sequence, actuated: Sequence[int], baumgarte: float = 0.0,
                 max_drift: float = 1.0, accuracy: float = 1e-12, iterations: int = 50, mu: float = 1e-12,
                 friction: JointFriction | None = None):
        if friction is not None and friction.n != model.nv:
            raise InvalidArgument(f"constraint dynamics plant: the friction is for {friction.n} coordinates, the model "
                                  f"has nv = {model.nv}")
        self.space, self.baumgarte, self.max_drift = model, float(baumgarte), float(max_drift)
        self.friction = friction if friction else None
        self.actuated = np.asarray(actuated, dtype=int)
        self.n_efforts = len(self.actuated)
        self.constraints = [pin.RigidConstraintModel(cm) for cm in constraints]
        for cm in self.constraints:
            cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(self.baumgarte**2, 2.0 * self.baumgarte))
        self.data = model.createData()
        self.cdatas = [cm.createData() for cm in self.constraints]
        pin.initConstraintDynamics(model, self.data, self.constraints, self.cdatas)
        self.settings = pin.ProximalSettings(accuracy, mu, iterations)
        self.tau = np.zeros(model.nv)
        self.kinematics = model.createData()

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Joint accelerations (nv,) under actuator efforts ``u`` (k,) on the actuated joints.

        Raises:
            SimulationDiverged: when Pinocchio rejects the state (not finite, singular).
        """
        self.tau[self.actuated] = u
        tau = self.tau if self.friction is None else self.tau - self.friction.force(v)
        try:
            return pin.constraintDynamics(self.space, self.data, q, v, tau, self.constraints, self.cdatas,
                                          self.settings).copy()
        except (RuntimeError, ValueError) as exc:
            raise SimulationDiverged(f"constraintDynamics failed: {exc}") from exc

    def drift(self, q: np.ndarray) -> tuple[float, float]:
        """Largest distance between the two frames of any closure (m) and, for 6-D closures,
        largest angle between them (rad)."""
        data = self.kinematics
        pin.forwardKinematics(self.space, data, q)
        position = orientation = 0.0
        for cm in self.constraints:
            first = data.oMi[cm.joint1_id] * cm.joint1_placement
            second = data.oMi[cm.joint2_id] * cm.joint2_placement
            position = max(position, float(np.linalg.norm(first.translation - second.translation)))
            if cm.type == pin.ContactType.CONTACT_6D:
                orientation = max(orientation, float(np.linalg.norm(pin.log3(first.rotation.T @ second.rotation))))
        return position, orientation
