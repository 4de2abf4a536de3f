"""Where the worst-case gain design has a solution (issue 21 item 5): the gain-feasibility map.

Eq 161's gains need ``(1 - |Delta|_max)^-1`` to exist and be non-negative, which for the
non-negative ``|Delta|_max`` holds if and only if its spectral radius is below 1
(:func:`~freefloat.parallel.gain_design.spectral_radius`). Pointwise, at a platform point x,

.. math:: |\\Delta|_{max}(x) = \\max_{\\theta \\in \\text{vertices}} |H(x; \\theta)^{-1} \\hat H(x) - 1|
          \\quad \\text{(element-wise)}, \\qquad \\text{feasible at } x \\iff \\rho(|\\Delta|_{max}(x)) < 1.

How much uncertainty a point tolerates: the *critical scale* ``s*(x)``, the largest factor on
every half-width for which x stays feasible, found by bisection on ``(0, s_max]`` (``s_max``
keeps every parameter positive; the bisection takes feasibility to shrink as the box grows, which
holds when the vertices' H approach singularity monotonically). ``s* > 1``: feasible at the stated
uncertainty.

A design over a region R takes the element-wise maximum over its points, so it is feasible if
and only if ``rho(max_{x in R} |Delta|_max(x)) < 1`` (:func:`region_radius`): that needs every
point of R feasible (the spectral radius of a non-negative matrix grows with its entries) but does
not follow from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FreefloatError
from .gain_design import LinearParameterModel, spectral_radius, vertices

#: Bisection steps of the critical scale (its bracket shrinks 2^-14: 1e-4 of s_max).
BISECTIONS = 14


@dataclass(frozen=True)
class FeasibilityMap:
    """The pointwise feasibility of eq 161 over m platform points.

    Attributes:
        assembled: (m,) whether the mechanism assembles there (the rest are NaN).
        radius: (m,) spectral radius of ``|Delta|_max(x)``; inf at a singular pose (A° or some
            vertex's H singular: no design there, critical scale 0).
        Delta: (m, p, p) ``|Delta|_max(x)``.
        scale: (m,) the critical scale s*(x) (module docstring), capped at ``s_max``.
        s_max: the largest scale keeping every parameter positive.
    """

    assembled: np.ndarray
    radius: np.ndarray
    Delta: np.ndarray
    scale: np.ndarray
    s_max: float

    @property
    def feasible(self) -> np.ndarray:
        """(m,) assembled and ``radius < 1``."""
        return self.assembled & (np.nan_to_num(self.radius, nan=np.inf) < 1.0)


def delta_max(model: LinearParameterModel, H_c: np.ndarray, extremes: np.ndarray) -> np.ndarray:
    """``|Delta|_max`` (p, p) over the parameter sets ``extremes`` (V, r) from H's coefficients
    (l, p, p) at one pose: ``max_v |H(theta_v)^-1 H(theta^) - 1|`` element-wise (eq 156).

    Raises:
        numpy.linalg.LinAlgError: when H is singular for some parameter set.
    """
    H_hat = np.tensordot(model.linear_parameters(model.nominal), H_c, 1)
    H = np.einsum("vl,lij->vij", np.array([model.linear_parameters(theta) for theta in extremes]), H_c)
    return np.abs(np.linalg.solve(H, np.broadcast_to(H_hat, H.shape)) - np.eye(len(H_hat))).max(axis=0)


def scaled_vertices(model: LinearParameterModel, signs: np.ndarray, scale: float) -> np.ndarray:
    """The vertices (V, r) of the box ``nominal +- scale * uncertainty`` for ``signs`` (V, r) of +-1."""
    return model.nominal + scale * signs * model.uncertainty


def largest_scale(model: LinearParameterModel) -> float:
    """The largest scale of the half-widths that keeps every parameter positive (just below
    ``min(nominal / uncertainty)``)."""
    return float(np.min(model.nominal / model.uncertainty)) * (1.0 - 1e-9)


def critical_scale(model: LinearParameterModel, H_c: np.ndarray, signs: np.ndarray, s_max: float) -> float:
    """The largest s in (0, s_max] with ``rho(|Delta|_max) < 1`` over the box scaled by s, by
    :data:`BISECTIONS` bisection steps (the lower end of the last bracket); 0 when none is found."""
    def feasible(scale: float) -> bool:
        try:
            return spectral_radius(delta_max(model, H_c, scaled_vertices(model, signs, scale))) < 1.0
        except np.linalg.LinAlgError:
            return False

    if feasible(s_max):
        return s_max
    low, high = 0.0, s_max
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if feasible(middle) else (low, middle)
    return low


def feasibility(model: LinearParameterModel, points: np.ndarray, sample: int | None = None,
                seed: int = 0) -> FeasibilityMap:
    """The map at ``points`` (m, p), platform coordinates, over the vertices of ``model``'s
    parameter box (all, or ``sample`` of them: :func:`~freefloat.parallel.gain_design.vertices`)."""
    extremes = vertices(model, sample, seed)
    signs = np.sign(extremes - model.nominal)
    s_max = largest_scale(model)
    m, p = len(points), model.p
    assembled, radius, Delta = np.zeros(m, bool), np.full(m, np.nan), np.full((m, p, p), np.nan)
    scale = np.full(m, np.nan)
    for k, point in enumerate(np.asarray(points, float)):
        try:
            q = model.assemble(point)
        except FreefloatError:
            continue
        assembled[k] = True
        try:
            H_c = model.coefficients(q)[0]
            Delta[k] = delta_max(model, H_c, extremes)
        except (FreefloatError, np.linalg.LinAlgError):  # a singular pose: no platform dynamics, no design
            Delta[k], radius[k], scale[k] = np.inf, np.inf, 0.0
            continue
        radius[k] = spectral_radius(Delta[k])
        scale[k] = critical_scale(model, H_c, signs, s_max)
    return FeasibilityMap(assembled, radius, Delta, scale, s_max)


def region_radius(Delta: np.ndarray, mask: np.ndarray) -> float:
    """Spectral radius of the element-wise maximum of ``Delta`` (m, p, p) over the points of
    ``mask`` (m,): the design over those points is feasible iff it is below 1; NaN for none."""
    if not mask.any():
        return float("nan")
    worst = Delta[mask].max(axis=0)
    return float("inf") if not np.isfinite(worst).all() else spectral_radius(worst)
