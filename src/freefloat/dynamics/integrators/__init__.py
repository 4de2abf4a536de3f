"""Integrators on the configuration Lie group, selectable by name."""

from __future__ import annotations

import pinocchio as pin

from .adaptive import DormandPrince45
from .base import Acceleration, Integrator
from .explicit_rkmk import RungeKuttaMuntheKaas6, RungeKuttaMuntheKaas8
from .fixed_step import RungeKutta4, SemiImplicitEuler
from .momentum_projection import MomentumProjection

#: Registry names and one-line descriptions.
INTEGRATORS = {
    "euler": "semi-implicit (symplectic) Euler, 1st order: the dissertation's scheme",
    "rkmk4": "Runge-Kutta-Munthe-Kaas 4, 4th order on the Lie group",
    "rk4_naive": "RK4 adding body velocities without dexp^-1: only 2nd order on SE(3)",
    "rkmk6": "Runge-Kutta-Munthe-Kaas 6 (Butcher's 7 stages), 6th order on the Lie group",
    "rkmk8": "Runge-Kutta-Munthe-Kaas 8 (Cooper-Verner, 11 stages), 8th order on the Lie group",
    "dopri5": "adaptive Dormand-Prince 5(4) in the Munthe-Kaas chart, dense output",
}


def make_integrator(
    name: str,
    model: pin.Model,
    substeps: int = 1,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    project_momentum: bool = False,
) -> Integrator:
    """The integrator called ``name`` (see :data:`INTEGRATORS`).

    ``project_momentum`` wraps it in :class:`MomentumProjection` (only for runs whose momentum is
    conserved: no external wrenches, no gravity; the scene option ``simulation.project_momentum``
    is refused together with either).

    Raises:
        ValueError: for an unknown name, listing the valid ones.
    """
    if project_momentum:
        return MomentumProjection(make_integrator(name, model, substeps, rtol, atol), model)
    if name == "euler":
        return SemiImplicitEuler(model, substeps)
    if name in ("rkmk4", "rk4_naive"):
        return RungeKutta4(model, substeps, lie_correction=name == "rkmk4")
    if name == "rkmk6":
        return RungeKuttaMuntheKaas6(model, substeps)
    if name == "rkmk8":
        return RungeKuttaMuntheKaas8(model, substeps)
    if name == "dopri5":
        return DormandPrince45(model, rtol=rtol, atol=atol)
    raise ValueError(f"unknown integrator '{name}'; valid: {', '.join(INTEGRATORS)}")


__all__ = [
    "INTEGRATORS",
    "Acceleration",
    "DormandPrince45",
    "Integrator",
    "MomentumProjection",
    "RungeKutta4",
    "RungeKuttaMuntheKaas6",
    "RungeKuttaMuntheKaas8",
    "SemiImplicitEuler",
    "make_integrator",
]
