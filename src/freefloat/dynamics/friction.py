"""Joint friction: viscous and Coulomb, the Coulomb part regularised (thesis proposal sec 9, item 4).

The friction force of joint ``j`` opposes its rate ``qdot_j`` (rad/s or m/s):

.. math:: f_j(\\dot q_j) = b_j \\dot q_j + c_j \\tanh(\\dot q_j / v_s),

``b`` the viscous coefficient (N m s/rad or N s/m, URDF ``<dynamics damping>``), ``c`` the Coulomb
level (N m or N, URDF ``<dynamics friction>``), ``v_s`` the slip speed of the regularisation. It
enters the equations of motion as a generalised force on the joint's row, ``M qddot + h = tau -
f(qdot)``, and dissipates ``f(qdot) . qdot >= 0`` (W).

Why ``tanh`` rather than an exact stick-slip: every integrator of the registry is explicit with a
fixed step (or an embedded step inside a fixed control period), and the compiled loops share that;
an exact Coulomb law needs event location at each stick/slip switch or a complementarity problem
per step (Moreau-Jean / Stewart-Trinkle time stepping), neither of which those integrators can
host, and it makes the vector field discontinuous at ``qdot = 0`` (an explicit scheme then
chatters about zero). ``tanh`` is smooth, bounded by ``c`` (so a sliding-mode law sees it as a
bounded disturbance) and reaches 96 % of ``c`` at ``2 v_s``. Its price: a joint held by a load
``|tau| < c`` creeps at ``v_s atanh(tau / c)`` instead of sticking, and its slope ``b + c / v_s``
makes the dynamics stiffer: an explicit step ``h`` on a joint of effective inertia ``J`` stays
stable while ``h (b + c / v_s) / J`` is below the method's real stability limit (2.78 for RK4,
:meth:`JointFriction.stiffness`). :data:`SLIP_SPEED` = 0.01 rad/s keeps that product at 0.2 for
the motorised 5R at 0.1 ms (Coulomb 0.04 N m, J >= 2e-3 kg m^2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument

#: Default slip speed ``v_s`` of the Coulomb regularisation, rad/s (or m/s on a prismatic joint).
SLIP_SPEED = 0.01


@dataclass(frozen=True, eq=False)
class JointFriction:
    """Viscous and regularised Coulomb friction on ``n`` joints.

    Attributes:
        viscous: ``b`` (n,), N m s/rad or N s/m, >= 0.
        coulomb: ``c`` (n,), N m or N, >= 0.
        slip_speed: ``v_s`` of ``tanh(qdot / v_s)``, rad/s or m/s, > 0.

    Raises:
        InvalidArgument: for coefficients of different lengths, negative or not finite, or a slip
            speed that is not positive (a negative coefficient would feed energy in).
    """

    viscous: np.ndarray
    coulomb: np.ndarray
    slip_speed: float = SLIP_SPEED

    def __post_init__(self) -> None:
        viscous, coulomb = (np.array(x, dtype=float, ndmin=1) for x in (self.viscous, self.coulomb))
        if viscous.ndim != 1 or viscous.shape != coulomb.shape:
            raise InvalidArgument(f"joint friction: 'viscous' and 'coulomb' must be two vectors of one length, got "
                                  f"shapes {viscous.shape} and {coulomb.shape}")
        for name, values in (("viscous", viscous), ("coulomb", coulomb)):
            if not (np.isfinite(values).all() and (values >= 0.0).all()):
                raise InvalidArgument(f"joint friction: '{name}' must be finite and >= 0 (friction dissipates), got "
                                      f"{values.tolist()}")
        if not (np.isfinite(self.slip_speed) and self.slip_speed > 0.0):
            raise InvalidArgument(f"joint friction: 'slip_speed' must be a positive speed, got {self.slip_speed}")
        viscous.flags.writeable = coulomb.flags.writeable = False
        object.__setattr__(self, "viscous", viscous)
        object.__setattr__(self, "coulomb", coulomb)
        object.__setattr__(self, "slip_speed", float(self.slip_speed))

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.viscous)

    def force(self, rate: np.ndarray) -> np.ndarray:
        """``f(qdot) = b qdot + c tanh(qdot / v_s)`` (..., n) for joint rates ``rate`` (..., n)."""
        rate = np.asarray(rate, dtype=float)
        return self.viscous * rate + self.coulomb * np.tanh(rate / self.slip_speed)

    def power(self, rate: np.ndarray) -> np.ndarray:
        """Power dissipated, ``f(qdot) . qdot`` (...,), W: never negative."""
        rate = np.asarray(rate, dtype=float)
        return np.sum(self.force(rate) * rate, axis=-1)

    def stiffness(self) -> np.ndarray:
        """Largest slope of each joint's friction, ``b + c / v_s`` (n,), N m s/rad (at zero rate):
        divided by the joint's effective inertia, the rate an explicit step must resolve."""
        return self.viscous + self.coulomb / self.slip_speed

    def __bool__(self) -> bool:
        """False when every coefficient is zero (no friction at all)."""
        return bool(np.any(self.viscous) or np.any(self.coulomb))

    def __getitem__(self, joints) -> JointFriction:
        """The friction of some joints (an index array or slice), same slip speed."""
        return JointFriction(self.viscous[joints], self.coulomb[joints], self.slip_speed)

    @classmethod
    def none(cls, n: int) -> JointFriction:
        """No friction on ``n`` joints."""
        return cls(np.zeros(n), np.zeros(n))

    @classmethod
    def of_model(cls, model: pin.Model, slip_speed: float = SLIP_SPEED) -> JointFriction:
        """The friction of every velocity coordinate (nv,) of a Pinocchio model: ``model.damping``
        (viscous) and ``model.friction`` (Coulomb), which Pinocchio's URDF parser fills from each
        joint's ``<dynamics damping friction>`` (zero where absent, and on a floating root)."""
        return cls(np.array(model.damping, dtype=float), np.array(model.friction, dtype=float), slip_speed)

    @classmethod
    def concatenate(cls, parts: list[JointFriction]) -> JointFriction:
        """One friction over the joints of ``parts`` in turn (all of one slip speed).

        Raises:
            InvalidArgument: for parts of different slip speeds, or none.
        """
        speeds = {p.slip_speed for p in parts}
        if len(speeds) != 1:
            raise InvalidArgument(f"joint friction: cannot join frictions of slip speeds {sorted(speeds)} (or none)")
        return cls(np.concatenate([p.viscous for p in parts]), np.concatenate([p.coulomb for p in parts]), speeds.pop())
