"""The system momentum estimated from measured states: a Kalman filter that uses momentum
conservation between impulses.

A free-floating robot's momentum about the inertial origin, ``h = [P; L_O]`` (inertial frame),
changes only by external wrenches: joint torques are internal. A controller that reads the
momentum (the detumbling law of eq 134 through ``H0^-1 M``) computes it today from the state it
is handed, through the momentum map ``M = H0 x0dot + H0m qdot`` (eq 69), which is exact for a
true state and carries every sensor error of a measured one. Here the map of each measured state
is a *measurement* ``z = A_O(q) v`` of a quantity that stays constant (up to gravity, zero in
space), and the filter is the minimum-variance estimator of that constant under a random walk
(Kalman 1960):

.. math::
    x^- = x + \\Delta t\\, [m g;\\ c \\times m g], \\quad P^- = P + \\Delta t\\, Q,

    S = P^- + R, \\quad K = P^- S^{-1}, \\quad x = x^- + K (z - x^-),

with ``R = A_O Sigma_v A_O^T + D Sigma_q D^T`` the measurement's covariance propagated from the
channels' noise through the map and its configuration derivative ``D = d(A_O v)/dq``
(Pinocchio's centroidal derivatives), and ``Q`` the random walk's intensity for what the model
leaves out (small unknown wrenches). A reading whose normalised innovation ``y^T S^-1 y`` exceeds
the gate (an impulse the controller does not know of: a capture, a thruster firing) restarts the
filter from it, the manoeuvre detection of tracking filters (Bar-Shalom, Li and Kirubarajan,
*Estimation with Applications to Tracking and Navigation*, Wiley 2001, ch. 11).

Why this and not a low-pass filter of the map: conservation is an exact process model, so the
filter averages the noise down as ``1/sqrt(samples)`` without the lag a low-pass filter puts on a
changing signal; a delayed reading measures the momentum of *now* (it has not changed since);
and the innovation test tells an impulse from noise. Bias passes through (it is not observable
from the momenta alone).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...robot.conventions import cross3, skew
from ...robot.robot import Robot
from .settings import MomentumKalman


def origin_map(model: pin.Model, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """``A_O`` (6, nv): ``[P; L about the inertial origin] = A_O v``, inertial frame, from
    Pinocchio's centroidal momentum matrix (about the system CoM) shifted to the origin; leaves
    ``data.com[0]`` at q."""
    Ag = pin.computeCentroidalMap(model, data, q)
    out = Ag.copy()
    out[3:] += skew(data.com[0]) @ Ag[:3]
    return out


def configuration_derivative(model: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``D = d(A_O(q) v)/dq`` (6, nv) in the tangent of ``pin.integrate``: the centroidal
    momentum's derivative (Pinocchio's ``computeCentroidalDynamicsDerivatives``) shifted to the
    origin, ``d(c x P) = [c]x dP - [P]x dc`` with ``dc/dq`` the CoM Jacobian."""
    dh_dq = pin.computeCentroidalDynamicsDerivatives(model, data, q, v, np.zeros(model.nv))[0]
    linear = data.hg.linear.copy()
    Jc = pin.jacobianCenterOfMass(model, data, q)
    out = dh_dq.copy()
    out[3:] += skew(data.com[0]) @ dh_dq[:3] - skew(linear) @ Jc
    return out


#: Components of ``[P; L_O]`` that only external wrenches change, by base kind: all six for a free
#: base; ``Px, Py, Lz`` for a planar one (its root joint's reactions, a z force and x, y torques,
#: change the others).
CONSERVED = {"free": np.arange(6), "planar": np.array([0, 1, 5])}


class MomentumEstimator:
    """The Kalman filter of the module docstring for one robot, on the components of the momentum
    that only external wrenches change (:data:`CONSERVED`); the others are the reading's own.

    Args:
        robot: the robot (its gravity enters the prediction).
        settings: the random walk's intensities, the false-alarm probability of the gate, the
            known impulses' times.
        velocity_noise: standard deviation of each velocity coordinate's noise (nv,), Pinocchio's
            order (base rows first).
        tangent_noise: standard deviation of each configuration tangent coordinate's noise (nv,).

    Attributes:
        rows: the filtered components, indices into ``[P; L_O]`` (c,).
        gate: the normalised innovation squared above which a reading restarts the filter.
        estimate: ``[P; L_O]`` (6,), kg m/s and kg m^2/s, inertial frame; None before the first reading.
        covariance: the filtered components' covariance (c, c); None before the first reading.
        resets: readings that restarted the filter (asked or by the gate).
    """

    def __init__(self, robot: Robot, settings: MomentumKalman, velocity_noise: np.ndarray, tangent_noise: np.ndarray):
        # the chi-square quantile, imported here: scipy.special costs 0.1-0.7 s to import
        from scipy.special import chdtri

        self.model, self.data, self.n_base = robot.model, robot.model.createData(), robot.n_base
        self.settings, self.rows = settings, CONSERVED[robot.base]
        self.gate = float(chdtri(len(self.rows), settings.false_alarm))
        self.velocity_variance = np.square(velocity_noise)
        self.tangent_variance = np.square(tangent_noise)
        walk = np.repeat([settings.linear_process_noise ** 2, settings.angular_process_noise ** 2], 3)
        self.intensity = np.diag(walk[self.rows])
        self.weight = self.model.gravity.linear * pin.computeTotalMass(self.model)  # m g, N
        self.estimate: np.ndarray | None = None
        self.covariance: np.ndarray | None = None
        self.resets = 0
        self.q = self.v = self.com = self.z = np.zeros(0)  # the reading (see read)
        self.A = np.zeros((6, 0))
        self.reading = np.zeros((6, 6))  # the covariance of the last reading taken (see update)
        self.previous = (np.zeros(3), np.zeros((3, 3)))  # that reading's CoM and its covariance (under gravity)
        self.exact = not (self.velocity_variance.any() or self.tangent_variance.any())

    def read(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Set the measured state (q (nq,), v (nv,)) that :meth:`update` and :meth:`velocity` use.

        Returns:
            its momentum map ``z = A_O(q) v`` (6,).
        """
        self.q, self.v = q, v
        self.A = origin_map(self.model, self.data, q)
        self.com = self.data.com[0].copy()
        self.z = self.A @ v
        return self.z

    def reading_covariance(self) -> np.ndarray:
        """``R`` (6, 6): the covariance of the reading's momentum map, from the channels' noise."""
        A = self.A
        R = (A * self.velocity_variance) @ A.T
        if self.tangent_variance.any():
            D = configuration_derivative(self.model, self.data, self.q, self.v)
            R += (D * self.tangent_variance) @ D.T
        return R

    def _com_covariance(self) -> np.ndarray:
        """The covariance of the reading's system CoM (3, 3), ``J_c Sigma_q J_c^T``."""
        if not self.tangent_variance.any():
            return np.zeros((3, 3))
        Jc = pin.jacobianCenterOfMass(self.model, self.data, self.q)
        return (Jc * self.tangent_variance) @ Jc.T

    def _predicted(self, elapsed: float) -> tuple[np.ndarray, np.ndarray]:
        """The estimate and its covariance carried ``elapsed`` s on to the reading (filtered
        components): the random walk and, under gravity, ``dP = m g dt`` and ``dL_O = c x m g dt``
        with c the mean of the two readings' CoMs (exact while the CoM moves linearly across the
        field, as it does in a uniform one), its noise added to the angular momentum's covariance."""
        rows = self.rows
        x, P = self.estimate[rows], self.covariance + elapsed * self.intensity
        if self.weight.any():
            com, com_covariance = 0.5 * (self.previous[0] + self.com), self._com_covariance()
            x = x + elapsed * np.concatenate((self.weight, cross3(com, self.weight)))[rows]
            W = skew(self.weight)
            input_noise = np.zeros((6, 6))
            input_noise[3:, 3:] = elapsed ** 2 * W @ (0.25 * (self.previous[1] + com_covariance)) @ W.T
            P = P + input_noise[np.ix_(rows, rows)]
            self.previous = (self.com, com_covariance)
        return x, P

    def update(self, elapsed: float, restart: bool = False) -> bool:
        """Take the reading set by :meth:`read`, ``elapsed`` s after the previous one, or restart
        the filter from it (a known impulse since the previous one); True when it restarted the
        filter, asked or by the gate (an impulse). Readings without noise are taken as they are."""
        rows = self.rows
        self.reading = self.reading_covariance()
        z, R = self.z[rows], self.reading[np.ix_(rows, rows)]
        if self.estimate is None or self.covariance is None or restart or self.exact:
            self._restart(R)
            self.resets += restart
            return restart
        x, P = self._predicted(elapsed)
        y = z - x
        S = P + R
        if float(y @ np.linalg.solve(S, y)) > self.gate:
            self._restart(R)
            self.resets += 1
            return True
        K = np.linalg.solve(S, P).T  # P S^-1 (both symmetric)
        I_K = np.eye(len(rows)) - K
        self.estimate = self.z.copy()
        self.estimate[rows] = x + K @ y
        self.covariance = I_K @ P @ I_K.T + K @ R @ K.T  # Joseph form: symmetric, positive
        return False

    def _restart(self, R: np.ndarray) -> None:
        """Start the filter afresh from the reading (R: its filtered components' covariance)."""
        self.estimate, self.covariance = self.z.copy(), R
        if self.weight.any():
            self.previous = (self.com, self._com_covariance())

    def spread(self) -> np.ndarray:
        """The estimate's standard deviations (6,): the filter's on the filtered components, the
        last reading's own on the others."""
        out = np.sqrt(np.diag(self.reading))
        out[self.rows] = np.sqrt(np.diag(self.covariance))
        return out

    def velocity(self) -> np.ndarray:
        """The reading's ``v`` (nv,) with its base rows replaced by those that give the estimated
        momentum with its joint rates: ``A_b v_b = estimate - A_j qdot`` on the filtered
        components (as many as the base's rates)."""
        nb, out = self.n_base, self.v.copy()
        A = self.A[self.rows]
        out[:nb] = np.linalg.solve(A[:, :nb], self.estimate[self.rows] - A[:, nb:] @ self.v[nb:])
        return out
