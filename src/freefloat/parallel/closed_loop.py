"""A mechanism's closed loop on the one engine: the plant is the mechanism by Orsino's coupling
(:class:`~freefloat.dynamics.plants.CoupledChainPlant`, eq 129 with Baumgarte), integrated by
any integrator of the registry at a fixed step ``h`` by
:func:`freefloat.dynamics.simulation.run_plant` (compiled when it can); the platform law is either
evaluated every ``period`` s (a whole number of steps) and held in between (zero-order hold, as a
digital controller does), or, with ``period`` None, evaluated at every integrator stage at the
stage's time and state ("continuous", the law as the document's analysis assumes it). One
telemetry row per step.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..dynamics.plants import CoupledChainPlant
from ..dynamics.sampled import Sampled
from ..dynamics.simulation import Result, run_plant
from ..errors import InvalidArgument
from .five_bar import FiveBarParameters, elbow_guess, five_bar
from .mechanism import ParallelMechanism


def steps_per_period(period: float, step: float) -> int:
    """Integration steps in one control period.

    Raises:
        FreefloatError: unless ``period`` is a whole number (>= 1) of ``step``.
    """
    n = round(period / step)
    if n < 1 or abs(n * step - period) > 1e-9 * period:
        raise InvalidArgument(f"control period {period} s must be a whole number of integration steps ({step} s)")
    return n


def track(plant: ParallelMechanism, control: Any, q0: np.ndarray, duration: float, step: float,
          period: float | None, baumgarte: float = 100.0, integrator: str = "rkmk4", qd0: np.ndarray | None = None,
          **run: Any) -> Result:
    """Closed loop from ``q0`` (n_q,) (at rest, or at rates ``qd0``) for ``duration`` s: one
    ``integrator`` step of ``step`` s per recorded row, the law (``control.torque(t, q, qd)``)
    held over ``period`` s or, for None, evaluated at every stage.

    Args:
        run: further keywords of :func:`~freefloat.dynamics.simulation.run_plant` (``backend``,
            ``progress``, ``checkpoint``, ``record_every``, ...).

    Raises:
        FreefloatError: for a period that is not a whole number of steps.
    """
    if period is not None:
        every = steps_per_period(period, step)
        control = control if every == 1 else Sampled(control, every)
    qd0 = np.zeros(len(q0)) if qd0 is None else qd0
    return run_plant(CoupledChainPlant(plant, baumgarte), q0, qd0, duration, step, integrator, control,
                     per_stage=period is None, **run)


def track_five_bar(plant: FiveBarParameters, control: Any, duration: float, step: float,
                   start: tuple[float, float] = (0.07, 0.17), **run: Any) -> Result:
    """Sec 5.6's closed loop: the 5R with parameters ``plant``, assembled with outward elbows at
    ``start`` (m) at rest, the law held over each ``step`` s, RK4 (``rkmk4``), Baumgarte 100."""
    mechanism = five_bar(plant)
    point = np.array(start, float)
    q0 = mechanism.assemble(point, elbow_guess(plant, point))
    return track(mechanism, control, q0, duration, step, step, **run)
