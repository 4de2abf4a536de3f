"""The conservation oracle: a run whose scene promises a conserved or balanced quantity is checked
at its end, and a violation makes it a failed run, not a completed one.

The quantities are read from the run's summary, never recomputed (:mod:`freefloat.dynamics.metrics`,
:mod:`freefloat.dynamics.balance`, the wheel, capture and closure summaries):

- momentum (N s or N m s, one number over the linear and angular parts):
  ``momentum_drift_max`` (no external wrench), ``momentum_balance_max`` (against the wrenches' and
  fields' impulse), ``wheel_momentum_balance_max`` (the wheels' stored momentum against the rest
  of the robot), ``momentum_balance_error`` (a capture: the merged robot after the grasp against
  robot and target before), ``momentum_drift_after_impact``;
- closures (m): ``closure_drift_max`` (a robot scene's loops, a two-hand grasp),
  ``loop_closure_drift_max`` (a mechanism).

Each is held to ``tolerance * scale``. The tolerance follows the integrator's global order ``p``
and step ``h`` (:func:`tolerance`): ``max(1e-6, (h / 0.1 s)^p)``, at most 0.5 (1e-6 for RK4 at
1 ms, 1e-2 for Euler at 1 ms); a momentum balance against fields, summed over the recorded rows,
also takes the second-order tolerance of the rows' spacing. The scale is the run's own: for momentum the largest of the momentum the
run carried (``momentum_scale``), the external impulse applied, the capture's momentum before the
grasp, the wheels' largest stored momentum and the internal impulse ``peak_joint_torque *
duration`` (a mechanism's ``peak_efforts``) the joints could exchange; for closures the length :data:`LENGTH_SCALE`, and never below
:data:`CLOSURE_FLOOR`. Energy
balances are reported, not checked: their scale (the largest kinetic energy) is not in the summary.

:func:`check` is the one function both the runner and the project's fuzzer call.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

#: Smallest relative tolerance: a run this close is never failed (round-off, solver tolerances).
TOLERANCE_FLOOR = 1e-6
#: The time (s) against which the step is measured: the fastest motion of the built-in scenes is
#: of this order (a 0.1 s impulse), so ``(h / T_REF)^p`` is the global error an order-p method makes.
T_REF = 0.1
#: Length (m) the closure drift is measured against: the size of the built-in robots' links.
LENGTH_SCALE = 1.0
#: Closure drift (m) never failed: a loop held to a millimetre is held. Without Baumgarte a loop
#: drifts by the integrator's error, which the stability study maps (its stable runs: at most 1 mm).
CLOSURE_FLOOR = 1e-3

MOMENTUM_KEYS = ("momentum_drift_max", "momentum_balance_max", "wheel_momentum_balance_max",
                 "momentum_balance_error", "momentum_drift_after_impact")
CLOSURE_KEYS = ("closure_drift_max", "loop_closure_drift_max")
#: The unit of each summary key the runner adds for this check.
UNITS = {"integrator_order": "", "integrator_step": "s", "record_step": "s", "duration": "s", "conservation_margin": ""}


class Checked(NamedTuple):
    """One checked quantity: its summary key, its value and bound (same unit) and ``value / bound``."""

    quantity: str
    value: float
    bound: float
    margin: float


def tolerance(order: int, step: float) -> float:
    """Relative tolerance of an order-``order`` integrator at ``step`` s: ``max(TOLERANCE_FLOOR,
    (step / T_REF)^order)``, at most 0.5."""
    return float(min(0.5, max(TOLERANCE_FLOOR, (step / T_REF) ** max(order, 1))))


def momentum_scale(summary: Mapping[str, Any]) -> float:
    """The run's momentum scale (N s or N m s): the largest of what it carried, applied or could
    exchange internally (see the module's docstring)."""
    efforts = summary.get("peak_efforts")  # a mechanism's actuators, N or N m
    peak = max([_number(summary.get("peak_joint_torque")),
                *(_number(e) for e in (efforts if isinstance(efforts, (list, tuple)) else ()))])
    candidates = [_number(summary.get("momentum_scale")), peak * _number(summary.get("duration"))]
    for key in ("external_impulse", "momentum_before_impact"):
        vector = summary.get(key)
        if isinstance(vector, (list, tuple)) and len(vector) == 6:
            candidates += [float(np.linalg.norm(vector[:3])), float(np.linalg.norm(vector[3:]))]
    stored = summary.get("wheel_momentum_max")
    if isinstance(stored, Mapping):
        candidates.append(sum(_number(v) for v in stored.values()))
    return max(candidates)


def checked(summary: Mapping[str, Any]) -> list[Checked]:
    """Every conserved or balanced quantity ``summary`` carries, with its bound; none without the
    integrator's ``integrator_order`` and ``integrator_step`` (a run the oracle does not cover)."""
    order, step = summary.get("integrator_order"), summary.get("integrator_step")
    if not isinstance(order, int) or not isinstance(step, float):
        return []
    scales = {key: momentum_scale(summary) for key in MOMENTUM_KEYS} | {key: LENGTH_SCALE for key in CLOSURE_KEYS}
    out = []
    for key, scale in scales.items():
        value = summary.get(key)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            bound = _tolerance(summary, key) * scale if scale > 0.0 else TOLERANCE_FLOOR
            if key in CLOSURE_KEYS:
                bound = max(bound, CLOSURE_FLOOR)
            out.append(Checked(key, float(value), bound, float(value) / bound))
    return out


def _tolerance(summary: Mapping[str, Any], key: str) -> float:
    """The tolerance of ``key`` in ``summary``: the integrator's (:func:`tolerance`); for
    ``momentum_balance_max``, whose fields' impulse is a trapezoidal sum over the recorded rows,
    at least that of a second-order rule at the rows' spacing ``record_step``."""
    tol = tolerance(summary["integrator_order"], summary["integrator_step"])
    rows = summary.get("record_step")
    if key == "momentum_balance_max" and isinstance(rows, float):
        tol = max(tol, tolerance(2, rows))
    return tol


def check(summary: Mapping[str, Any]) -> str | None:
    """The message of the worst violation in ``summary`` (``momentum_drift_max 2.2 exceeds its
    bound 1.3e-05 ...``), or None when every checked quantity is within its bound."""
    worst = max(checked(summary), key=lambda c: c.margin, default=None)
    if worst is None or worst.margin <= 1.0:
        return None
    return (f"conservation violated: {worst.quantity} {worst.value:.3g} exceeds its bound {worst.bound:.3g} "
            f"(margin {worst.margin:.3g}; tolerance {_tolerance(summary, worst.quantity):.3g} of the run's scale)")


def _number(value: object) -> float:
    """``value`` as a finite float, 0 when it is none."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value):
        return float(value)
    return 0.0
