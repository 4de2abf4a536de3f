"""Adaptive sliding mode of a parallel platform (thesis proposal sec 3 and planned chapter 5.3):
the Slotine-Li law on the platform dynamics' regressor, with a switching term.

With ``e = q#_d - q#``, the reference rates ``qdot_r = qdot#_d + lambda e``, ``qddot_r =
qddot#_d + lambda edot`` and the sliding variable ``s = qdot# - qdot_r = -(edot + lambda e)``
(eqs 142-143's, so ``qddot_r`` is eq 153's ``sigma``), the law asks the platform force

.. math:: u^* = W(q, \\dot q^\\#, \\dot q_r, \\ddot q_r)\\, \\hat\\theta - K_D s - K_s f(s),
          \\qquad \\dot{\\hat\\theta} = -\\Gamma W^T s,

``W theta = H qddot_r + C#(q, qdot#) qdot_r + g_M`` the Slotine-Li regressor
(:class:`~freefloat.parallel.platform_regressor.PlatformRegressor`), ``K_D`` symmetric positive
definite, ``K_s = diag(k_s) >= 0``, ``f`` eq 153's switch (``tanh(100 s)`` or ``sign``) and
``Gamma = diag(gamma) > 0``. With ``V = s^T H s / 2 + (theta^ - theta)^T Gamma^-1 (theta^ -
theta) / 2`` and ``dH/dt - 2 C#`` skew-symmetric, ``dV/dt = -s^T K_D s - sum_i k_s,i s_i f(s_i)
<= 0``: s and the estimates stay bounded and s -> 0 (Barbalat), so e -> 0 whatever theta is;
the estimates tend to the true parameters when the reference excites them persistently (``W``
along it of full column rank over every window of some length). Slotine and Li, "On the adaptive
control of robot manipulators", IJRR 6(3), 1987 (the document's [44]); the law divides by no
model matrix, so an estimate far off never makes it singular.

**Discretisation.** The law is a digital controller: at each control instant ``t_k`` it
measures (q, qdot), evaluates ``u*_k`` with the estimate it holds and the efforts are held until
``t_{k+1}`` (zero-order hold, as every law of :mod:`~freefloat.parallel.closed_loop`). The update
law's integrand is sampled with it and held too, so the estimate is integrated exactly under
that hold (explicit Euler), then projected:

.. math:: \\hat\\theta_{k+1} = \\Pi\\left(\\hat\\theta_k - (t_{k+1} - t_k)\\, \\Gamma W_k^T s_k\\right),

``Pi`` the clip onto the box ``lower <= theta <= upper`` (none by default). For a diagonal
``Gamma`` the clip is the projection in ``Gamma^-1``'s metric, which cannot move the estimate
away from a true value inside the box, so it keeps the Lyapunov argument. The estimate changes
once per control period only: when the law is evaluated more often (at every integrator stage),
those evaluations use the estimate of the period's start.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import BadShape, FreefloatError
from .closed_chain import ClosedChain
from .five_bar import FiveBarParameters
from .platform_regressor import PlatformRegressor, five_bar_regressor, five_bar_theta
from .sliding_mode import SWITCHES, Reference

#: The 5R's physical parameters the projection box spreads (sec 5.6's uncertain six).
FIVE_BAR_UNCERTAIN = ("lg1", "lg2", "m1", "m2", "Jz1", "Jz2")


@dataclass
class AdaptiveSlidingMode:
    """The adaptive law (module docstring): a controller of the one loop (``torque(t, q, qd)``,
    ``reference(t)``) with the estimate as its state.

    Attributes:
        regressor: the platform dynamics' regressor on theta (l,); its chain's geometry maps
            ``u*`` to the actuator efforts (``B = C^T U``, eq 136).
        trajectory: ``t -> (q#_d, qdot#_d, qddot#_d)``, each (p,).
        lam: lambda, 1/s.
        estimate: theta^ (l,), the start estimate; the law's current one as it runs.
        gamma: ``Gamma``'s diagonal (l,), theta^2 / (N m) each (u* in N and s in m/s for a point platform).
        damping: ``K_D`` (p, p), N s/m for a point platform.
        switching: ``k_s`` (p,), N (0: no switching term).
        period: the control period, s: the estimate is updated once per period.
        saturation: ``"tanh"`` (``tanh(100 s)``) or ``"sign"``.
        lower, upper: the projection box (l,) each, or None for no projection.

    Raises:
        BadShape: for gains or bounds of the wrong shape, a start outside the bounds.
        FreefloatError: for a gain that is not positive, an unknown switch or a non-positive period.
    """

    regressor: PlatformRegressor
    trajectory: Reference
    lam: float
    estimate: np.ndarray
    gamma: np.ndarray
    damping: np.ndarray
    switching: np.ndarray
    period: float
    saturation: str = "tanh"
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    #: The estimate at the first call and after each update, ``(t, theta^)``.
    history: list[tuple[float, np.ndarray]] = field(default_factory=list, init=False, repr=False)

    def __post_init__(self) -> None:
        l, p = len(self.regressor.names), self.regressor.p
        self.estimate = np.array(self.estimate, float)
        self.gamma, self.damping = np.asarray(self.gamma, float), np.asarray(self.damping, float)
        self.switching = np.asarray(self.switching, float)
        shapes = {"estimate": (self.estimate, (l,)), "gamma": (self.gamma, (l,)), "damping": (self.damping, (p, p)),
                  "switching": (self.switching, (p,))}
        for bound in ("lower", "upper"):
            if getattr(self, bound) is not None:
                setattr(self, bound, np.asarray(getattr(self, bound), float))
                shapes[bound] = (getattr(self, bound), (l,))
        for name, (value, shape) in shapes.items():
            if value.shape != shape:
                raise BadShape(f"adaptive sliding mode: {name} must have shape {shape} ({l} parameters "
                               f"{self.regressor.names}, {p} platform coordinates), got {value.shape}")
        if self.saturation not in SWITCHES:
            raise FreefloatError(f"adaptive sliding mode: saturation must be one of {SWITCHES}, got '{self.saturation}'")
        if not (np.all(self.gamma > 0.0) and self.lam > 0.0 and self.period > 0.0 and np.all(self.switching >= 0.0)):
            raise FreefloatError(f"adaptive sliding mode: gamma ({self.gamma}), lam ({self.lam}) and period "
                                 f"({self.period}) must be positive and switching ({self.switching}) non-negative")
        if not np.all(np.linalg.eigvalsh(0.5 * (self.damping + self.damping.T)) > 0.0):
            raise FreefloatError(f"adaptive sliding mode: damping K_D must be positive definite, got {self.damping.tolist()}")
        if self.projected(self.estimate) is not None and not np.array_equal(self.projected(self.estimate), self.estimate):
            raise BadShape(f"adaptive sliding mode: the start estimate {self.estimate.tolist()} is outside the bounds "
                           f"[{self.lower}, {self.upper}]")
        self._start = self.estimate.copy()
        self.reset()

    def reset(self) -> None:
        """Back to the start estimate, for a new run (the first call then starts the clock)."""
        self.estimate = self._start.copy()
        self.history = []
        self._sample: tuple[float, np.ndarray, np.ndarray] | None = None

    def projected(self, theta: np.ndarray) -> np.ndarray | None:
        """theta clipped onto ``[lower, upper]`` (l,), or None without bounds."""
        if self.lower is None and self.upper is None:
            return None
        return np.clip(theta, self.lower, self.upper)

    def _update(self, t: float) -> None:
        """Integrate the estimate from the last sample to ``t`` when a period has passed."""
        if self._sample is None:
            return
        t_k, W, s = self._sample
        if t < t_k:
            raise FreefloatError(f"adaptive sliding mode: called at t = {t} s after t = {t_k} s; call reset() before "
                                 "a new run")
        if t - t_k < self.period * (1.0 - 1e-9):
            return
        theta = self.estimate - (t - t_k) * self.gamma * (W.T @ s)
        clipped = self.projected(theta)
        self.estimate = theta if clipped is None else clipped
        self.history.append((t, self.estimate.copy()))
        self._sample = None

    def law(self, t: float, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(tau, e, s)``: actuator efforts (k,), the error ``e = q#_d - q#`` and the sliding
        variable s (p,) for the measured q and qd (n_q,) at ``t`` s (advancing the estimate to t)."""
        self._update(t)
        p, lam = self.regressor.p, self.lam
        q_d, qd_d, qdd_d = self.trajectory(t)
        e, edot = q_d - q[:p], qd_d - qd[:p]
        s = -(edot + lam * e)
        W = self.regressor.slotine_li(q, qd[:p], qd_d + lam * e, qdd_d + lam * edot)
        switch = np.sign(s) if self.saturation == "sign" else np.tanh(100.0 * s)
        u = W @ self.estimate - self.damping @ s - self.switching * switch
        if not self.history:
            self.history.append((t, self.estimate.copy()))
        if self._sample is None:
            self._sample = (t, W, s)
        mech = self.regressor.chain.mechanism
        return mech.efforts(mech.velocity_map(q).T @ mech.selection(), u), e, s

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Actuator efforts (k,) of :meth:`law` (the loop's controller interface)."""
        return self.law(t, q, qd)[0]

    def reference(self, t: float) -> np.ndarray:
        """The platform reference ``q#_d`` (p,) at ``t`` s."""
        return self.trajectory(t)[0]

    def estimates(self) -> tuple[np.ndarray, np.ndarray]:
        """``(t, theta^)``: the first call's and the updates' times (N,) and estimates (N, l)."""
        return np.array([t for t, _ in self.history]), np.array([x for _, x in self.history])


def five_bar_box(nominal: FiveBarParameters, spread: float) -> tuple[np.ndarray, np.ndarray]:
    """``(lower, upper)`` (4,) each: the range of the 5R's base parameters
    (:func:`~freefloat.parallel.platform_regressor.five_bar_theta`) over the physical box, the
    six uncertain parameters of sec 5.6 each within ``nominal (1 +- spread)``. Every base
    parameter grows with each of them, so the range is that of the box's 2^6 vertices."""
    thetas = np.array([five_bar_theta(replace(nominal, **{n: getattr(nominal, n) * (1.0 + s * spread)
                                                          for n, s in zip(FIVE_BAR_UNCERTAIN, signs)}))
                       for signs in itertools.product((-1.0, 1.0), repeat=len(FIVE_BAR_UNCERTAIN))])
    return thetas.min(axis=0), thetas.max(axis=0)


def five_bar_law(chain: ClosedChain, trajectory: Reference, period: float, lam: float = 40.0, gamma: float = 3000.0,
                 damping: float = 10.0, switching: float = 10.0, spread: float = 0.6,
                 nominal: FiveBarParameters | None = None) -> AdaptiveSlidingMode:
    """The 5R's adaptive law as docs/control_laws.md runs it: the estimate starts at the nominal
    base parameters theta^_0, ``Gamma = gamma diag(theta^_0)^2`` (each parameter adapted relative
    to its size: gamma in 1/(N m)), ``K_D = damping I`` (N s/m; 10 is about
    lambda H^, H^ near 0.25 kg on the sec 5.6 circle), ``k_s = switching`` (N) and the projection
    box of :func:`five_bar_box` (``nominal``: the model's parameters, sec 5.6's by default).

    Near the surface ``k_s tanh(100 s)`` acts as a gain of ``100 k_s`` (1000 N s/m), far from it
    it is bounded by ``k_s``: the law is stiff on the surface without asking large efforts in the
    reaching phase (with ``K_D = 1000 I`` and no switching term instead, the same stiffness asked
    234 N m at the start, s = 2 m/s). The zero-order hold limits the gains: at ``period`` = 0.1 ms,
    ``gamma`` 10 000 with 1000 N s/m made the estimates diverge (without the box) on the 50 %
    plant; 3000 settles. A stiffer surface slows the parameters' convergence (``s ~ W theta~ /
    gain`` feeds the update law)."""
    nominal = FiveBarParameters() if nominal is None else nominal
    theta0 = five_bar_theta(nominal)
    lower, upper = five_bar_box(nominal, spread)
    return AdaptiveSlidingMode(five_bar_regressor(chain), trajectory, lam, theta0, gamma * theta0**2,
                               damping * np.eye(2), np.full(2, switching), period, lower=lower, upper=upper)
