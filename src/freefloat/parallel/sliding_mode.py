"""Sliding-mode control of a parallel platform and its worst-case gain design (thesis proposal
sec 5.5, eqs 141-170), and the computed-torque law it is compared with (eq 190).

``e = q#_d - q#`` (eq 142 as printed reads ``qddot_d - q``: a typo), ``s = -(edot + lambda e)``,
``sigma = qddot_d + lambda edot``, and the law ``u* = h^ + H^ (sigma - k f(s))`` (eq 153) with
``f = sign`` or its smooth ``tanh(100 s)``. The gain ``diag(k) = n + T |sigma| +
sum_{i >= j} n_ij |qdot#_i| |qdot#_j|`` (eq 167) comes from the worst case, over a grid of the
workspace and all extreme parameter combinations, of ``Delta = H^-1 H^ - 1``,
``delta_0 = H^-1 (g^ - g)`` and ``delta_ij = H^-1 (delta^_ij - delta_ij)`` (eqs 155-170):
:mod:`freefloat.parallel.gain_design`, here applied to the 5R (:class:`FiveBarModel`).
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from ..arguments import real_number
from ..dynamics.compiled_chain import CompiledChainLoop
from ..dynamics.plants import CoupledChainPlant
from ..errors import InvalidArgument, UnknownName
from . import gain_design
from .five_bar import FiveBarParameters, elbow_guess, five_bar
from .gain_design import SlidingModeGains, WorstCase
from .mechanism import ParallelMechanism
from .platform import platform_dynamics, quadratic_coefficients
from .platform_control import CircleReference

#: The switching functions of eq 153: ``tanh(100 s)`` or ``sign(s)``.
SWITCHES = ("tanh", "sign")
#: The six uncertain 5R parameters and their stated uncertainties (sec 5.6, iv).
UNCERTAINTY = {"lg1": 0.009, "lg2": 0.011, "m1": 0.0215, "m2": 0.0257, "Jz1": 25.7e-6, "Jz2": 48.1e-6}


def workspace_grid(p: FiveBarParameters, spacing: float = 0.01, max_condition: float = 20.0) -> np.ndarray:
    """Points (N, 2) of a ``spacing`` grid where the 5R assembles with outward elbows and both the
    passive-joint matrix A° and the actuation map C^T U have condition numbers below
    ``max_condition`` (the document draws its non-singular region without stating a threshold;
    this is freefloat's stated choice)."""
    mech = five_bar(p)
    reach = p.l1 + p.l2 + p.l0
    points = []
    for x in np.arange(-reach, reach + 1e-9, spacing):
        for y in np.arange(spacing, reach + 1e-9, spacing):
            try:
                q = mech.assemble(np.array([x, y]), elbow_guess(p, np.array([x, y])))
            except Exception:
                continue
            A, _, C, *_ = mech.terms(q, np.zeros(6))
            if np.linalg.cond(A[:, 2:]) < max_condition and np.linalg.cond(C.T @ mech.selection()) < max_condition:
                points.append((x, y))
    return np.array(points)


def extreme_parameters(nominal: FiveBarParameters, uncertainty: dict[str, float] = UNCERTAINTY):
    """The 2^6 parameter sets at the ends of the uncertainty intervals."""
    names = list(uncertainty)
    for signs in itertools.product((-1.0, 1.0), repeat=len(names)):
        yield replace(nominal, **{n: getattr(nominal, n) + s * uncertainty[n] for n, s in zip(names, signs)})


def base_parameters(p: FiveBarParameters) -> np.ndarray:
    """``(m1, m1 lg1, m1 lg1^2 + Jz1, m2, m2 lg2, m2 lg2^2 + Jz2)``: the 5R's dynamics (H, v_M,
    g_M) are linear in these six numbers (each link's mass, first and second moments about its
    joint), which makes every parameter set a linear combination of six evaluations."""
    return np.array([p.m1, p.m1 * p.lg1, p.m1 * p.lg1**2 + p.Jz1, p.m2, p.m2 * p.lg2, p.m2 * p.lg2**2 + p.Jz2])


def point_coefficients(nominal: FiveBarParameters, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
    """Per-base-parameter coefficients of H (6, p, p), g_M (6, p) and each delta_ij (6, p) at q."""
    rng = np.random.default_rng(0)
    names = ("lg1", "lg2", "m1", "m2", "Jz1", "Jz2")
    sets = [replace(nominal, **{n: getattr(nominal, n) * (1.0 + 0.3 * rng.normal()) for n in names}) for _ in range(6)]
    X = np.array([base_parameters(pp) for pp in sets])
    rows = []
    for pp in sets:
        mech = five_bar(pp)
        H, _, g, _ = platform_dynamics(mech, q, np.zeros(2))
        quad = quadratic_coefficients(mech, q)
        rows.append(np.concatenate([H.ravel(), g] + [quad[k] for k in sorted(quad)]))
    coef = np.linalg.solve(X, np.array(rows))
    keys = sorted(quadratic_coefficients(five_bar(nominal), q))
    p = 2
    H_c, g_c = coef[:, : p * p].reshape(6, p, p), coef[:, p * p: p * p + p]
    quad_c = {k: coef[:, p * p + p + 2 * i: p * p + p + 2 * i + 2] for i, k in enumerate(keys)}
    return H_c, g_c, quad_c


@dataclass(frozen=True)
class FiveBarModel:
    """The 5R as a :class:`~freefloat.parallel.gain_design.LinearParameterModel`: the uncertain
    parameters of ``uncertainty`` (names of :class:`FiveBarParameters` fields, half-widths) about
    ``params``, linear in :func:`base_parameters`; poses with the elbows outward."""

    params: FiveBarParameters
    uncertainty_of: dict[str, float] = field(default_factory=lambda: dict(UNCERTAINTY))
    p: int = 2

    def __post_init__(self) -> None:
        fields = [f for f in FiveBarParameters.__dataclass_fields__]
        for name, width in self.uncertainty_of.items():
            if name not in fields:
                raise UnknownName("uncertain parameter of the 5R (a FiveBarParameters field)", name, fields)
            real_number(f"uncertainty['{name}']", width, low=0.0)  # a half-width

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.uncertainty_of)

    @property
    def nominal(self) -> np.ndarray:
        return np.array([getattr(self.params, n) for n in self.names])

    @property
    def uncertainty(self) -> np.ndarray:
        return np.array([self.uncertainty_of[n] for n in self.names])

    @functools.cached_property
    def mechanism(self) -> ParallelMechanism:
        """The nominal 5R."""
        return five_bar(self.params)

    def linear_parameters(self, theta: np.ndarray) -> np.ndarray:
        """:func:`base_parameters` (6,) of ``params`` with ``names`` set to theta (r,)."""
        return base_parameters(replace(self.params, **dict(zip(self.names, (float(x) for x in theta)))))

    def assemble(self, point: np.ndarray) -> np.ndarray:
        return self.mechanism.assemble(point, elbow_guess(self.params, point))

    def coefficients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        return point_coefficients(self.params, q)


def worst_case(nominal: FiveBarParameters, points: np.ndarray, uncertainty: dict[str, float] = UNCERTAINTY) -> WorstCase:
    """The 5R's worst cases over ``points`` (N, 2) and the 2^6 extremes
    (:func:`freefloat.parallel.gain_design.worst_case`)."""
    return gain_design.worst_case(FiveBarModel(nominal, dict(uncertainty)), points)


def design_gains(nominal: FiveBarParameters, points: np.ndarray, eta: float = 20.0,
                 uncertainty: dict[str, float] = UNCERTAINTY) -> SlidingModeGains:
    """Worst-case gains (eqs 155-170) of the 5R over ``points`` (N, 2) and all 2^6 extreme
    parameter sets (:func:`freefloat.parallel.gain_design.design_gains`)."""
    return gain_design.design_gains(FiveBarModel(nominal, dict(uncertainty)), points, eta)


Reference = Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class PlatformLaw:
    """:class:`PlatformControl` on a circle reference as the compiled closed-chain loop runs it
    (``_sim.ChainSimulation.set_platform_law``).

    Attributes:
        model: the nominal mechanism (its compiled core).
        center: the circle's centre (p,); radius (m or rad), rate (rad/s), axes (a, b).
        lam: lambda, 1/s.
        sliding: sliding mode (eq 153) rather than computed torque (eq 190).
        sign: the switching function ``sign`` rather than ``tanh(100 s)``.
        n, T: eq 167's gains (p,), (p, p) (zeros for computed torque).
        pairs, n_ij: the (i, j) pairs of eq 167's ``n_ij`` and their gains (p,) each.
        every: control periods per law update (:class:`~freefloat.dynamics.sampled.Sampled`).
    """

    model: ParallelMechanism
    center: np.ndarray
    radius: float
    rate: float
    axes: tuple[int, int]
    lam: float
    sliding: bool
    sign: bool
    n: np.ndarray
    T: np.ndarray
    pairs: tuple[tuple[int, int], ...]
    n_ij: tuple[np.ndarray, ...]
    every: int = 1

    kind: ClassVar[str] = "platform"

    def install(self, simulation: Any, robot: Any = None) -> None:
        """Hand this law to the compiled closed-chain loop."""
        chains, coupling = self.model.core_arrays()
        simulation.set_platform_law(chains, coupling, self.center, self.radius, self.rate, self.axes, self.lam,
                                    self.sliding, self.sign, self.n, self.T, list(self.pairs), list(self.n_ij),
                                    self.every)


@dataclass(frozen=True)
class PlatformControl:
    """Computed torque (eq 190, ``gains`` None) or sliding mode (eq 153) on a nominal model, for
    any mechanism: a controller of the one loop (:func:`freefloat.dynamics.simulation.run_plant`)
    on Orsino's coordinates ``q = [q#; q°]``. The law asks a platform force ``u*`` (p,) and the
    model's :meth:`~freefloat.parallel.mechanism.ParallelMechanism.efforts` gives the actuator
    efforts: ``B = C^T U`` inverted when square, the model's effort distribution when there are
    more actuators than coordinates (redundant actuation; ``B tau = u*`` to round-off, so the gain
    design of eqs 155-170, made on ``u*``'s dynamics, holds unchanged).

    Attributes:
        model: the mechanism the controller believes (its p platform coordinates lead q).
        trajectory: ``t -> (q#_d, qdot#_d, qddot#_d)``, each (p,).
        lam: lambda, 1/s.
        gains: eq 167's gains; None means computed torque ``u* = h^ + H^ (qddot_d + 2 lam edot + lam^2 e)``.
        saturation: ``"tanh"`` (``tanh(100 s)``) or ``"sign"``.
    """

    model: ParallelMechanism
    trajectory: Reference
    lam: float
    gains: SlidingModeGains | None = None
    saturation: str = "tanh"

    def __post_init__(self) -> None:
        real_number("lam", self.lam, low=0.0)  # lambda, 1/s
        if self.saturation not in SWITCHES:
            raise InvalidArgument(f"sliding mode: saturation must be one of {SWITCHES}, got '{self.saturation}'")

    def law(self, t: float, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(tau, e, s)``: actuator efforts (k,), N m or N, the error ``e = q#_d - q#`` and the
        sliding variable ``s = -(edot + lam e)`` (p,), for the measured q and qd (n_q,)."""
        p, lam = self.model.p, self.lam
        q_d, qd_d, qdd_d = self.trajectory(t)
        e, edot = q_d - q[:p], qd_d - qd[:p]
        H, v, g, B = platform_dynamics(self.model, q, qd[:p])
        s = -(edot + lam * e)
        if self.gains is None:
            acceleration = qdd_d + 2.0 * lam * edot + lam**2 * e
        else:
            sigma = qdd_d + lam * edot
            switch = np.sign(s) if self.saturation == "sign" else np.tanh(100.0 * s)
            acceleration = sigma - self.gains.k(sigma, qd[:p]) * switch
        return self.model.efforts(B, v + g + H @ acceleration), e, s

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Actuator efforts (k,) of :meth:`law` (the loop's controller interface)."""
        return self.law(t, q, qd)[0]

    def reference(self, t: float) -> np.ndarray:
        """The platform reference ``q#_d`` (p,) at ``t`` s."""
        return self.trajectory(t)[0]

    def sliding_variables(self, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(e, s)`` (N, p) at recorded times (N,) and states (N, n_q)."""
        p = self.model.p
        rows = [self.trajectory(tk) for tk in t]
        q_d = np.array([r[0] for r in rows]).reshape(-1, p)
        qd_d = np.array([r[1] for r in rows]).reshape(-1, p)
        e = q_d - q[:, :p]
        return e, -(qd_d - qd[:, :p] + self.lam * e)

    def compiled_law(self) -> PlatformLaw | None:
        """This law as the compiled closed-chain loop takes it (``ChainSimulation.set_platform_law``):
        for a circle reference (:class:`~.platform_control.CircleReference`) on a model with a
        compiled core and square actuation (the compiled law inverts ``C^T U``) and gains without
        rate terms (``n_rate``, which the compiled law lacks); None otherwise (the loop then calls
        :meth:`torque` from Python)."""
        circle = self.trajectory
        if self.model.core is None or not self.model.square_actuation or (self.gains is not None and self.gains.n_rate) or \
                not all(hasattr(circle, k) for k in ("center", "radius", "rate", "axes")):
            return None
        p = self.model.p
        sliding = self.gains is not None
        pairs = sorted(self.gains.n_ij) if sliding else []
        return PlatformLaw(self.model, np.asarray(circle.center, float), float(circle.radius), float(circle.rate),
                           tuple(int(a) for a in circle.axes), float(self.lam), sliding, self.saturation == "sign",
                           self.gains.n if sliding else np.zeros(p), self.gains.T if sliding else np.zeros((p, p)),
                           tuple((int(i), int(j)) for i, j in pairs),
                           tuple(np.asarray(self.gains.n_ij[k], float) for k in pairs))

    def compiled_torque(self) -> Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None:
        """:meth:`torque` evaluated by the compiled closed-chain loop's law
        (:meth:`~freefloat.dynamics.compiled_chain.CompiledChainLoop.law_efforts`, the C++ of
        :meth:`compiled_law`): the same efforts to round-off (tested) in 3 to 9 us against about
        85 us here, for a controller called from Python each period (a mechanism on a moving base).
        None when :meth:`compiled_law` is."""
        if self.compiled_law() is None:
            return None
        return CompiledChainLoop(CoupledChainPlant(self.model), self, "euler", 1.0).law_efforts


def chattering(t: np.ndarray, efforts: np.ndarray, s: np.ndarray, after: float,
               effort_times: np.ndarray | None = None) -> dict:
    """How much a closed loop chatters after time ``after`` (s), from the sliding variables
    (N, p) sampled at times ``t`` (N,) and the efforts (M, k) the law gave at ``effort_times``
    (M,; default ``t``, M = N): its control updates.

    Returns:
        ``effort_jump_median`` (k,): median |tau_{i+1} - tau_i| between updates, N m;
        ``effort_variation_per_s`` (k,): sum of those jumps per second, N m/s;
        ``s_sign_changes_per_s`` (p,): sign changes of s per second; ``s_max`` (p,): max |s|.
    """
    effort_times = t if effort_times is None else effort_times
    late, late_u = t > after, effort_times > after
    if late.sum() < 2 or late_u.sum() < 2:
        raise InvalidArgument(f"chattering: fewer than two samples or control updates after t = {after} s "
                              f"(the run ends at {t[-1]} s)")
    span, span_u = t[late][-1] - t[late][0], effort_times[late_u][-1] - effort_times[late_u][0]
    jumps = np.abs(np.diff(efforts[late_u], axis=0))
    return {"effort_jump_median": np.median(jumps, axis=0).tolist(),
            "effort_variation_per_s": (jumps.sum(axis=0) / span_u).tolist(),
            "s_sign_changes_per_s": ((np.diff(np.sign(s[late]), axis=0) != 0).sum(axis=0) / span).tolist(),
            "s_max": np.abs(s[late]).max(axis=0).tolist()}


#: Sec 5.6's reference (eq 189): x = 0.07 cos(28.57 t), y = 0.17 + 0.07 sin(28.57 t), m; called
#: with t (s), gives ``(q#_d, qdot#_d, qddot#_d)``.
circle_reference = CircleReference(np.array([0.0, 0.17]), 0.07, 28.57)


def printed_gains(n: np.ndarray, T: np.ndarray, n_ij: dict[tuple[int, int], np.ndarray]) -> SlidingModeGains:
    """Eq 167's gain from printed numbers (e.g. eq 187): ``n`` (p,), ``T`` (p, p), ``n_ij``
    {(i, j): (p,)} for i >= j. The design's worst cases and eta are unknown for printed gains:
    they are NaN, and no design points."""
    p = len(n)
    return SlidingModeGains(n=np.asarray(n, float), T=np.asarray(T, float),
                            n_ij={k: np.asarray(v, float) for k, v in n_ij.items()}, eta=float("nan"),
                            Delta_max=np.full((p, p), np.nan), delta0_max=np.full(p, np.nan),
                            deltaij_max={}, points=np.empty((0, p)))
