"""Integrators on the configuration Lie group, one registry of objects: :data:`INTEGRATORS`.

Each entry carries what the rest of freefloat needs to know about an integrator (its order, the
dynamics evaluations of one step, whether it corrects the chart with ``dexp^-1``, whether the
compiled loop has it) and builds it. A new integrator is one module plus one :func:`register`
call; the scene schema, the run-size estimate, the compiled-loop check, the bench and the
stability study read their lists here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import pinocchio as pin

from ...arguments import an_object, real_number, whole_number
from ...errors import UnknownName
from ...registry import Registry
from .adaptive import BogackiShampine32, DormandPrince45
from .base import Acceleration, Integrator, StageAcceleration, TimeVarying, Velocity, at_stage_time
from .dop853 import DormandPrince853
from .explicit_rkmk import RungeKuttaMuntheKaas3, RungeKuttaMuntheKaas6, RungeKuttaMuntheKaas8
from .fixed_step import ExplicitEuler, RungeKutta4, SemiImplicitEuler
from .momentum_projection import MomentumProjection

#: ``build(model, substeps, rtol, atol) -> Integrator`` on the configuration space ``model``.
Build = Callable[[pin.Model, int, float, float], Integrator]


@dataclass(frozen=True)
class IntegratorSpec:
    """One integrator of the registry.

    Attributes:
        name: registry name (scene key ``simulation.integrator``).
        description: one line for listings and docs.
        order: global order of accuracy on the Lie group (on a vector space, the tableau's order).
        stages: dynamics evaluations per step (for the adaptive ones: per accepted step, about).
        lie: True when stage velocities are corrected by ``dexp^-1`` (full order on SE(3)).
        adaptive: True for step-size control (``rtol``, ``atol``); False for fixed steps
            (``substeps`` per control period).
        compiled: True when the compiled loops (``cpp/sim/rkmk.hpp``) have it under the same name.
        build: makes it for a configuration space.
        bench: the loops ``freefloat bench`` sweeps it in (``"python"``, ``"compiled"``).
    """

    name: str
    description: str
    order: int
    stages: int
    lie: bool
    adaptive: bool
    compiled: bool
    build: Build
    bench: tuple[str, ...] = ("python",)


#: Registry: name -> :class:`IntegratorSpec`.
INTEGRATORS: Registry[IntegratorSpec] = Registry("integrator")


def register(spec: IntegratorSpec) -> IntegratorSpec:
    """Add ``spec`` to :data:`INTEGRATORS` (a name already there is replaced)."""
    return INTEGRATORS.register(spec, replace=True)


for _spec in (
    IntegratorSpec("euler", "semi-implicit (symplectic) Euler, 1st order: the dissertation's scheme", order=1,
                   stages=1, lie=True, adaptive=False, compiled=True, bench=("python", "compiled"),
                   build=lambda m, n, rtol, atol: SemiImplicitEuler(m, n)),
    IntegratorSpec("explicit_euler", "explicit (forward) Euler, 1st order: the old rate moves q; not compiled",
                   order=1, stages=1, lie=True, adaptive=False, compiled=False, bench=(),
                   build=lambda m, n, rtol, atol: ExplicitEuler(m, n)),
    IntegratorSpec("rkmk3", "Runge-Kutta-Munthe-Kaas 3 (Kutta's 3 stages), 3rd order on the Lie group", order=3,
                   stages=3, lie=True, adaptive=False, compiled=True, bench=("compiled",),
                   build=lambda m, n, rtol, atol: RungeKuttaMuntheKaas3(m, n)),
    IntegratorSpec("rkmk4", "Runge-Kutta-Munthe-Kaas 4, 4th order on the Lie group", order=4, stages=4, lie=True,
                   adaptive=False, compiled=True, bench=("python", "compiled"),
                   build=lambda m, n, rtol, atol: RungeKutta4(m, n)),
    IntegratorSpec("rk4_naive", "RK4 adding body velocities without dexp^-1: only 2nd order on SE(3)", order=2,
                   stages=4, lie=False, adaptive=False, compiled=True, bench=("python",),
                   build=lambda m, n, rtol, atol: RungeKutta4(m, n, lie_correction=False)),
    IntegratorSpec("rkmk6", "Runge-Kutta-Munthe-Kaas 6 (Butcher's 7 stages), 6th order on the Lie group", order=6,
                   stages=7, lie=True, adaptive=False, compiled=True, bench=("compiled",),
                   build=lambda m, n, rtol, atol: RungeKuttaMuntheKaas6(m, n)),
    IntegratorSpec("rkmk8", "Runge-Kutta-Munthe-Kaas 8 (Cooper-Verner, 11 stages), 8th order on the Lie group",
                   order=8, stages=11, lie=True, adaptive=False, compiled=True, bench=("compiled",),
                   build=lambda m, n, rtol, atol: RungeKuttaMuntheKaas8(m, n)),
    IntegratorSpec("dopri5", "adaptive Dormand-Prince 5(4) in the Munthe-Kaas chart, dense output", order=5,
                   stages=6, lie=True, adaptive=True, compiled=True, bench=("python", "compiled"),
                   build=lambda m, n, rtol, atol: DormandPrince45(m, rtol=rtol, atol=atol)),
    IntegratorSpec("bs32", "adaptive Bogacki-Shampine 3(2) in the Munthe-Kaas chart: 3 evaluations a step, for "
                   "loose tolerances", order=3, stages=3, lie=True, adaptive=True, compiled=True, bench=("compiled",),
                   build=lambda m, n, rtol, atol: BogackiShampine32(m, rtol=rtol, atol=atol)),
    IntegratorSpec("dop853", "adaptive Dormand-Prince 8(5,3) (scipy's DOP853, the thesis's method) in the "
                   "Munthe-Kaas chart: a tight reference, not compiled", order=8, stages=12, lie=True, adaptive=True,
                   compiled=False, bench=(), build=lambda m, n, rtol, atol: DormandPrince853(m, rtol, atol)),
):
    register(_spec)


def swept(loop: str, adaptive: bool) -> tuple[str, ...]:
    """Names ``freefloat bench`` sweeps in ``loop`` (``"python"`` or ``"compiled"``), fixed-step or
    adaptive, in registry order."""
    return tuple(n for n, s in INTEGRATORS.items() if loop in s.bench and s.adaptive == adaptive)


def integrator_spec(name: str) -> IntegratorSpec:
    """The registry entry called ``name``.

    Raises:
        UnknownName: for a name not in :data:`INTEGRATORS`, listing the valid ones.
    """
    try:
        return INTEGRATORS[name]
    except (KeyError, TypeError):
        raise UnknownName("integrator", name, INTEGRATORS) from None


#: Most steps per control period :func:`make_integrator` takes (each is a full step's work).
MAX_SUBSTEPS = 10**6
#: Tightest relative tolerance of the adaptive integrators: below a double's resolution none
#: can be met and the step would shrink without end.
MIN_RTOL = 1e-16


def check_settings(substeps: int, rtol: float, atol: float) -> tuple[int, float, float]:
    """An integrator's settings, checked: ``substeps`` an integer from 1 to :data:`MAX_SUBSTEPS`,
    ``rtol`` in [:data:`MIN_RTOL`, 1], ``atol`` > 0.

    Raises:
        InvalidArgument: naming the setting (``'substeps' must be ...``).
    """
    return (whole_number("substeps", substeps, 1, MAX_SUBSTEPS), real_number("rtol", rtol, low=MIN_RTOL, high=1.0),
            real_number("atol", atol, above=0.0))


def make_integrator(
    name: str,
    model: pin.Model,
    substeps: int = 1,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    project_momentum: bool = False,
) -> Integrator:
    """The integrator called ``name`` (see :data:`INTEGRATORS`) on the configuration space of
    ``model``.

    ``project_momentum`` wraps it in :class:`MomentumProjection` (only for runs whose momentum is
    conserved: no external wrenches, no gravity; the scene option ``simulation.project_momentum``
    is refused together with either).

    Raises:
        UnknownName: for an unknown name, listing the valid ones.
        InvalidArgument: for ``model`` not a ``pinocchio.Model``, ``substeps`` not an integer
            from 1 to :data:`MAX_SUBSTEPS`, ``rtol`` outside [:data:`MIN_RTOL`, 1] or ``atol``
            not > 0 (each named).
    """
    spec = integrator_spec(name)
    an_object("model", model, "a pinocchio.Model (a robot's: robot.model)", (pin.Model,))
    substeps, rtol, atol = check_settings(substeps, rtol, atol)
    if project_momentum:
        return MomentumProjection(spec.build(model, substeps, rtol, atol), model)
    return spec.build(model, substeps, rtol, atol)


__all__ = [
    "INTEGRATORS",
    "MAX_SUBSTEPS",
    "MIN_RTOL",
    "Acceleration",
    "BogackiShampine32",
    "DormandPrince45",
    "DormandPrince853",
    "ExplicitEuler",
    "Integrator",
    "IntegratorSpec",
    "MomentumProjection",
    "RungeKutta4",
    "RungeKuttaMuntheKaas3",
    "RungeKuttaMuntheKaas6",
    "RungeKuttaMuntheKaas8",
    "SemiImplicitEuler",
    "StageAcceleration",
    "TimeVarying",
    "Velocity",
    "at_stage_time",
    "check_settings",
    "integrator_spec",
    "make_integrator",
    "register",
    "swept",
]

from ...lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
