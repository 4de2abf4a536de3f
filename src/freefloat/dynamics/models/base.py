"""What a dynamics model is: accelerations from state, torques and external wrenches."""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np
import pinocchio as pin

from ...arguments import real_array
from ...errors import InvalidArgument


class DynamicsModel(Protocol):
    """Forward dynamics of a free-floating robot.

    Attributes:
        name: registry name of the variant.
    """

    name: str

    def acceleration(
        self,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        fext: Sequence[pin.Force] | None = None,
    ) -> np.ndarray:
        """Generalized acceleration (nv,), Pinocchio convention (base part: derivative of the
        base-link local twist).

        Args:
            q: configuration (nq,).
            v: velocity (nv,).
            tau: generalized forces (nv,); zero on the base rows of a free-floating robot.
            fext: one wrench ``pin.Force`` [f; n] per Pinocchio joint (njoints): joint-frame axes,
                moment about the joint-frame origin; or None.
        """
        ...

    def joint_space_at(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(H, c)`` with ``tau = H qddot + c`` for the actuated joints (n, n), (n,): the model
        as a computed-torque controller sees it. Models with an internal state (``nidc``) also
        have ``end_period(q, v, dt)``, called once per control period with the period's start
        state."""
        ...


def checked(acceleration: Callable[..., np.ndarray]) -> Callable[..., np.ndarray]:
    """A model's ``acceleration`` that refuses wrong-sized or non-finite arguments with
    :class:`~freefloat.errors.InvalidArgument` naming the argument, instead of Pinocchio's C++
    message or NaN accelerations. The check runs only when the call fails or its result is not
    finite, so the simulation's hot loop pays one ``isfinite`` per call; lists that Pinocchio's
    bindings refuse are taken as numpy arrays."""

    @functools.wraps(acceleration)
    def guarded(self: Any, q: np.ndarray, v: np.ndarray, tau: np.ndarray, fext: Any = None) -> np.ndarray:
        try:
            result = acceleration(self, q, v, tau, fext)
        except InvalidArgument:
            raise
        except (ValueError, RuntimeError, TypeError, IndexError):
            check_arguments(self, q, v, tau, fext)
            if all(isinstance(a, np.ndarray) for a in (q, v, tau)):
                raise
            return guarded(self, *(np.asarray(a, dtype=float) for a in (q, v, tau)), fext)  # lists, as numpy takes them
        if not np.isfinite(result).all() or _complex(q, v, tau):
            check_arguments(self, q, v, tau, fext)
        return result

    return guarded


def _complex(q: Any, v: Any, tau: Any) -> bool:
    """Whether ``q``, ``v`` or ``tau`` is an array of complex numbers (numpy would drop their
    imaginary parts; a list of them fails the conversion and is checked then)."""
    return (type(q) is np.ndarray and q.dtype.kind == "c") or (type(v) is np.ndarray and v.dtype.kind == "c") or \
        (type(tau) is np.ndarray and tau.dtype.kind == "c")


def check_arguments(model: Any, q: Any, v: Any, tau: Any, fext: Any) -> None:
    """Raise :class:`InvalidArgument` naming the first of ``q``, ``v``, ``tau``, ``fext`` of
    ``model.acceleration`` that is not real numbers of the right size, finite and at most
    :data:`~freefloat.arguments.MAX_MAGNITUDE` (nothing if all fit)."""
    pin_model = model.robot.model
    for name, value, size in (("q", q, pin_model.nq), ("v", v, pin_model.nv), ("tau", tau, pin_model.nv)):
        try:
            real_array(name, value, (size,))
        except InvalidArgument as exc:
            raise type(exc)(f"{model.name}.acceleration: {exc}") from None
    if fext is not None:
        if len(fext) != pin_model.njoints:
            raise InvalidArgument(f"{model.name}.acceleration: 'fext' must hold one pin.Force per joint "
                                  f"({pin_model.njoints}), got {len(fext)}")
        for i, force in enumerate(fext):
            if not np.isfinite(np.asarray(force.vector)).all():
                raise InvalidArgument(f"{model.name}.acceleration: 'fext[{i}]' must be finite")
