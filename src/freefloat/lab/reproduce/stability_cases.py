"""The cases of ``freefloat reproduce stability``: a run at step ``h`` and whether it was stable.

Each case's :meth:`measure` runs its scene with step ``h`` (s) and returns the run's status and
drifts; :meth:`stable` applies the case's stated bound to them (:data:`DRIFT_BOUND`,
:data:`CLOSURE_BOUND`). The run lasts a whole number of steps, the first at or beyond the case's
duration.

- :class:`Tumbling`: a robot (free base) tumbling torque-free at ``rate`` rad/s about a seeded
  random axis, joints at seeded random angles (uniform in +-0.5 rad) and at rest relative to the
  base, for 10 rad of base rotation (``10 / rate`` s). Stable: the run completes, and the kinetic
  energy and the angular momentum about the inertial origin stay within 1 % of their start values.
- :class:`Detumbling`: a ``detumble_impulse_*`` scene with its controller's period equal to the
  step (one integration step per control period), for 0.5 s. Stable: the run completes, and after
  the last impulse ends the angular momentum about the inertial origin stays within 1 % of what the
  held impulse gives exactly, ``L(0) + sum_k h s(t_k) n`` (the torques ``n`` are pure torques,
  sampled at each period's start ``t_k``, as the loop holds them).
- :class:`ClosedChain`: a mechanism scene (efforts held over each step) with Baumgarte lambda
  ``baumgarte``, for 0.3 s. Stable: the run completes (the mechanism neither comes apart nor
  reaches a singular pose) and the loop-closure drift max |qbar| stays below 1 mm.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, replace

import numpy as np

from ...app.runner import simulate
from ...app.scenes import find_scene
from ...dynamics.integrators import INTEGRATORS, make_integrator
from ...dynamics.models import make_model
from ...dynamics.simulation import run
from ...dynamics.wrenches import ExternalWrench
from ...errors import InvalidArgument, SceneError
from ...robot.conventions import state_from_base
from ...robot.loading import load_robot
from .interrupts import finished

#: Relative bound on the energy and angular-momentum drift of a stable robot run.
DRIFT_BOUND = 1e-2
#: Bound on the loop-closure drift max |qbar| of a stable mechanism run, m.
CLOSURE_BOUND = 1e-3
#: Telemetry rows kept per robot run (about; the drifts are checked on them).
ROWS = 200


class Case(ABC):
    """A scene run at a chosen step: subclasses give :meth:`measure` and :meth:`passes`."""

    @abstractmethod
    def measure(self, h: float) -> dict:
        """The run at step ``h`` (s): its ``status``, ``steps`` and drifts."""

    @abstractmethod
    def passes(self, m: dict) -> bool:
        """Whether :meth:`measure`'s result ``m`` counts as stable."""

    def stable(self, h: float) -> bool:
        """:meth:`passes` of :meth:`measure` at step ``h`` (s)."""
        return self.passes(self.measure(h))


def known(integrator: str, valid: tuple[str, ...]) -> None:
    """Raises InvalidArgument naming ``integrator`` and the valid names unless it is one of them."""
    if integrator not in valid:
        raise InvalidArgument(f"stability: unknown integrator '{integrator}'; valid: {', '.join(valid)}")


def whole_steps(duration: float, h: float) -> tuple[int, float]:
    """``(n, n h)``: the fewest steps of ``h`` s that last at least ``duration`` s."""
    n = max(1, math.ceil(duration / h - 1e-9))
    return n, n * h


@dataclass
class Tumbling(Case):
    """Torque-free tumbling of ``robot`` at ``rate`` rad/s, integrated by ``integrator``.

    Attributes:
        robot: a robot name or URDF (loaded with a free base, no gravity).
        rate: base angular speed at the start, rad/s.
        integrator: a name in :data:`freefloat.dynamics.integrators.INTEGRATORS`.
        seed: seeds the rotation axis and the joint angles.
    """

    robot: str
    rate: float
    integrator: str
    seed: int = 0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.rate) and self.rate > 0.0):
            raise InvalidArgument(f"stability: tumbling rate must be finite and > 0 rad/s, got {self.rate}")
        known(self.integrator, tuple(INTEGRATORS))
        self._robot = load_robot(self.robot, base="free", visuals=False)
        rng = np.random.default_rng(self.seed)
        axis = rng.normal(size=3)
        joints = rng.uniform(-0.5, 0.5, self._robot.n_joints)
        twist = np.concatenate([np.zeros(3), self.rate * axis / np.linalg.norm(axis)])
        self.q0, self.v0 = state_from_base(self._robot, np.zeros(3), np.eye(3), twist, joints,
                                           np.zeros(self._robot.n_joints))
        self._model = make_model("exact", self._robot)

    @property
    def duration(self) -> float:
        """10 rad of base rotation at the start rate, s."""
        return 10.0 / self.rate

    def measure(self, h: float) -> dict:
        """Run at step ``h`` (s): ``status``, ``energy_drift`` and ``momentum_drift`` (max over the
        recorded rows, relative to the start value)."""
        n, duration = whole_steps(self.duration, h)
        integrator = make_integrator(self.integrator, self._robot.model)
        result = finished(run(self._robot, self.q0, self.v0, duration, h, integrator, self._model,
                              record_every=max(1, n // ROWS)))
        tel = result.telemetry
        L = tel.momentum[:, 3:]
        return {"status": result.status, "steps": n,
                "energy_drift": float(np.abs(tel.energy - tel.energy[0]).max() / abs(tel.energy[0])),
                "momentum_drift": float(np.linalg.norm(L - L[0], axis=1).max() / np.linalg.norm(L[0]))}

    @staticmethod
    def passes(m: dict) -> bool:
        """Completed, energy and angular momentum within :data:`DRIFT_BOUND` of their start."""
        return bool(m["status"] == "completed" and m["energy_drift"] <= DRIFT_BOUND and m["momentum_drift"] <= DRIFT_BOUND)


@dataclass
class Detumbling(Case):
    """A built-in ``detumble_impulse_*`` scene integrated by ``integrator``, one step per control
    period.

    Attributes:
        scene: the scene name.
        integrator: a name in :data:`freefloat.dynamics.integrators.INTEGRATORS`.
        duration: simulated time, s.
    """

    scene: str
    integrator: str
    duration: float = 0.5

    def __post_init__(self) -> None:
        known(self.integrator, tuple(INTEGRATORS))
        self._scene = find_scene(self.scene)
        self._wrenches = [ExternalWrench(w.link, w.force, w.torque, w.start, w.end, w.rise) for w in self._scene.wrenches]
        if not self._wrenches or any(np.any(w.force) for w in self._wrenches):
            raise SceneError(f"stability: scene '{self.scene}' needs impulses that are pure torques "
                                 "(the exact momentum they give is then known)")
        self._after = max(w.end for w in self._wrenches)

    def held_impulse(self, h: float, steps: int) -> np.ndarray:
        """``sum_k h s(t_k) n`` over the wrenches (pure torques, inertial frame) and periods, N m s (3,)."""
        return sum((h * sum(w.scale(k * h) for k in range(steps)) * np.asarray(w.torque, float)
                    for w in self._wrenches), np.zeros(3))

    def measure(self, h: float) -> dict:
        """Run at step ``h`` (s): ``status`` and ``momentum_drift``, the largest distance, after the
        last impulse, of the angular momentum from what the held impulse gives, relative to that
        impulse."""
        n, duration = whole_steps(self.duration, h)
        sim = replace(self._scene.simulation, duration=duration, control_period=h, substeps=1,
                      integrator=self.integrator, record_every=1)
        outcome = finished(simulate(replace(self._scene, simulation=sim)))
        tel = outcome.telemetry
        impulse = self.held_impulse(h, n)
        after = tel.t >= self._after
        drift = np.linalg.norm(tel.momentum[after, 3:] - (tel.momentum[0, 3:] + impulse), axis=1)
        return {"status": outcome.status, "steps": n,
                "momentum_drift": float(drift.max(initial=0.0) / np.linalg.norm(impulse))}

    @staticmethod
    def passes(m: dict) -> bool:
        """Completed, the angular momentum after the impulse within :data:`DRIFT_BOUND` of exact."""
        return bool(m["status"] == "completed" and m["momentum_drift"] <= DRIFT_BOUND)


@dataclass
class ClosedChain(Case):
    """A built-in mechanism scene integrated by ``integrator`` with Baumgarte ``baumgarte``.

    Attributes:
        scene: the scene name (``five_bar_computed_torque``, ``rsu_ppap_computed_torque``, ...).
        integrator: a name of the integrator registry (or ``rk4``, which is ``rkmk4``).
        baumgarte: lambda of eq 129, 1/s (0: no stabilisation); None: the document's 1/h.
        duration: simulated time, s.
    """

    scene: str
    integrator: str
    baumgarte: float | None
    duration: float = 0.3

    def __post_init__(self) -> None:
        known(self.integrator, ("rk4", *INTEGRATORS))
        self._scene = find_scene(self.scene)

    def measure(self, h: float) -> dict:
        """Run at step ``h`` (s): ``status`` and ``closure_drift`` (max |qbar| over the run, m)."""
        n, duration = whole_steps(self.duration, h)
        lam = 1.0 / h if self.baumgarte is None else self.baumgarte
        sim = replace(self._scene.simulation, duration=duration, step=h, baumgarte=lam, integrator=self.integrator)
        outcome = finished(simulate(replace(self._scene, simulation=sim)))
        return {"status": outcome.status, "steps": n,
                "closure_drift": float(np.max(outcome.telemetry.drift, initial=0.0))}

    @staticmethod
    def passes(m: dict) -> bool:
        """Completed, loop-closure drift at most :data:`CLOSURE_BOUND`."""
        return bool(m["status"] == "completed" and m["closure_drift"] <= CLOSURE_BOUND)
