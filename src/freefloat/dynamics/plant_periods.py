"""The loop's control periods for a plant (:mod:`freefloat.dynamics.plants`) in Python: the
readable reference of the compiled closed-chain loop (:class:`~.compiled_chain.CompiledChainLoop`,
the same interface), driven period by period by :func:`freefloat.dynamics.simulation.run_plant`."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import InvalidArgument, SimulationDiverged
from .integrators import make_integrator
from .plants import Plant, vector_space
from .telemetry import PlantTelemetry

#: ``law(t, q, v) -> u``: efforts (n_efforts,) at time t (s) and state (q, v).
Law = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


class PlantPeriods:
    """One plant integrated period by period, efforts held over each period (zero-order hold), or
    with ``stage_law`` the law evaluated at every integrator stage at the stage's time and state
    (continuous control: time is carried as one more Euclidean coordinate, ``[q; t]`` with rate
    1, so that every explicit tableau hands the law its stage time ``t + c_i h``).

    Args:
        plant: what is integrated.
        integrator: a registry name; ``substeps``, ``rtol``, ``atol`` its settings.
        control_period: zero-order-hold period, s.
        start_time: time of period 0, s.
        stage_law: the law to evaluate at every stage (plants on a vector space only), or None.

    Raises:
        InvalidArgument: for a stage law on a plant that is not on a vector space.
    """

    backend = "python"

    def __init__(self, plant: Plant, integrator: str, control_period: float, start_time: float = 0.0,
                 substeps: int = 1, rtol: float = 1e-10, atol: float = 1e-12, stage_law: Law | None = None):
        self.plant, self.control_period, self.start_time = plant, control_period, start_time
        space = plant.space
        self.stage_law = stage_law
        if stage_law is not None:
            if space.nq != space.nv or any(j.shortname() != "JointModelPX" for j in list(space.joints)[1:]):
                raise InvalidArgument(f"a law evaluated per stage needs a plant on a vector space; "
                                      f"'{plant.name}' is on a Lie group")
            space = vector_space(space.nq + 1)
        self.integrator = make_integrator(integrator, space, substeps, rtol, atol)
        self.u = np.zeros(plant.n_efforts)
        self.tel: PlantTelemetry | None = None
        self.periods_done = 0
        self.q, self.v = np.zeros(plant.space.nq), np.zeros(plant.space.nv)
        self.drift = (0.0, 0.0)

    def start(self, q: np.ndarray, v: np.ndarray) -> None:
        """Set the state at period 0."""
        self.q, self.v = np.array(q, dtype=float), np.array(v, dtype=float)
        self.drift = self.plant.drift(self.q)

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The current ``(q, v)``."""
        return self.q, self.v

    def bind(self, chunk: PlantTelemetry) -> None:
        """The chunk :meth:`record` writes into."""
        self.tel = chunk

    def hold(self, u: np.ndarray) -> None:
        """Hold the efforts ``u`` (n_efforts,) from the current period on (with a stage law: the
        efforts recorded for the period; the integration evaluates the law itself)."""
        self.u = np.asarray(u, dtype=float)

    def set_wrenches(self, field: object) -> None:
        """Plants take no external wrenches yet.

        Raises:
            InvalidArgument: for any field.
        """
        if field is not None:
            raise InvalidArgument(f"plant '{self.plant.name}': external wrenches are not supported")

    def record(self, row: int, reference: np.ndarray | None = None) -> None:
        """Row ``row`` of the bound chunk at the current state, with the controller's ``reference``."""
        tel = self.tel
        tel.t[row] = self.start_time + self.periods_done * self.control_period
        tel.q[row], tel.v[row], tel.efforts[row] = self.q, self.v, self.u
        if reference is not None:
            tel.reference[row] = reference
        tel.drift[row], tel.orientation_drift[row] = self.drift

    def _held(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.plant.acceleration(q, v, self.u)

    def _staged(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:  # q = [q; t], v = [v; 1]
        a = np.empty(len(v))
        a[:-1] = self.plant.acceleration(q[:-1], v[:-1], self.stage_law(q[-1], q[:-1], v[:-1]))
        a[-1] = 0.0
        return a

    def step(self) -> None:
        """One control period.

        Raises:
            SimulationDiverged: when the state stops being finite, a closure opens past the
                plant's ``max_drift``, or the plant's dynamics fail (a singular pose).
        """
        k = self.periods_done
        t_end = self.start_time + (k + 1) * self.control_period
        try:
            if self.stage_law is None:
                q, v = self.integrator.advance(self._held, self.q, self.v, self.control_period)
            else:
                t = self.start_time + k * self.control_period
                q, v = self.integrator.advance(self._staged, np.append(self.q, t), np.append(self.v, 1.0),
                                               self.control_period)
                q, v = q[:-1], v[:-1]
        except SimulationDiverged as exc:  # the plant's dynamics failed: say when
            raise SimulationDiverged(f"at t = {t_end - self.control_period:.6g} s (step {k + 1}): {exc}") from exc
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise SimulationDiverged(f"the state is not finite at t = {t_end:.6g} s (step {k + 1})")
        drift = self.plant.drift(q)
        if not max(drift) <= self.plant.max_drift:
            raise SimulationDiverged(f"loop-closure residual {drift[0]:.3g} m (orientation {drift[1]:.3g} rad) at "
                                     f"t = {t_end:.6g} s (step {k + 1}): the mechanism came apart")
        self.q, self.v, self.drift, self.periods_done = q, v, drift, k + 1

    def evaluations(self) -> int:
        """Dynamics evaluations made by the integrator."""
        return self.integrator.evaluations()
