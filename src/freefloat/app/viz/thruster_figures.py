"""The thrusters over a run (the ``thrusters`` figure): each thruster's thrust and the propellant
burnt (:meth:`freefloat.space.thrusters.ThrusterSet.rows`)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .plotting import curve, figure, finish


def thruster_figure(t: np.ndarray, thrust: np.ndarray, propellant: np.ndarray, specific_impulse: float) -> Figure:
    """Above, the thrust held over each control period (N) of every thruster that fires, as steps
    (pulses averaged over the period); below, the propellant burnt since the start (g) vs t
    (``thrust`` (N, k), ``propellant`` (N,) kg, ``specific_impulse`` s)."""
    fig, (thrust_ax, propellant_ax) = figure(2, 1, (9.0, 6.5), "Thrusters: thrust and propellant", right=0.8)
    firing = [i for i in range(thrust.shape[1]) if np.any(thrust[:, i])]
    for i in firing:
        curve(thrust_ax, t, thrust[:, i], f"thruster {i}", drawstyle="steps-post")
    finish(thrust_ax, "t (s)", "thrust (N)", f"thrust held over each period, {len(firing)} of {thrust.shape[1]} "
           "thrusters firing", legend="outside" if firing else None)
    curve(propellant_ax, t, 1e3 * propellant, "propellant burnt")
    finish(propellant_ax, "t (s)", "propellant (g)", f"propellant burnt, I_sp {specific_impulse:g} s: "
           f"{1e3 * propellant[-1]:.4g} g at the end", legend=None)
    return fig
