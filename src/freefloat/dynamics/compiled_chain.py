"""The closed-chain loop in compiled code (``freefloat.dynamics._sim.ChainSimulation``).

The same loop as :func:`freefloat.dynamics.simulation.run_plant` on a
:class:`~freefloat.dynamics.plants.CoupledChainPlant`, period for period: eq 129 with Baumgarte
from the mechanism's compiled core (``cpp/chains/mechanism.hpp``), the integrators of the registry on the
Euclidean coordinates (``cpp/sim/rkmk.hpp`` on R^n), the platform control of
``freefloat.parallel.sliding_mode.PlatformControl`` (its ``compiled_law()``: computed torque or
sliding mode on the nominal model, a circle reference; held over each period or evaluated at
every stage) and the telemetry row of :class:`~.plant_periods.PlantPeriods`. Python is entered
once per telemetry chunk or progress report.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InvalidArgument
from . import _sim
from .compiled import CompiledEngine
from .integrators import INTEGRATORS
from .plants import CoupledChainPlant

__all__ = ["CompiledChainLoop", "unsupported"]


def unsupported(plant: Any, integrator: str, controller: Any, stop: Any) -> str | None:
    """Why this run cannot use the compiled closed-chain loop, or None when it can: a
    :class:`CoupledChainPlant` whose mechanism has a compiled core, an integrator the compiled
    loop has, a controller with a ``compiled_law()`` (or none), and no stop event."""
    spec = INTEGRATORS.get(integrator, None)
    if spec is None or not spec.compiled:
        return f"integrator '{integrator}' is not compiled"
    if not isinstance(plant, CoupledChainPlant):
        return f"plant '{getattr(plant, 'name', plant)}' is not a coupled chain"
    if type(plant).acceleration is not CoupledChainPlant.acceleration:
        return "the plant's acceleration is overridden in Python"
    if getattr(plant.mechanism, "core", None) is None:
        return ("the mechanism has no compiled core (numpy backend, a non-square A°, a turning platform, or joint "
                "armature or friction)")
    if controller is not None and _law(controller) is None:
        return "the controller has no compiled law"
    if stop is not None:
        return "a stop event needs Python between periods"
    return None


def _law(controller: Any) -> Any:
    return getattr(controller, "compiled_law", lambda: None)()


class CompiledChainLoop(CompiledEngine):
    """One compiled run of a coupled closed chain: plant, integrator, law, telemetry. The same
    interface as :class:`~.plant_periods.PlantPeriods`.

    Args:
        plant: a coupled chain with a compiled core.
        controller: a controller with ``compiled_law()`` (``PlatformControl``, or ``Sampled`` over
            one), or None (zero efforts).
        integrator: a registry name with ``compiled``; ``substeps``, ``rtol``, ``atol`` its settings.
        control_period: zero-order-hold period, s.
        start_time: time of period 0, s.
        per_stage: the law evaluated at every stage instead of held.
        record_every: one telemetry row every this many periods.

    Raises:
        InvalidArgument: for an integrator the compiled loop does not have, or a law whose model
            differs in size from the plant.
    """

    def __init__(self, plant: CoupledChainPlant, controller: Any, integrator: str, control_period: float,
                 start_time: float = 0.0, substeps: int = 1, rtol: float = 1e-10, atol: float = 1e-12,
                 per_stage: bool = False, record_every: int = 1):
        spec = INTEGRATORS.get(integrator, None)
        if spec is None or not spec.compiled:
            raise InvalidArgument(f"integrator '{integrator}' is not compiled; compiled: "
                                  f"{', '.join(n for n, s in INTEGRATORS.items() if s.compiled)}")
        chains, coupling = plant.mechanism.core_arrays()
        self.plant = plant
        try:
            self.sim = _sim.ChainSimulation(chains, coupling, plant.baumgarte, plant.max_drift, integrator, substeps,
                                            rtol, atol, control_period, start_time, record_every, per_stage)
            law = _law(controller) if controller is not None else None
            if law is not None:
                law.install(self.sim)
        except ValueError as exc:
            raise InvalidArgument(f"compiled closed-chain loop: {exc}") from exc

    def start(self, q: np.ndarray, v: np.ndarray, period: int = 0) -> None:
        """Set the state at period ``period``."""
        self.sim.set_state(q, v, period)

    def hold(self, u: np.ndarray) -> None:
        """Hold the efforts ``u`` (k,) from the current period on."""
        self.sim.hold(np.asarray(u, dtype=float))

    def set_wrenches(self, field: object) -> None:
        """Plants take no external wrenches yet.

        Raises:
            InvalidArgument: for any field.
        """
        if field is not None:
            raise InvalidArgument("compiled closed-chain loop: external wrenches are not supported")

    def law_efforts(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The compiled law's efforts (k,) at time ``t`` and state ``(q, v)``."""
        return self.sim.law_efforts(t, q, v)
