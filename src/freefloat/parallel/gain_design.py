"""Worst-case sliding-mode gain design (thesis proposal sec 5.5, eqs 154-170) for any mechanism
whose platform dynamics are linear in a parameter vector.

A :class:`LinearParameterModel` states its uncertain physical parameters ``theta`` (r,) (names,
nominal values, half-widths of their intervals) and the vector ``pi(theta)`` (l,) the dynamics
are linear in: at every assembled pose q,

.. math:: H(q; \\theta) = \\sum_k \\pi_k(\\theta) H_k(q), \\quad
          g_M(q; \\theta) = \\sum_k \\pi_k(\\theta) g_k(q), \\quad
          \\delta_{ij}(q; \\theta) = \\sum_k \\pi_k(\\theta) \\delta_{ij,k}(q)

(eq 137's ``H qddot# + v_M + g_M = u*``, ``v_M = sum_{i >= j} delta_ij qdot#_i qdot#_j``, eq 162),
so one evaluation of the coefficients per pose serves every parameter set. The design takes, over
the workspace points and the vertices of the parameter box (the 2^r extreme combinations, as the
thesis does for the 5R), the element-wise worst cases ``|Delta|_max`` of ``Delta = H^-1 H^ - 1``
(eq 156), ``|delta_0|_max`` of ``H^-1 (g^ - g)`` (eq 164) and ``|delta_ij|_max`` of
``H^-1 (delta^_ij - delta_ij)`` (eq 165), then the gains of eqs 167-170.

The vertices are the thesis's method, not a bound: ``Delta`` is not linear in theta (``H^-1``),
so an interior parameter set may be worse than every vertex. Beyond :data:`MAX_VERTICES`
vertices the design refuses, unless asked to sample: ``sample`` distinct vertices drawn uniformly
(seeded), which gives a worst case no larger than the full one.

The box may come from an identification: :class:`~freefloat.parallel.identification.RegressorModel`
is a mechanism's Pinocchio regressor as such a model, its parameters the base parameters, its
nominal values an estimate and its half-widths the estimate's confidence box
(:meth:`~freefloat.parallel.identification.RegressorModel.identified`): the design then covers
the uncertainty the measurements leave instead of a stated one.

Eq 161 (``diag(k) = (1 - |Delta|_max)^-1 (...)``) has a solution only when
``(1 - |Delta|_max)^-1`` exists and is non-negative; for the non-negative matrix
``|Delta|_max`` that holds exactly when its spectral radius is below 1 (``1 - |Delta|_max`` is
then a non-singular M-matrix). :func:`spectral_radius` is that margin, pointwise for the
feasibility map.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ..arguments import real_number
from ..errors import BadShape, InvalidArgument, NotAssembled

#: Most vertices (2^r) the design evaluates exhaustively (r = 12 parameters).
MAX_VERTICES = 4096


class LinearParameterModel(Protocol):
    """A mechanism whose platform dynamics are linear in ``pi(theta)``.

    Attributes:
        names: the uncertain parameters (r,), e.g. ``"m1"`` or ``"rsu.crank_mass"``.
        nominal: their nominal values theta^ (r,), SI units; the controller's model.
        uncertainty: half-widths of their intervals (r,), same units.
        p: number of platform coordinates.
    """

    names: tuple[str, ...]
    nominal: np.ndarray
    uncertainty: np.ndarray
    p: int

    def linear_parameters(self, theta: np.ndarray) -> np.ndarray:
        """``pi(theta)`` (l,) for parameters theta (r,)."""

    def assemble(self, point: np.ndarray) -> np.ndarray:
        """The nominal mechanism's coordinates q (n_q,) at platform coordinates ``point`` (p,);
        raises :class:`~freefloat.errors.FreefloatError` where it does not assemble."""

    def coefficients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """At q (n_q,): the coefficients of H (l, p, p), g_M (l, p) and each delta_ij
        {(i, j): (l, p)}, i >= j, on ``pi``."""


@dataclass(frozen=True)
class WorstCase:
    """Element-wise worst cases over points and vertices: ``|Delta|_max`` (p, p),
    ``|delta_0|_max`` (p,), ``|delta_ij|_max`` {(i, j): (p,)} and, for a disturbance linear in
    the platform rates (a drive's back-EMF or viscous-friction error,
    :mod:`~freefloat.parallel.drive_gain_design`), ``|delta_i|_max`` {i: (p,)}, the bound of its
    coefficient on ``qdot#_i`` (empty when there is none). Worst cases of disjoint point sets
    combine by element-wise maximum (:meth:`combine`)."""

    Delta: np.ndarray
    delta0: np.ndarray
    deltaij: dict
    deltai: dict = field(default_factory=dict)

    def combine(self, other: WorstCase) -> WorstCase:
        """The worst case over both point sets."""
        return WorstCase(np.maximum(self.Delta, other.Delta), np.maximum(self.delta0, other.delta0),
                         {k: np.maximum(v, other.deltaij[k]) for k, v in self.deltaij.items()},
                         {k: np.maximum(v, other.deltai[k]) for k, v in self.deltai.items()})


@dataclass(frozen=True)
class SlidingModeGains:
    """eq 167: ``diag(k) = n + T |sigma| + sum n_ij |qd_i| |qd_j|``, plus ``sum n_i |qd_i|``
    where the worst case has a term linear in the rates (``n_rate``; a drive's, empty otherwise).

    Attributes:
        n: (p,). T: (p, p). n_ij: {(i, j): (p,)} for i >= j. eta: the reaching rate used.
        Delta_max, delta0_max, deltaij_max: the worst cases found (element-wise absolute
            values): (p, p), (p,), {(i, j): (p,)}.
        points: workspace points used (N, p), platform coordinates.
        n_rate: {i: (p,)}, the gains on ``|qdot#_i|``; empty: none.
    """

    n: np.ndarray
    T: np.ndarray
    n_ij: dict
    eta: float
    Delta_max: np.ndarray
    delta0_max: np.ndarray
    deltaij_max: dict = field(default_factory=dict)
    points: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    n_rate: dict = field(default_factory=dict)

    def k(self, sigma: np.ndarray, qd_sharp: np.ndarray) -> np.ndarray:
        """``diag(k)`` at (sigma, qdot#) (p,)."""
        out = self.n + self.T @ np.abs(sigma)
        for (i, j), nij in self.n_ij.items():
            out = out + nij * abs(qd_sharp[i]) * abs(qd_sharp[j])
        for i, ni in self.n_rate.items():
            out = out + ni * abs(qd_sharp[i])
        return out


def vertices(model: LinearParameterModel, sample: int | None = None, seed: int = 0) -> np.ndarray:
    """The parameter sets at the vertices of the box ``nominal +- uncertainty`` (V, r): all 2^r
    (signs in ``itertools.product((-1, 1), repeat=r)`` order) or, with ``sample``, that many
    distinct ones drawn uniformly without replacement (``numpy.random.default_rng(seed)``).

    Raises:
        InvalidArgument: for 2^r above :data:`MAX_VERTICES` without ``sample``, or a ``sample``
            below 1 or above 2^r.
    """
    r = len(model.names)
    total = 2**r
    if sample is None:
        if total > MAX_VERTICES:
            raise InvalidArgument(f"gain design: {r} uncertain parameters give {total} vertices, more than "
                                  f"{MAX_VERTICES}; pass sample=N to draw N of them (a lower bound of the worst case)")
        signs = np.array(list(itertools.product((-1.0, 1.0), repeat=r))).reshape(total, r)
    else:
        if not 1 <= sample <= total:
            raise InvalidArgument(f"gain design: sample must be in [1, {total}] (2^{r} vertices), got {sample}")
        codes = np.random.default_rng(seed).choice(total, size=sample, replace=False)
        signs = np.where((codes[:, None] >> np.arange(r - 1, -1, -1)) & 1, 1.0, -1.0)
    return np.array([model.nominal + s * model.uncertainty for s in signs])


def point_worst_case(model: LinearParameterModel, q: np.ndarray, extremes: np.ndarray) -> WorstCase:
    """The worst cases at one assembled pose q (n_q,) over the parameter sets ``extremes`` (V, r)
    (eqs 156, 164, 165): H, g_M and delta_ij from the coefficients at q, the estimates at the
    nominal parameters; all parameter sets at once (a batch of p x p inverses)."""
    H_c, g_c, quad_c = model.coefficients(q)
    pi_hat = model.linear_parameters(model.nominal)
    H_hat = np.tensordot(pi_hat, H_c, 1)
    p = H_hat.shape[0]
    pis = np.array([model.linear_parameters(theta) for theta in extremes])          # (V, l)
    Hinv = np.linalg.inv(np.einsum("vl,lij->vij", pis, H_c))                       # (V, p, p)

    def worst(x: np.ndarray) -> np.ndarray:
        """max over the sets of |H^-1 x| for x (V, p): (p,)."""
        return np.abs(np.einsum("vij,vj->vi", Hinv, x)).max(axis=0)

    return WorstCase(np.abs(Hinv @ H_hat - np.eye(p)).max(axis=0), worst(pi_hat @ g_c - pis @ g_c),
                     {key: worst((pi_hat - pis) @ c) for key, c in quad_c.items()})


def box_grid(center: np.ndarray, half_width: float, spacing: float) -> np.ndarray:
    """Design points (N, p): the grid of ``spacing`` through ``center`` (p,) filling the cube
    ``center +- half_width`` (platform units), C order over the coordinates.

    Raises:
        InvalidArgument: for a spacing or half-width that is not positive.
    """
    if not (spacing > 0.0 and half_width > 0.0):
        raise InvalidArgument(f"box_grid: spacing ({spacing}) and half_width ({half_width}) must be positive")
    offsets = np.arange(-np.floor(half_width / spacing + 1e-9), np.floor(half_width / spacing + 1e-9) + 1) * spacing
    axes = np.meshgrid(*[c + offsets for c in np.asarray(center, float)], indexing="ij")
    return np.stack([a.ravel() for a in axes], axis=-1)


def design_points(model: LinearParameterModel, points: object) -> np.ndarray:
    """``points`` as an array (N, p) of finite platform coordinates of ``model`` (p of them).

    Raises:
        BadShape: naming the shape expected and given (one point as a flat list among them).
        InvalidArgument: for no points, or a point that is not finite.
    """
    try:
        array = np.asarray(points, float)
    except (TypeError, ValueError):
        raise BadShape(f"gain design: points must be an array (N, {model.p}) of platform coordinates, got "
                       f"{type(points).__name__}") from None
    if array.ndim != 2 or array.shape[1] != model.p:
        one = f" (one point is [[{', '.join(['...'] * model.p)}]])" if array.ndim == 1 else ""
        raise BadShape(f"gain design: points must be an array (N, {model.p}) of platform coordinates, got shape "
                       f"{array.shape}{one}")
    if len(array) == 0:
        raise InvalidArgument("gain design: no workspace points")
    if not np.all(np.isfinite(array)):
        raise InvalidArgument(f"gain design: point {int(np.flatnonzero(~np.isfinite(array).all(axis=1))[0])} is not "
                              "finite")
    return array


def worst_case(model: LinearParameterModel, points: np.ndarray, sample: int | None = None, seed: int = 0,
               at: Callable[[Any, np.ndarray, np.ndarray], WorstCase] | None = None) -> WorstCase:
    """The worst cases over ``points`` (N, p) and the :func:`vertices` of the parameter box, each
    point's by ``at(model, q, vertices)`` (default :func:`point_worst_case`).

    Raises:
        BadShape, InvalidArgument: for points that :func:`design_points` refuses.
        NotAssembled: for a point where the mechanism does not assemble (named).
    """
    points = design_points(model, points)
    extremes = vertices(model, sample, seed)
    out = None
    for point in points:
        try:
            q = model.assemble(point)
        except NotAssembled as exc:
            raise NotAssembled(f"gain design: point {np.round(point, 6).tolist()}: {exc}") from exc
        here = (at or point_worst_case)(model, q, extremes)
        out = here if out is None else out.combine(here)
    return out


def spectral_radius(Delta: np.ndarray) -> float:
    """Spectral radius of ``|Delta|_max`` (p, p): eq 161 has a solution (``(1 - |Delta|_max)^-1``
    exists and is non-negative) if and only if it is below 1."""
    return float(np.max(np.abs(np.linalg.eigvals(Delta))))


#: The slowest reaching rate a design takes, 1/s: below it the sliding surface is reached after
#: 1e9 s or more, no design a mechanism can use (1e-300 was accepted and gave gains of no meaning).
MIN_REACHING_RATE = 1e-9


def gains_from_worst_case(worst: WorstCase, eta: float, points: np.ndarray) -> SlidingModeGains:
    """Eqs 168-170 from the worst cases, for the reaching rate ``eta``.

    Raises:
        InvalidArgument: for ``eta`` not a finite number >= :data:`MIN_REACHING_RATE`
            (:func:`~freefloat.arguments.real_number`); when ``(1 - |Delta|_max)^-1`` does not
            exist or has negative entries (spectral radius of ``|Delta|_max`` >= 1): eq 161 has
            no solution.
    """
    eta = real_number("eta", eta, low=MIN_REACHING_RATE)  # the reaching rate of eq 168, 1/s
    Dmax, d0max = worst.Delta, worst.delta0
    radius = spectral_radius(Dmax)
    if radius >= 1.0:
        raise InvalidArgument(f"gain design: |Delta|_max = {np.round(Dmax, 3).tolist()} has spectral radius {radius:.3f} "
                              ">= 1, so (1 - |Delta|_max)^-1 is singular or has negative entries: eq 161 has no solution "
                              "over these points (cover a smaller region or a smaller uncertainty)")
    inv = np.linalg.inv(np.eye(len(d0max)) - Dmax)
    return SlidingModeGains(n=inv @ (d0max + eta), T=inv @ Dmax, n_ij={k: inv @ v for k, v in worst.deltaij.items()},
                            eta=eta, Delta_max=Dmax, delta0_max=d0max, deltaij_max=worst.deltaij,
                            points=np.asarray(points, float), n_rate={k: inv @ v for k, v in worst.deltai.items()})


def design_gains(model: LinearParameterModel, points: np.ndarray, eta: float = 20.0, sample: int | None = None,
                 seed: int = 0) -> SlidingModeGains:
    """Worst-case gains (eqs 155-170) over ``points`` (N, p) and the parameter box's vertices."""
    return gains_from_worst_case(worst_case(model, points, sample, seed), eta, points)
