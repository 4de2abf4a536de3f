r"""The compliant contact law: Hunt-Crossley in the normal direction, regularised Coulomb friction
in the tangent plane.

With d the penetration depth (m), :math:`\dot d` its rate (m/s, > 0 while the shapes press in),
:math:`v_t` the tangential sliding velocity of the second body's material point on the first's at
the contact point (m/s), the force on the second body is

.. math::
    f_n = \max\left(0,\; k d^n + c\, d^n \dot d\right), \qquad
    f_t = -\mu f_n \frac{v_t}{\sqrt{|v_t|^2 + v_s^2}}

along the normal from the first shape to the second and in the tangent plane; the first body
gets the opposite force at the same point. The law never pulls (the max), and the friction is
Coulomb's to within the regularisation velocity :math:`v_s` (a part ``v_s^2 / (2 |v_t|^2)`` short
of ``mu f_n`` at speed ``|v_t|``, linear viscous below it).

Restitution (Hunt & Crossley 1975; the exact first integral): for two bodies meeting head-on with
a normal approach speed :math:`v_{in}`, :math:`m_* \ddot d = -d^n (k + c \dot d)` has the first
integral :math:`m_* (\dot d - (k / c) \ln(1 + c \dot d / k)) / c = -d^{n+1} / (n + 1) + const`,
so the separation speed :math:`e\, v_{in}` solves, with :math:`\alpha = c v_{in} / k`,

.. math::
    \alpha - \ln(1 + \alpha) = -\alpha e - \ln(1 - \alpha e)

whatever the masses and the exponent (:func:`restitution`); to first order
:math:`e = 1 - \tfrac{2}{3} \alpha`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InvalidArgument


@dataclass(frozen=True)
class ContactLaw:
    """Hunt-Crossley normal law with regularised Coulomb friction (module docstring).

    Attributes:
        stiffness: k, N/m^n.
        exponent: n (1.5: Hertz's sphere), > 0.
        damping: c, N s/m^(n+1) (``c / k`` in s/m sets the restitution).
        friction: Coulomb coefficient mu, >= 0.
        slip_speed: regularisation velocity v_s, m/s, > 0.
    """

    stiffness: float
    exponent: float = 1.5
    damping: float = 0.0
    friction: float = 0.0
    slip_speed: float = 1e-3

    def __post_init__(self) -> None:
        for name, value, low in (("stiffness", self.stiffness, 0.0), ("exponent", self.exponent, 0.0),
                                 ("slip_speed", self.slip_speed, 0.0)):
            if not (math.isfinite(value) and value > low):
                raise InvalidArgument(f"contact: {name} must be a positive number, got {value!r}")
        for name, value in (("damping", self.damping), ("friction", self.friction)):
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidArgument(f"contact: {name} must be a number >= 0, got {value!r}")

    def force(self, depth: float, normal: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """Force on the second body, inertial frame, N (3,), at penetration ``depth`` (m, > 0) with
        the unit ``normal`` from the first shape to the second (3,) and the second body's material
        velocity relative to the first's at the contact point, inertial frame, m/s (3,)."""
        along = float(normal @ velocity)
        pressure = depth**self.exponent * (self.stiffness - self.damping * along)  # d_dot = -n . v
        if pressure <= 0.0:
            return np.zeros(3)
        slip = velocity - along * normal
        speed2 = float(slip @ slip)
        return pressure * (normal - self.friction / math.sqrt(speed2 + self.slip_speed**2) * slip)


def restitution(law: ContactLaw, speed: float) -> float:
    """Coefficient of restitution e of a frictionless head-on impact at normal approach speed
    ``speed`` (m/s, > 0): the root of the module's exact relation (1 without damping)."""
    alpha = law.damping * speed / law.stiffness
    if alpha == 0.0:
        return 1.0
    balance = alpha - math.log1p(alpha)
    from scipy.optimize import brentq  # here: scipy costs every run's start 0.6 s

    return brentq(lambda e: -alpha * e - math.log1p(-alpha * e) - balance, 0.0, min(1.0, (1.0 - 1e-15) / alpha),
                  xtol=1e-15, rtol=1e-14)
