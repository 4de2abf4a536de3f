"""Computed torque with feedforward (the thesis proposal's CTCp, sec 3): the nominal model's
inverse dynamics along the reference computed once, before the run, so that the law evaluates
no model at all (objective 2: a law of much lower cost per call than computed torque).

Along the reference ``q#_d(t)`` the platform force of eq 137 and the inertia are tabulated at
times ``t_i = t_0 + i dt``: the actuator efforts ``tau_d = (C^T U)^-1 (H^ qddot#_d + h^)``
(eqs 130-140, :meth:`~freefloat.parallel.mechanism.ParallelMechanism.inverse_trajectory`) and
``G_d = (C^T U)^-1 H^`` (k, p), both at the reference's pose. The law adds feedback through
``G_d`` in place of the measured pose's ``(C^T U)^-1 H^``:

.. math:: \\tau = \\tau_d(t) + G_d(t)\\, a, \\qquad
          a = 2 \\lambda \\dot e + \\lambda^2 e \\ \\text{(PD, eq 190's)} \\quad\\text{or}\\quad
          a = \\lambda \\dot e - k(\\sigma, \\dot q^\\#) f(s) \\ \\text{(sliding, eq 153's)},

``e = q#_d - q#``, ``s = -(edot + lambda e)``, ``sigma = qddot#_d + lambda edot``, k eq 167's
gains. Where the platform tracks its reference (q# = q#_d, qdot# = qdot#_d) both equal their
feedback-linearising twins (eqs 190 and 153): eq 153's ``h^ + H^ (sigma - k f(s))`` is
``u*_d + H^ (lambda edot - k f(s))`` there. Away from it the model terms are those of the
reference's pose and rates, an error the feedback has to absorb. Between table rows the law
interpolates linearly; the control instants of a run on the table's grid hit rows exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import FreefloatError
from .mechanism import ParallelMechanism
from .sliding_mode import PlatformControl, Reference


@dataclass(frozen=True)
class FeedforwardTable:
    """The reference and the nominal model's inverse dynamics along it, at ``t_0 + i dt``.

    Attributes:
        t0: time of the first row, s. dt: spacing of the rows, s.
        reference: ``(q#_d, qdot#_d, qddot#_d)`` per row (N, 3, p).
        efforts: ``tau_d`` (N, k), N m or N.
        inertia: ``G_d = (C^T U)^-1 H^`` (N, k, p).
    """

    t0: float
    dt: float
    reference: np.ndarray
    efforts: np.ndarray
    inertia: np.ndarray

    @classmethod
    def along(cls, model: ParallelMechanism, trajectory: Reference, guess: np.ndarray, duration: float,
              dt: float, t0: float = 0.0) -> FeedforwardTable:
        """Tabulate ``trajectory`` (``t -> (q#_d, qdot#_d, qddot#_d)``) over ``[t0, t0 + duration]``
        every ``dt`` s on ``model``, the first pose assembled from the chain joints ``guess``.

        Raises:
            FreefloatError: for a model whose actuation is not square (the table inverts
                ``C^T U``), a duration or spacing that is not positive, or a reference the model
                cannot follow (where it does not assemble or its joint path jumps).
        """
        if not model.square_actuation:
            raise FreefloatError("feedforward table: the model must have as many actuators as platform coordinates "
                                 "and no effort distribution (the table holds (C^T U)^-1)")
        if not (duration > 0.0 and dt > 0.0):
            raise FreefloatError(f"feedforward table: duration ({duration} s) and dt ({dt} s) must be positive")
        times = t0 + dt * np.arange(int(np.floor(duration / dt + 1e-9)) + 1)
        reference = np.array([np.array(trajectory(t)) for t in times])          # (N, 3, p)
        tau, q = model.inverse_trajectory(reference[:, 0], reference[:, 1], reference[:, 2], guess)
        _, _, C, M, _, _ = model.reference().terms(q, np.zeros_like(q))
        CT = C.swapaxes(-1, -2)
        inertia = np.linalg.solve(CT @ model.selection(), CT @ M @ C)
        return cls(float(t0), float(dt), reference, tau, inertia)

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(reference (3, p), tau_d (k,), G_d (k, p))`` at ``t`` s, linear between rows.

        Raises:
            FreefloatError: for a time outside the table.
        """
        x = (t - self.t0) / self.dt
        i = int(np.floor(x + 1e-9))
        last = len(self.efforts) - 1
        if i < 0 or i > last or (i == last and x - i > 1e-9):
            raise FreefloatError(f"feedforward table: t = {t} s is outside the table "
                                 f"[{self.t0}, {self.t0 + last * self.dt}] s; tabulate a longer span")
        w = x - i
        if w <= 1e-9:
            return self.reference[i], self.efforts[i], self.inertia[i]
        return tuple((1.0 - w) * a[i] + w * a[i + 1] for a in (self.reference, self.efforts, self.inertia))


@dataclass(frozen=True)
class FeedforwardControl:
    """The law of the module docstring: a controller of the one loop on Orsino's coordinates
    ``q = [q#; q°]`` that reads only the platform coordinates and rates.

    Attributes:
        twin: the feedback-linearising law it stands for (:class:`~.sliding_mode.PlatformControl`:
            eq 190 without gains, eq 153 with them): its reference, lambda, gains and switch; its
            model is the one the table holds.
        table: the reference and its feedforward.
    """

    twin: PlatformControl
    table: FeedforwardTable

    @classmethod
    def along(cls, twin: PlatformControl, guess: np.ndarray, duration: float, dt: float,
              t0: float = 0.0) -> FeedforwardControl:
        """``twin`` with its model tabulated along its reference (:meth:`FeedforwardTable.along`)."""
        return cls(twin, FeedforwardTable.along(twin.model, twin.trajectory, guess, duration, dt, t0))

    def law(self, t: float, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(tau, e, s)``: actuator efforts (k,), ``e = q#_d - q#`` and ``s = -(edot + lam e)``
        (p,) for the measured q and qd (n_q,)."""
        (q_d, qd_d, qdd_d), tau, G = self.table.at(t)
        p, lam, gains = len(q_d), self.twin.lam, self.twin.gains
        e, edot = q_d - q[:p], qd_d - qd[:p]
        s = -(edot + lam * e)
        if gains is None:
            a = 2.0 * lam * edot + lam * lam * e
        else:
            switch = np.sign(s) if self.twin.saturation == "sign" else np.tanh(100.0 * s)
            a = lam * edot - gains.k(qdd_d + lam * edot, qd[:p]) * switch
        return tau + G @ a, e, s

    def torque(self, t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Actuator efforts (k,) of :meth:`law` (the loop's controller interface)."""
        return self.law(t, q, qd)[0]

    def reference(self, t: float) -> np.ndarray:
        """The platform reference ``q#_d`` (p,) at ``t`` s."""
        return self.twin.trajectory(t)[0]
