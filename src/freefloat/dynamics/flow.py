r"""First-order systems on the configuration Lie group, stepped by the engine's integrators.

Where a velocity field gives the motion, ``q' = V(t, q)`` (free-floating kinematics: the joint
rates of a plan and the conserved momentum give the base's velocity), the state is the
configuration alone. :func:`rollout` steps it over a time grid with a fixed-step integrator of
:data:`~freefloat.dynamics.integrators.INTEGRATORS`, each grid interval one call of the
integrator's first-order form (:meth:`~freefloat.dynamics.integrators.fixed_step.FixedStep.flow`:
the same tableau as its second-order steps, Munthe-Kaas's RKMK in the exponential chart, of the
integrator's order on the group).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import InvalidArgument
from .integrators import INTEGRATORS, Velocity, make_integrator


def first_order(integrator: str, model: pin.Model):
    """The integrator ``integrator`` on ``model``, built for first-order systems.

    Raises:
        UnknownName: for a name not in the registry.
        InvalidArgument: for an integrator without a first-order form (the adaptive ones),
            naming those that have one.
    """
    built = make_integrator(integrator, model)
    if not hasattr(built, "flow"):
        able = [name for name, spec in INTEGRATORS.items() if not spec.adaptive]
        raise InvalidArgument(f"integrator: '{integrator}' steps no first-order system (fixed-step ones do: "
                              f"{', '.join(able)})")
    return built


def rollout(velocity: Velocity, model: pin.Model, q0: np.ndarray, times: np.ndarray,
            integrator: str = "rkmk4") -> tuple[np.ndarray, np.ndarray]:
    """Configurations and velocities of ``q' = velocity(t, q)`` on the grid ``times`` (N,), s,
    from ``q0`` (nq,) at ``times[0]``: one step of ``integrator`` per interval.

    Returns:
        ``(qs, vs)``: (N, nq) and (N, nv); ``vs[k] = velocity(times[k], qs[k])`` (each also the
        first stage of the step from ``times[k]``, so it costs no further call).

    Raises:
        InvalidArgument: for an integrator without a first-order form (see :func:`first_order`).
    """
    stepper = first_order(integrator, model)
    qs, vs = [np.asarray(q0, float)], [velocity(times[0], np.asarray(q0, float))]
    for k in range(len(times) - 1):
        qs.append(stepper.flow(velocity, qs[-1], times[k], times[k + 1] - times[k], vs[-1]))
        vs.append(velocity(times[k + 1], qs[-1]))
    return np.array(qs), np.array(vs)


def stage_times(times: np.ndarray, integrator: str = "rkmk4") -> np.ndarray:
    """Every time :func:`rollout` asks the velocity for on the grid ``times`` with
    ``integrator``, computed as it computes them (a caller can tabulate the velocity's time
    dependence there beforehand)."""
    steps = times[1:] - times[:-1]
    nodes = first_order(integrator, pin.Model()).nodes
    return np.unique(np.concatenate([times, *(times[:-1] + steps * c for c in nodes if c > 0.0)]))
