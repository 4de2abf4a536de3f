"""Optimised approach planning: a polynomial joint path that minimises the base rotation subject to
the grasp conditions and the limits (scipy's SLSQP).

Each mission joint follows a Bernstein polynomial of degree ``d`` in ``s = t / T``,

.. math:: q(t) = \\sum_{i=0}^{d} b_i \\binom{d}{i} s^i (1 - s)^{d - i},

whose first three control points give the start's position and rate at zero acceleration; the
others are the unknowns (the other joints keep their start rate). The base motion is rolled out at
the conserved momentum on ``samples`` intervals (:func:`.floating_kinematics.rollout`) and SLSQP
solves

.. math:: \\min_b\\; T \\int_0^T |\\omega_0|^2 dt \\quad \\text{s.t.}\\quad x_E(T) = p_g(T),\\;
   \\dot x_E(T) = \\dot p_g(T),\\; |\\dot q_j(t_k)| \\le \\dot q_{max,j},\\; |\\tau_j(t_k)| \\le \\tau_{max,j},

where ``T int |w0|^2 dt`` bounds the squared rotation angle (Cauchy-Schwarz) and ``tau = H* qddot
+ c*`` is the exact joint-space dynamics. It starts from the minimum-norm plan fitted by least
squares, and differentiates by forward differences of one roll-out per unknown.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BPoly
from scipy.optimize import minimize
from scipy.special import comb

from ...dynamics.models.exact import joint_space_dynamics
from ...errors import InfeasiblePlan
from ...robot.joints import JointCoordinates
from .floating_kinematics import FloatingKinematics, rollout, stage_times
from .plan import JointPath
from .reaction_null_space import RATE_LAWS
from .request import ApproachRequest
from .resolved_rate import resolved_rate_path


def optimised_path(request: ApproachRequest, degree: int = 6, samples: int = 16, max_iterations: int = 100,
                   ftol: float = 1e-5) -> JointPath:
    """The SLSQP-optimised joint path (see the module docstring): Bernstein ``degree``, roll-outs
    on ``samples`` intervals, SLSQP's ``max_iterations`` and ``ftol`` (on the objective scaled to
    1 at the minimum-norm start: 1e-5 stops near a rotation sqrt(1e-5) of the minimum-norm one).

    Raises:
        InfeasiblePlan: when SLSQP ends without meeting the constraints (its message and the
            largest violation: of the grasp or of the limits).
    """
    problem = _Problem(request, degree, samples)
    start = problem.fit(resolved_rate_path(request, RATE_LAWS["min_norm"]))
    eq = problem.n_equalities
    result = minimize(lambda x: problem.values(x)[0], start, jac=lambda x: problem.jacobian(x)[0], method="SLSQP",
                      constraints=[{"type": "eq", "fun": lambda x: problem.values(x)[1:1 + eq],
                                    "jac": lambda x: problem.jacobian(x)[1:1 + eq]},
                                   {"type": "ineq", "fun": lambda x: problem.values(x)[1 + eq:],
                                    "jac": lambda x: problem.jacobian(x)[1 + eq:]}],
                      options={"maxiter": max_iterations, "ftol": ftol})
    values = problem.values(result.x)
    violation = max(np.abs(values[1:1 + eq] * problem.scale / problem.tolerances).max(),
                    -min(values[1 + eq:].min() + problem.margin, 0.0))
    if not result.success and violation > 1.0:  # beyond a tolerance or a limit (the plan's check decides within)
        raise InfeasiblePlan(f"approach (optimised): SLSQP found no path that meets the grasp within the limits "
                             f"({result.message}; largest constraint violation {violation:.3g} in tolerances "
                             "of the grasp or fractions of a limit); the grasp point may be out of reach or the "
                             "deadline too short", "optimiser")
    return JointPath(problem.poly(result.x))


class _Problem:
    """The optimisation's unknowns, polynomial and scaled values: objective (1 at the start),
    grasp equalities (the matched entries of :meth:`ApproachRequest.grasp_errors`, hand after
    hand, in units of :attr:`scale`), limit inequalities (1 - margin - |value| / limit on the
    grid, rates then torques)."""

    #: The limits are kept this fraction inside on the optimiser's grid, so that the peaks
    #: between its samples stay within them on the plan's finer grid (which checks them).
    margin = 0.02

    #: The grasp equalities' unit, m and m/s: O(1) values for SLSQP, which meets them far inside
    #: the request's tolerances when it converges.
    scale = 1e-2

    def __init__(self, request: ApproachRequest, degree: int, samples: int):
        robot = request.robot
        self.request, self.degree, self.T = request, degree, request.duration
        self.joints = np.arange(robot.n_joints) if request.joints is None else np.asarray(request.joints, int)
        self.times = np.linspace(0.0, self.T, samples + 1)
        self.kin = FloatingKinematics.at_state(robot, request.q0, request.v0)
        start = JointCoordinates(robot).get(request.q0)
        rate0 = request.v0[robot.n_base:]
        step = self.T / degree
        self.fixed = np.array([start, start + rate0 * step, start + 2 * rate0 * step])  # zero acceleration
        self.line = start + rate0 * step * np.arange(degree + 1)[:, None]  # (d + 1, n): the joints at their rate
        matched = np.broadcast_to(request.matched, (len(request.end_effectors), 4, 3))
        self.n_equalities = int(matched.sum())
        self.tolerances = np.broadcast_to(request.tolerances[:, None], matched.shape)[matched]
        self.data = robot.model.createData()
        self.reference = 1.0
        self._values: dict[bytes, np.ndarray] = {}
        self._jacobian: tuple[bytes, np.ndarray] | None = None

    def control_points(self, x: np.ndarray) -> np.ndarray:
        """Bernstein control points (d + 1, n) from the unknowns."""
        points = self.line.copy()
        points[:3] = self.fixed
        points[3:, self.joints] = x.reshape(self.degree - 2, len(self.joints))
        return points

    def poly(self, x: np.ndarray) -> BPoly:
        """The joint path's polynomial on [0, T] (values (n,))."""
        return BPoly(self.control_points(x)[:, None, :], [0.0, self.T])

    def fit(self, path: JointPath) -> np.ndarray:
        """Unknowns whose polynomial is the least-squares fit of ``path`` on the grid; the
        objective is scaled to 1 there."""
        s, d = self.times / self.T, self.degree
        basis = np.array([comb(d, i) * s**i * (1 - s) ** (d - i) for i in range(d + 1)]).T  # (N, d + 1)
        target = np.array([path(t)[0] for t in self.times]) - basis[:, :3] @ self.fixed
        free, *_ = np.linalg.lstsq(basis[:, 3:], target[:, self.joints], rcond=None)
        x = free.ravel()
        self.reference = max(float(self._evaluate(x)[0]), 1e-30)
        return x

    def values(self, x: np.ndarray) -> np.ndarray:
        """[objective / its value at the fit, grasp equalities, limit inequalities] (cached)."""
        x = np.asarray(x, float)
        key = x.tobytes()
        if key not in self._values:
            self._values.clear()
            values = self._evaluate(x)
            values[0] /= self.reference
            self._values[key] = values
        return self._values[key]

    def _evaluate(self, x: np.ndarray) -> np.ndarray:
        """[T int |w0|^2 dt, grasp equalities, limit inequalities] (unscaled objective)."""
        request, robot = self.request, self.request.robot
        path = JointPath(self.poly(x))
        stages = stage_times(self.times)
        table = dict(zip(stages, path.rate(stages)))
        q, v = rollout(self.kin, request.q0, lambda t, _q: table[t], self.times)
        angular = v[:, 3:6] if robot.base == "free" else v[:, 2:3]
        objective = self.T * np.trapezoid((angular**2).sum(axis=1), self.times)
        data = self.data
        rates, accelerations = path.rate(self.times), path.acceleration(self.times)
        torques = np.empty_like(rates)
        for k in range(len(self.times)):
            H, bias = joint_space_dynamics(robot, data, q[k], v[k])
            torques[k] = H @ accelerations[k] + bias
        limits = request.limits
        return np.concatenate(([objective], request.grasp_errors(q[-1], v[-1])[:, request.matched].ravel() / self.scale,
                               (1.0 - self.margin - np.abs(rates) / limits.joint_rate).ravel(),
                               (1.0 - self.margin - np.abs(torques) / limits.torque).ravel()))

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Forward differences of :meth:`values` (rows: values, columns: unknowns)."""
        key = np.asarray(x, float).tobytes()
        if self._jacobian is None or self._jacobian[0] != key:
            x = np.asarray(x, float)
            base = self.values(x)
            scale = np.ones_like(base)
            scale[0] = self.reference
            out = np.empty((len(base), len(x)))
            for i in range(len(x)):
                h = 1e-7 * max(1.0, abs(x[i]))
                shifted = x.copy()
                shifted[i] += h
                out[:, i] = (self._evaluate(shifted) / scale - base) / h
            self._jacobian = (key, out)
        return self._jacobian[1]
